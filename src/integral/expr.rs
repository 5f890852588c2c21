//! Integrand expressions: a formula in a string, compiled once and evaluated
//! at every point without allocating.
//!
//! The expression is parsed and evaluated by [exmex](https://docs.rs/exmex)
//! (a flat expression whose numbers sit on the stack, up to 32 numbers and
//! variables; a longer expression allocates one small buffer per point).
//! Before exmex sees it, [`check`] reads the text token by token, so every
//! fault is named with its column, and refuses what exmex would read
//! otherwise than a person does:
//!
//! - `-x^2` is `(-x)^2` to exmex (its unary minus binds before `^`): refused,
//!   with `-(x^2)` and `(-x)^2` offered; `exp(-x^2)` would have been
//!   `exp(x^2)`;
//! - `a^b^c` is `(a^b)^c` to exmex: refused, with both readings offered;
//! - a function without parentheses (`sin x`) or written between its
//!   arguments (`x min y`): refused; calls are `f(a)` and `f(a, b)`.
//!
//! Numbers are decimal with an optional exponent (`1.5e-3`, `.5`).
//!
//! | kind | names |
//! |---|---|
//! | constants | `pi`, `e` |
//! | operators | `+ - * / ^` (and unary `-`, `+`) |
//! | functions of one argument | `sin cos tan asin acos atan sinh cosh tanh exp log ln log10 sqrt abs floor ceil step` (`log` is the natural logarithm, as `ln`; `step(a)` is 1 for `a >= 0`, else 0) |
//! | functions of two arguments | `atan2(y, x)`, `min(a, b)`, `max(a, b)` |
//!
//! ```
//! use lightquad::integral::expr::Expr;
//!
//! let f = Expr::compile("x*exp(-(x*y)) + step(y - 1)", &["x", "y"])?;
//! assert!((f.eval(&[2.0, 0.5]) - 2.0 * (-1.0f64).exp()).abs() < 1e-15);
//! assert_eq!(f.eval(&[0.0, 1.0]), 1.0);
//! // `-x^2` is refused with its column, not read as (-x)^2.
//! let err = Expr::compile("exp(-x^2)", &["x"]).unwrap_err();
//! assert_eq!(err.column, 7);
//! # Ok::<(), lightquad::integral::expr::ExprError>(())
//! ```

use exmex::{BinOp, Express, FlatEx, MakeOperators, MatchLiteral, Operator};

/// The most variables a domain gives an expression.
pub const MAX_VARIABLES: usize = 16;

/// The functions of one argument, by name.
const UNARY: [&str; 18] = [
    "sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh", "exp", "log", "ln",
    "log10", "sqrt", "abs", "floor", "ceil", "step",
];

/// The functions of two arguments, by name.
const BINARY: [&str; 3] = ["atan2", "min", "max"];

/// The constants, by name.
const CONSTANTS: [&str; 2] = ["pi", "e"];

/// A fault in an expression: where (1-based column, in characters) and what.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("column {column} of {text:?}: {message}")]
pub struct ExprError {
    /// The expression as written.
    pub text: String,
    /// The 1-based character column of the fault (one past the end for an
    /// expression that ends too soon).
    pub column: usize,
    /// What is wrong and what is accepted.
    pub message: String,
}

/// The operators exmex knows in lightquad's expressions
/// ([module documentation](self)).
#[derive(Debug, Clone)]
pub struct Operators;

