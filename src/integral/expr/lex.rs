//! The tokens of an expression, each with its byte offset, and the fault
//! type that names a column.

use super::ExprError;

/// One token of an expression.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Token<'a> {
    /// A decimal number (its text).
    Number(&'a str),
    /// A name: a variable, a constant or a function.
    Name(&'a str),
    /// One of `+ - * / ^`.
    Op(u8),
    /// `(`.
    Open,
    /// `)`.
    Close,
    /// `,`.
    Comma,
}

/// The tokens of `text` with their byte offsets; an unknown character is
/// a fault at its column.
pub(super) fn tokens(text: &str) -> Result<Vec<(Token<'_>, usize)>, ExprError> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let start = i;
        let token = match b[i] {
            b' ' | b'\t' | b'\n' | b'\r' => {
                i += 1;
                continue;
            }
            b'0'..=b'9' | b'.' if number_len(&text[i..]) > 0 => {
                i += number_len(&text[i..]);
                Token::Number(&text[start..i])
            }
            b'a'..=b'z' | b'A'..=b'Z' | b'_' => {
                while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                    i += 1;
                }
                Token::Name(&text[start..i])
            }
            c @ (b'+' | b'-' | b'*' | b'/' | b'^' | b'(' | b')' | b',') => {
                i += 1;
                match c {
                    b'(' => Token::Open,
                    b')' => Token::Close,
                    b',' => Token::Comma,
                    op => Token::Op(op),
                }
            }
            _ => {
                let ch = text[i..].chars().next().unwrap_or('?');
                return Err(fault(
                    text,
                    i,
                    format!(
                        "unexpected character {ch:?}: expected numbers, names, + - * / ^, \
                         parentheses and commas"
                    ),
                ));
            }
        };
        out.push((token, start));
    }
    Ok(out)
}

/// The bytes of the decimal number at the start of `text` (0 if none):
/// `digits [. digits] [e [+-] digits]` or `. digits [e ...]`.
pub(super) fn number_len(text: &str) -> usize {
    let b = text.as_bytes();
    let digits = |mut i: usize| {
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
        i
    };
    let int_end = digits(0);
    let mut end = int_end;
    if end < b.len() && b[end] == b'.' {
        let frac_end = digits(end + 1);
        if frac_end > end + 1 || int_end > 0 {
            end = frac_end;
        }
    }
    if end == 0 {
        return 0;
    }
    if end < b.len() && (b[end] == b'e' || b[end] == b'E') {
        let mut i = end + 1;
        if i < b.len() && (b[i] == b'+' || b[i] == b'-') {
            i += 1;
        }
        let exp_end = digits(i);
        if exp_end > i {
            end = exp_end;
        }
    }
    end
}

/// An [`ExprError`] at byte offset `at` of `text`.
pub(super) fn fault(text: &str, at: usize, message: impl Into<String>) -> ExprError {
    let column = text[..at.min(text.len())].chars().count() + 1;
    ExprError {
        text: near(text, column),
        column,
        message: message.into(),
    }
}

/// `text`, or where it is longer than 60 characters the 60 around `column`
/// (1-based), cut ends marked `…`.
fn near(text: &str, column: usize) -> String {
    const WINDOW: usize = 60;
    let len = text.chars().count();
    if len <= WINDOW {
        return text.to_string();
    }
    let start = column.saturating_sub(WINDOW / 2 + 1).min(len - WINDOW);
    let part: String = text.chars().skip(start).take(WINDOW).collect();
    let head = if start > 0 { "…" } else { "" };
    let tail = if start + WINDOW < len { "…" } else { "" };
    format!("{head}{part}{tail}")
}
