//! The grammar check: reads an expression token by token and names the
//! first fault with its column, before anything is built from it
//! ([`super`]'s documentation says what is refused and why).

use super::ExprError;
use super::lex::{Token, fault, tokens};
use super::ops::{BINARY, CONSTANTS, UNARY};

/// The names of a function table, space separated.
fn names<F>(table: &[(&str, F)]) -> String {
    table.iter().map(|f| f.0).collect::<Vec<_>>().join(" ")
}

/// How the operand just read began: after a unary sign, or as the exponent
/// of a `^` (either makes a following `^` ambiguous).
#[derive(Debug, Clone, Copy, Default)]
struct Lead {
    signed: bool,
    exponent: bool,
}

/// An open parenthesis: a group, or a call expecting `args` arguments.
struct Open {
    at: usize,
    lead: Lead,
    call: Option<(&'static str, usize)>,
    commas: usize,
}

/// Reads `text` as an expression over `variables`, token by token, and
/// names the first fault with its column ([`super`]'s documentation).
pub(super) fn check(text: &str, variables: &[&str]) -> Result<(), ExprError> {
    let toks = tokens(text)?;
    bounded(text, &toks)?;
    let mut open: Vec<Open> = Vec::new();
    let mut want_operand = true;
    let mut lead = Lead::default();
    let mut last = Lead::default();
    let mut i = 0;
    while i < toks.len() {
        let (tok, at) = toks[i];
        if want_operand {
            match tok {
                Token::Op(b'+' | b'-') => lead.signed = true,
                Token::Number(digits) => {
                    in_range(text, at, digits)?;
                    (last, lead, want_operand) = (lead, Lead::default(), false);
                }
                Token::Name(name) => {
                    if let Some(arity) = function(name) {
                        if toks.get(i + 1).map(|t| t.0) != Some(Token::Open) {
                            return Err(fault(
                                text,
                                at,
                                format!(
                                    "`{name}` is a function: write its argument in parentheses, {name}(...)"
                                ),
                            ));
                        }
                        open.push(Open {
                            at: toks[i + 1].1,
                            lead,
                            call: Some(arity),
                            commas: 0,
                        });
                        lead = Lead::default();
                        i += 1;
                    } else if CONSTANTS.iter().any(|c| c.0 == name) || variables.contains(&name) {
                        (last, lead, want_operand) = (lead, Lead::default(), false);
                    } else {
                        return Err(fault(text, at, unknown(name, variables)));
                    }
                }
                Token::Open => {
                    open.push(Open {
                        at,
                        lead,
                        call: None,
                        commas: 0,
                    });
                    lead = Lead::default();
                }
                _ => {
                    return Err(fault(
                        text,
                        at,
                        "expected a number, a variable, a function or `(` here",
                    ));
                }
            }
        } else {
            match tok {
                Token::Op(op) => {
                    if op == b'^' {
                        ambiguous_power(text, at, last)?;
                    }
                    lead = Lead {
                        signed: false,
                        exponent: op == b'^',
                    };
                    want_operand = true;
                }
                Token::Close => {
                    let Some(group) = open.pop() else {
                        return Err(fault(text, at, "`)` without a `(` before it"));
                    };
                    if let Some((name, args)) = group.call
                        && group.commas + 1 != args
                    {
                        return Err(fault(
                            text,
                            at,
                            format!(
                                "`{name}` takes {args} argument(s), given {}",
                                group.commas + 1
                            ),
                        ));
                    }
                    last = group.lead;
                }
                Token::Comma => match open.last_mut() {
                    Some(g) if g.call.is_some_and(|(_, args)| g.commas + 1 < args) => {
                        g.commas += 1;
                        lead = Lead::default();
                        want_operand = true;
                    }
                    _ => {
                        return Err(fault(
                            text,
                            at,
                            "a comma outside the arguments of atan2, min or max",
                        ));
                    }
                },
                _ => {
                    return Err(fault(
                        text,
                        at,
                        "expected an operator (+ - * / ^), `)` or the end here",
                    ));
                }
            }
        }
        i += 1;
    }
    if want_operand {
        return Err(fault(
            text,
            text.len(),
            "the expression ends where a number, a variable or a function is expected",
        ));
    }
    if let Some(group) = open.last() {
        return Err(fault(text, group.at, "this `(` is never closed"));
    }
    Ok(())
}

/// The most tokens an expression may have: its tree, built and evaluated
/// by recursion, then stays a few hundred levels deep.
pub(super) const MAX_TOKENS: usize = 1000;

/// The deepest nesting of parentheses and signs (`-(-(-x))`).
pub(super) const MAX_NESTING: usize = 64;

/// Refuses an expression longer than [`MAX_TOKENS`] or nested deeper than
/// [`MAX_NESTING`], at the token that passes the limit.
fn bounded(text: &str, toks: &[(Token<'_>, usize)]) -> Result<(), ExprError> {
    if let Some(&(_, at)) = toks.get(MAX_TOKENS) {
        return Err(fault(
            text,
            at,
            format!("longer than {MAX_TOKENS} tokens (numbers, names, operators, parentheses)"),
        ));
    }
    let (mut parens, mut signs) = (0usize, 0usize);
    for (k, &(tok, at)) in toks.iter().enumerate() {
        match tok {
            Token::Open => parens += 1,
            Token::Close => parens = parens.saturating_sub(1),
            _ => {}
        }
        let sign = matches!(tok, Token::Op(b'+' | b'-'));
        let after_op = k == 0 || matches!(toks[k - 1].0, Token::Op(_) | Token::Open | Token::Comma);
        signs = if sign && after_op {
            signs + 1
        } else if sign {
            signs
        } else {
            0
        };
        if parens + signs > MAX_NESTING {
            return Err(fault(
                text,
                at,
                format!("nested deeper than {MAX_NESTING} parentheses and signs"),
            ));
        }
    }
    Ok(())
}

/// Refuses a number beyond the f64 range, or one that is not 0 but rounds
/// to it.
fn in_range(text: &str, at: usize, digits: &str) -> Result<(), ExprError> {
    let x: f64 = digits.parse().unwrap_or(f64::NAN);
    let nonzero = digits
        .split(['e', 'E'])
        .next()
        .is_some_and(|m| m.bytes().any(|c| (b'1'..=b'9').contains(&c)));
    if x.is_finite() && (x != 0.0 || !nonzero) {
        return Ok(());
    }
    Err(fault(
        text,
        at,
        format!(
            "{digits} is beyond the f64 range: expected a number from 2.2e-308 to 1.8e308 in magnitude, or 0"
        ),
    ))
}

/// A `^` after an operand read with a sign before it, or as an exponent
/// itself, is ambiguous ([`super`]'s documentation).
fn ambiguous_power(text: &str, at: usize, last: Lead) -> Result<(), ExprError> {
    if last.signed {
        return Err(fault(
            text,
            at,
            "a signed base before `^` is ambiguous (Excel reads -a^b as (-a)^b, Python as -(a^b)): \
             write -(a^b) or (-a)^b",
        ));
    }
    if last.exponent {
        return Err(fault(
            text,
            at,
            "a chain of `^` is ambiguous (Excel and Matlab read a^b^c as (a^b)^c, Python as a^(b^c)): write a^(b^c) or (a^b)^c",
        ));
    }
    Ok(())
}

/// The number of arguments of the function `name`, if it is one.
fn function(name: &str) -> Option<(&'static str, usize)> {
    UNARY
        .iter()
        .map(|f| (f.0, 1))
        .chain(BINARY.iter().map(|f| (f.0, 2)))
        .find(|(f, _)| *f == name)
}

/// The message for a name that is neither a function, a constant nor one
/// of `variables`.
fn unknown(name: &str, variables: &[&str]) -> String {
    format!(
        "unknown name `{name}`: this domain's variables are {}; constants pi, e; functions {}, {}",
        if variables.is_empty() {
            "none (a value has no variables)".to_string()
        } else {
            variables.join(", ")
        },
        names(&UNARY),
        names(&BINARY)
    )
}