fn bin(repr: &'static str, apply: fn(f64, f64) -> f64, prio: i64) -> Operator<'static, f64> {
    Operator::make_bin(
        repr,
        BinOp {
            apply,
            prio,
            is_commutative: false,
        },
    )
}

impl MakeOperators<f64> for Operators {
    fn make<'a>() -> Vec<Operator<'a, f64>> {
        let mut ops = vec![
            bin("^", f64::powf, 4),
            bin("*", |a, b| a * b, 2),
            bin("/", |a, b| a / b, 3),
            Operator::make_bin_unary(
                "+",
                BinOp {
                    apply: |a, b| a + b,
                    prio: 0,
                    is_commutative: true,
                },
                |a| a,
            ),
            Operator::make_bin_unary(
                "-",
                BinOp {
                    apply: |a, b| a - b,
                    prio: 1,
                    is_commutative: false,
                },
                |a| -a,
            ),
            bin("atan2", f64::atan2, 0),
            bin("min", f64::min, 0),
            bin("max", f64::max, 0),
            Operator::make_constant("pi", std::f64::consts::PI),
            Operator::make_constant("e", std::f64::consts::E),
        ];
        let unary: [(&str, Unary); 18] = [
            ("sin", f64::sin),
            ("cos", f64::cos),
            ("tan", f64::tan),
            ("asin", f64::asin),
            ("acos", f64::acos),
            ("atan", f64::atan),
            ("sinh", f64::sinh),
            ("cosh", f64::cosh),
            ("tanh", f64::tanh),
            ("exp", f64::exp),
            ("log", f64::ln),
            ("ln", f64::ln),
            ("log10", f64::log10),
            ("sqrt", f64::sqrt),
            ("abs", f64::abs),
            ("floor", f64::floor),
            ("ceil", f64::ceil),
            ("step", step),
        ];
        ops.extend(unary.into_iter().map(|(n, f)| Operator::make_unary(n, f)));
        ops
    }
}

/// A function of one argument, as exmex applies it.
type Unary = fn(f64) -> f64;

/// Heaviside's step: 1 for `a >= 0`, 0 below (and for NaN, which the
/// integrand's check then meets elsewhere).
fn step(a: f64) -> f64 {
    if a >= 0.0 { 1.0 } else { 0.0 }
}

/// Decimal numbers with an optional exponent, for exmex (whose own matcher
/// reads `1e-3` as `1e - 3`).
#[derive(Debug, Clone)]
pub struct Literal;

impl MatchLiteral for Literal {
    fn is_literal(text: &str) -> Option<&str> {
        let n = number_len(text);
        (n > 0).then(|| &text[..n])
    }
}

/// The bytes of the decimal number at the start of `text` (0 if none):
/// `digits [. digits] [e [+-] digits]` or `. digits [e ...]`.
fn number_len(text: &str) -> usize {
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

/// A compiled expression and where its variables come from.
#[derive(Debug, Clone)]
pub struct Expr {
    flat: FlatEx<f64, Operators, Literal>,
    /// For each of exmex's variables (in its order, sorted by name), the
    /// index into the values [`Expr::eval`] is given.
    slots: Vec<usize>,
    text: String,
}

impl Expr {
    /// Compiles `text` over the variables `variables` (the names a domain
    /// gives, in the order [`Expr::eval`] takes their values).
    pub fn compile(text: &str, variables: &[&str]) -> Result<Expr, ExprError> {
        check(text, variables)?;
        let flat = FlatEx::<f64, Operators, Literal>::parse(text).map_err(|e| ExprError {
            text: text.to_string(),
            column: 1,
            message: format!("not an expression: {e}"),
        })?;
        let slots = flat
            .var_names()
            .iter()
            .map(|name| variables.iter().position(|v| v == name))
            .collect::<Option<Vec<usize>>>()
            .ok_or_else(|| ExprError {
                text: text.to_string(),
                column: 1,
                message: format!(
                    "names {:?} beyond the domain's variables {variables:?}",
                    flat.var_names()
                ),
            })?;
        Ok(Expr {
            flat,
            slots,
            text: text.to_string(),
        })
    }

    /// The expression's value at `values` (one per variable of
    /// [`Expr::compile`], in its order); NaN if exmex refuses to evaluate.
    #[inline]
    pub fn eval(&self, values: &[f64]) -> f64 {
        let mut vars = [0.0; MAX_VARIABLES];
        for (v, &slot) in vars.iter_mut().zip(&self.slots) {
            *v = values[slot];
        }
        self.flat
            .eval(&vars[..self.slots.len()])
            .unwrap_or(f64::NAN)
    }

    /// The expression as written.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// True when the expression names `variable`.
    pub fn uses(&self, variable: &str) -> bool {
        self.flat.var_names().iter().any(|v| v == variable)
    }
}

/// One token of an expression and its byte offset.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Token<'a> {
    Number,
    Name(&'a str),
    Op(u8),
    Open,
    Close,
    Comma,
}

/// The tokens of `text` with their byte offsets; an unknown character is
/// a fault at its column.
fn tokens(text: &str) -> Result<Vec<(Token<'_>, usize)>, ExprError> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        let start = i;
        let token = match c {
            b' ' | b'\t' | b'\n' | b'\r' => {
                i += 1;
                continue;
            }
            b'0'..=b'9' | b'.' if number_len(&text[i..]) > 0 => {
                i += number_len(&text[i..]);
                Token::Number
            }
            b'a'..=b'z' | b'A'..=b'Z' | b'_' => {
                while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                    i += 1;
                }
                Token::Name(&text[start..i])
            }
            b'+' | b'-' | b'*' | b'/' | b'^' => {
                i += 1;
                Token::Op(c)
            }
            b'(' => {
                i += 1;
                Token::Open
            }
            b')' => {
                i += 1;
                Token::Close
            }
            b',' => {
                i += 1;
                Token::Comma
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

/// An [`ExprError`] at byte offset `at` of `text`.
fn fault(text: &str, at: usize, message: impl Into<String>) -> ExprError {
    ExprError {
        text: text.to_string(),
        column: text[..at.min(text.len())].chars().count() + 1,
        message: message.into(),
    }
}

/// How the operand just read began: after a unary sign, or as the exponent
/// of a `^` (either makes a following `^` ambiguous to exmex).
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
/// names the first fault with its column ([module documentation](self)).
pub fn check(text: &str, variables: &[&str]) -> Result<(), ExprError> {
    let toks = tokens(text)?;
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
                Token::Number => {
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
                            at,
                            lead,
                            call: Some(arity),
                            commas: 0,
                        });
                        lead = Lead::default();
                        i += 1;
                    } else if CONSTANTS.contains(&name) || variables.contains(&name) {
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

/// A `^` after an operand read with a sign before it, or as an exponent
/// itself, is ambiguous ([module documentation](self)).
fn ambiguous_power(text: &str, at: usize, last: Lead) -> Result<(), ExprError> {
    if last.signed {
        return Err(fault(
            text,
            at,
            "a signed base before `^` is ambiguous (exmex reads -a^b as (-a)^b): \
             write -(a^b) or (-a)^b",
        ));
    }
    if last.exponent {
        return Err(fault(
            text,
            at,
            "a chain of `^` is ambiguous (exmex reads a^b^c as (a^b)^c): write a^(b^c) or (a^b)^c",
        ));
    }
    Ok(())
}

/// The number of arguments of the function `name`, if it is one.
fn function(name: &str) -> Option<(&'static str, usize)> {
    UNARY
        .iter()
        .map(|&f| (f, 1))
        .chain(BINARY.iter().map(|&f| (f, 2)))
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
        UNARY.join(" "),
        BINARY.join(" ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every function and operator against Rust's own at a few points.
    #[test]
    fn expressions_agree_with_rust() -> Result<(), ExprError> {
        type F = fn(f64, f64) -> f64;
        let cases: [(&str, F); 14] = [
            ("x*exp(-(x*y))", |x, y| x * (-(x * y)).exp()),
            ("-(x^2) + y", |x, y| -(x * x) + y),
            ("(-x)^2", |x, _| x * x),
            ("2^-y", |_, y| 2f64.powf(-y)),
            ("x^(y^2)", |x, y| x.powf(y * y)),
            ("sin(x)^2 + cos(x)^2 - y", |x, y| {
                x.sin().powi(2) + x.cos().powi(2) - y
            }),
            ("atan2(y, x)", |x, y| y.atan2(x)),
            ("max(min(x, y), 0.5)", |x, y| x.min(y).max(0.5)),
            ("step(x - y)*2 - -y", |x, y| {
                (if x - y >= 0.0 { 2.0 } else { 0.0 }) + y
            }),
            ("1.5e-3*x + .5E+1/y", |x, y| 1.5e-3 * x + 5.0 / y),
            ("log(x) + ln(y) + log10(x)", |x, y| {
                x.ln() + y.ln() + x.log10()
            }),
            ("sqrt(abs(x - y)) * floor(x) * ceil(y)", |x, y| {
                (x - y).abs().sqrt() * x.floor() * y.ceil()
            }),
            ("pi*e - x/y/2", |x, y| {
                std::f64::consts::PI * std::f64::consts::E - x / y / 2.0
            }),
            (
                "tanh(x)*sinh(y)/cosh(y) + asin(0.5) + acos(0.5) + atan(x)*tan(y)",
                |x, y| {
                    x.tanh() * y.sinh() / y.cosh()
                        + 0.5f64.asin()
                        + 0.5f64.acos()
                        + x.atan() * y.tan()
                },
            ),
        ];
        for (text, f) in cases {
            let e = Expr::compile(text, &["x", "y"])?;
            for (x, y) in [(0.3, 1.7), (2.5, 0.25), (1.0, 1.0), (0.9, 0.1)] {
                let (got, want) = (e.eval(&[x, y]), f(x, y));
                assert!(
                    (got - want).abs() <= 1e-15 * want.abs().max(1.0),
                    "{text} at ({x}, {y}): {got} against {want}"
                );
            }
        }
        Ok(())
    }

    /// Each fault is named at its column.
    #[test]
    fn faults_are_named_at_their_column() {
        let cases = [
            ("exp(-x^2)", 7, "signed base"),
            ("x^2^3", 4, "chain"),
            ("sin x", 1, "parentheses"),
            ("x min y", 3, "expected an operator"),
            ("x +", 4, "ends"),
            ("3 4", 3, "expected an operator"),
            ("foo(x)", 1, "unknown name `foo`"),
            ("x + w", 5, "unknown name `w`"),
            ("x $ y", 3, "unexpected character"),
            ("(x + y", 1, "never closed"),
            ("x)", 2, "without a `(`"),
            ("atan2(x)", 8, "takes 2"),
            ("sin(x, y)", 6, "comma"),
            ("", 1, "ends"),
            ("x * é", 5, "unexpected character"),
        ];
        for (text, column, says) in cases {
            match Expr::compile(text, &["x", "y"]) {
                Ok(_) => panic!("{text} was accepted"),
                Err(e) => {
                    assert_eq!(e.column, column, "{text}: {e}");
                    assert!(e.message.contains(says), "{text}: {e}");
                }
            }
        }
    }
}
