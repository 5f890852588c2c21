//! Integrand expressions: random expression trees printed with the fewest
//! parentheses their precedence needs, read back by lightquad, each value
//! against the tree evaluated directly in Rust; and random strings fuzzed
//! through `check` (never a panic; every refusal at `scene.integrand` with
//! a column). 2,000 cases each. (The expression crate exmex was a second
//! reader here until it was seen to misread its own precedence:
//! `sin(-(x + 0.5 + 0.5))` at x = -2.3624 is -3.20 to it, 0.978 truly.)

use lightquad::integral::expr::Expr;
use proptest::prelude::*;

/// A random expression over `x` and `y`.
#[derive(Debug, Clone)]
enum T {
    Num(f64),
    Var(usize),
    Neg(Box<T>),
    Bin(char, Box<T>, Box<T>),
    Pow(Box<T>, f64),
    Call1(&'static str, Box<T>),
    Call2(&'static str, Box<T>, Box<T>),
}

type Unary = fn(f64) -> f64;
type Binary = fn(f64, f64) -> f64;

const UNARY: [(&str, Unary); 9] = [
    ("sin", f64::sin),
    ("cos", f64::cos),
    ("exp", f64::exp),
    ("atan", f64::atan),
    ("tanh", f64::tanh),
    ("abs", f64::abs),
    ("floor", f64::floor),
    ("sqrt", f64::sqrt),
    ("ln", f64::ln),
];

const BINARY: [(&str, Binary); 3] = [("min", f64::min), ("max", f64::max), ("atan2", f64::atan2)];

fn tree() -> impl Strategy<Value = T> {
    let leaf = prop_oneof![
        prop::sample::select(vec![0.5, 1.0, 1.25, 2.0, 3.0, 0.75]).prop_map(T::Num),
        (0usize..2).prop_map(T::Var),
    ];
    leaf.prop_recursive(5, 40, 2, |inner| {
        prop_oneof![
            inner.clone().prop_map(|a| T::Neg(Box::new(a))),
            (
                prop::sample::select(vec!['+', '-', '*', '/']),
                inner.clone(),
                inner.clone()
            )
                .prop_map(|(op, a, b)| T::Bin(op, Box::new(a), Box::new(b))),
            (inner.clone(), prop::sample::select(vec![2.0, 3.0, 0.5]))
                .prop_map(|(a, k)| T::Pow(Box::new(a), k)),
            (0usize..UNARY.len(), inner.clone())
                .prop_map(|(f, a)| T::Call1(UNARY[f].0, Box::new(a))),
            (0usize..BINARY.len(), inner.clone(), inner).prop_map(|(f, a, b)| T::Call2(
                BINARY[f].0,
                Box::new(a),
                Box::new(b)
            )),
        ]
    })
}

impl T {
    /// The value, computed directly.
    fn value(&self, v: &[f64; 2]) -> f64 {
        match self {
            T::Num(c) => *c,
            T::Var(i) => v[*i],
            T::Neg(a) => -a.value(v),
            T::Bin(op, a, b) => {
                let (a, b) = (a.value(v), b.value(v));
                match op {
                    '+' => a + b,
                    '-' => a - b,
                    '*' => a * b,
                    _ => a / b,
                }
            }
            T::Pow(a, k) => a.value(v).powf(*k),
            T::Call1(f, a) => (UNARY.iter().find(|u| u.0 == *f).expect("known").1)(a.value(v)),
            T::Call2(f, a, b) => {
                (BINARY.iter().find(|u| u.0 == *f).expect("known").1)(a.value(v), b.value(v))
            }
        }
    }

    /// The largest magnitude of any of its parts at `v`: the scale of the
    /// rounding two evaluation orders may differ by.
    fn scale(&self, v: &[f64; 2]) -> f64 {
        let own = self.value(v).abs();
        let parts = match self {
            T::Num(_) | T::Var(_) => 0.0,
            T::Neg(a) | T::Pow(a, _) | T::Call1(_, a) => a.scale(v),
            T::Bin(_, a, b) | T::Call2(_, a, b) => a.scale(v).max(b.scale(v)),
        };
        own.max(parts).max(1.0)
    }

    /// Its binding strength: sums 1, products 2, signed 3, powers 4, atoms 5.
    fn level(&self) -> u8 {
        match self {
            T::Bin('+' | '-', ..) => 1,
            T::Bin(..) => 2,
            T::Neg(_) => 3,
            T::Pow(..) => 4,
            _ => 5,
        }
    }

    /// Printed with parentheses only where its place needs them: at least
    /// `min` binding strength; a power's base an atom, and no sign before
    /// a power (both refused as ambiguous).
    fn print(&self, min: u8) -> String {
        let text = match self {
            T::Num(c) => format!("{c}"),
            T::Var(i) => ["x", "y"][*i].to_string(),
            T::Neg(a) => {
                let inner = if a.level() == 4 { 5 } else { 3 };
                format!("-{}", a.print(inner))
            }
            T::Bin(op, a, b) => {
                let (l, r) = if matches!(op, '+' | '-') {
                    (1, 2)
                } else {
                    (2, 3)
                };
                format!("{} {op} {}", a.print(l), b.print(r))
            }
            T::Pow(a, k) => format!("{}^{k}", a.print(5)),
            T::Call1(f, a) => format!("{f}({})", a.print(1)),
            T::Call2(f, a, b) => format!("{f}({}, {})", a.print(1), b.print(1)),
        };
        if self.level() < min {
            format!("({text})")
        } else {
            text
        }
    }
}

/// `a` and `b` agree: both NaN, equal infinities, or within `tol` of the
/// largest magnitude `scale` met on the way.
fn agree(a: f64, b: f64, scale: f64, tol: f64) -> bool {
    (a.is_nan() && b.is_nan()) || a == b || (a - b).abs() <= tol * scale
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]

    /// lightquad's value of the printed tree is the tree's own.
    #[test]
    fn printed_trees_read_back_to_their_values(t in tree(), x in -3.0f64..3.0, y in -3.0f64..3.0) {
        let text = t.print(1);
        let e = Expr::compile(&text, &["x", "y"]).map_err(|e| TestCaseError::fail(format!("{text}: {e}")))?;
        let want = t.value(&[x, y]);
        let got = e.eval(&[x, y]);
        let scale = t.scale(&[x, y]);
        // The same operations in the same order, but for constants folded
        // and x^3 as x*x*x: within a few roundings.
        prop_assert!(agree(got, want, scale, 1e-13), "{text} at ({x}, {y}): {got} against the tree's {want}");

    }

    /// Strings of expression characters: `check` refuses or accepts, never
    /// panics; a refusal is at `scene.integrand` and names a column inside
    /// the text (or one past its end).
    #[test]
    fn random_expression_text_never_panics(text in "[xyzt0-9.eE+*/^(), -]{0,12}|(sin|exp|pi|min|atan2|x|y|2|\\^|-|\\(|\\)|,| |\\*|/|1e|é|\\+){0,16}") {
        refused_or_accepted(&text)?;
    }

    /// Arbitrary text, any characters.
    #[test]
    fn arbitrary_text_never_panics(text in ".{0,80}") {
        refused_or_accepted(&text)?;
    }
}

/// The law for one integrand text, through the validator and the compiler.
fn refused_or_accepted(text: &str) -> Result<(), TestCaseError> {
    let json = serde_json::json!({
        "name": "f", "family": "integral",
        "scene": {"domain": {"type": "cube", "dimension": 2}, "integrand": text},
        "quantities": ["integral"], "rules": [{"rule": "gauss-legendre"}],
        "budgets": [4], "repeats": 1, "reference": {"type": "converged"}
    });
    match lightquad::families::builtin().load(json, "h") {
        Ok(_) => {
            let e = Expr::compile(text, &["x1", "x2", "x", "y"])
                .map_err(|e| TestCaseError::fail(format!("{text}: {e}")))?;
            let _ = e.eval(&[0.5, 0.25, 0.5, 0.25]);
        }
        Err(e) => {
            prop_assert_eq!(e.path.as_str(), "scene.integrand", "{}", e);
            let column = lightquad::integral::expr::Expr::compile(text, &["x1", "x2", "x", "y"])
                .err()
                .map(|e| e.column)
                .ok_or_else(|| TestCaseError::fail(format!("{text}: refused by load, compiled")))?;
            prop_assert!(
                (1..=text.chars().count() + 1).contains(&column),
                "{text}: column {column}"
            );
            prop_assert!(e.message.contains(&format!("column {column}")), "{}", e);
        }
    }
    Ok(())
}
