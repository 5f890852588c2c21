//! Integrand expressions: a formula in a string, compiled once into a tree
//! of closures (`program`) and evaluated at every point without allocating.
//!
//! The grammar check (`check`) reads the text token by token first, so every fault is named
//! with its column. It refuses what tools read differently, rather than
//! pick one reading silently:
//!
//! - `-x^2` is `(-x)^2` in Excel (and in the expression crates exmex and
//!   fasteval), `-(x^2)` in Python and Julia: refused, with `-(x^2)` and
//!   `(-x)^2` offered (`exp(-x^2)` would be `exp(x^2)` in one reading);
//! - `a^b^c` is `(a^b)^c` in Excel and Matlab, `a^(b^c)` in Python: refused,
//!   with both offered;
//! - a function without parentheses (`sin x`) or between its arguments
//!   (`x min y`): refused; calls are `f(a)` and `f(a, b)`.
//!
//! Otherwise the usual precedence: `^`, then unary signs, then `* /`, then
//! `+ -`, each left to right (`a/b/c` is `(a/b)/c`). Numbers are decimal
//! with an optional exponent (`1.5e-3`, `.5`).
//!
//! | kind | names |
//! |---|---|
//! | constants | `pi`, `e` |
//! | operators | `+ - * / ^` (and unary `-`, `+`) |
//! | functions of one argument | `sin cos tan asin acos atan sinh cosh tanh exp log ln log10 sqrt abs floor ceil step` (`log` is the natural logarithm, as `ln`; `step(a)` is 1 for `a >= 0`, else 0) |
//! | functions of two arguments | `atan2(y, x)`, `min(a, b)`, `max(a, b)` |
//!
//! Why not an expression crate: exmex (maintained, MIT/Apache) and fasteval
//! (last released 2020) both read `-x^2` as `(-x)^2`; exmex also misreads
//! some sums inside calls (`sin(-(x + 0.5 + 0.5))` at x = -2.3624 is -3.20
//! to it) and its evaluator cost 4.8 times a Rust closure per point on a
//! 10-term integrand with elementary functions and 16 times on a 10-term
//! polynomial (benches/README.md), against this compiler's figures there;
//! evalexpr is AGPL.
//!
//! ```
//! use lightquad::integral::expr::Expr;
//!
//! let f = Expr::compile("x*exp(-(x*y)) + step(y - 1)", &["x", "y"])?;
//! assert!((f.eval(&[2.0, 0.5]) - 2.0 * (-1.0f64).exp()).abs() < 1e-15);
//! assert_eq!(f.eval(&[0.0, 1.0]), 1.0);
//! // `-x^2` is refused with its column, not read one way or the other.
//! let err = Expr::compile("exp(-x^2)", &["x"]).unwrap_err();
//! assert_eq!(err.column, 7);
//! # Ok::<(), lightquad::integral::expr::ExprError>(())
//! ```

mod check;
mod lex;
mod ops;
mod program;
mod tree;

/// The most variables a domain gives an expression.
pub const MAX_VARIABLES: usize = 16;

/// A fault in an expression: where (1-based column, in characters) and what.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("column {column} of {text:?}: {message}")]
pub struct ExprError {
    /// The expression, or the 60 characters about the fault where it is longer.
    pub text: String,
    /// The 1-based character column of the fault (one past the end for an
    /// expression that ends too soon).
    pub column: usize,
    /// What is wrong and what is accepted.
    pub message: String,
}

/// A compiled expression.
#[derive(Debug, Clone)]
pub struct Expr {
    program: program::Program,
    /// The variables it names, by index into the list it was compiled over.
    uses: Vec<usize>,
    variables: Vec<String>,
    text: String,
}

impl Expr {
    /// Compiles `text` over the variables `variables` (the names a domain
    /// gives, in the order [`Expr::eval`] takes their values; at most
    /// [`MAX_VARIABLES`]).
    pub fn compile(text: &str, variables: &[&str]) -> Result<Expr, ExprError> {
        check::check(text, variables)?;
        let toks = lex::tokens(text)?;
        let tree = tree::Parser {
            text,
            toks: &toks,
            variables,
            i: 0,
        }
        .parse()?
        .folded();
        let mut uses = Vec::new();
        tree.variables(&mut uses);
        uses.sort_unstable();
        uses.dedup();
        Ok(Expr {
            program: program::Program::compile(&tree),
            uses,
            variables: variables.iter().map(|v| v.to_string()).collect(),
            text: text.to_string(),
        })
    }

    /// The expression's value at `values` (one per variable of
    /// [`Expr::compile`], in its order).
    #[inline]
    pub fn eval(&self, values: &[f64]) -> f64 {
        self.program.eval(values)
    }

    /// The expression as written.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// True when the expression names `variable`.
    pub fn uses(&self, variable: &str) -> bool {
        self.uses.iter().any(|&k| self.variables[k] == variable)
    }
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
            (
                &format!("{}x{}", "(".repeat(70), ")".repeat(70)),
                65,
                "nested deeper",
            ),
            (&format!("{}x", "-".repeat(70)), 65, "nested deeper"),
            (&"x+".repeat(600), 1001, "longer than 1000"),
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
