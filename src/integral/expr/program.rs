//! The compiled expression: a tree of closures, one per operation, each
//! reading its operands directly where they are variables or numbers
//! (`x*y` is one closure), so evaluating allocates nothing and costs one
//! indirect call per operation. An integer power up to 64 is a chain of
//! products (`x^2` is `x*x`, as a person writes it in code).

use super::tree::{BinOp, Node};

/// A (sub)expression's value at the variables' values.
type Function = dyn Fn(&[f64]) -> f64 + Send + Sync;

/// A compiled (sub)expression.
type Compiled = Box<Function>;

/// A compiled expression (shared, not copied, by clones of the scene).
#[derive(Clone)]
pub(super) struct Program {
    root: std::sync::Arc<Function>,
}

impl std::fmt::Debug for Program {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Program")
    }
}

impl Program {
    /// The program of `node`.
    pub(super) fn compile(node: &Node) -> Program {
        Program {
            root: std::sync::Arc::from(compile(node)),
        }
    }

    /// The value at `vars`.
    #[inline]
    pub(super) fn eval(&self, vars: &[f64]) -> f64 {
        (self.root)(vars)
    }
}

/// `k` where `node` is the number `k`, an integer with `|k| <= 64`.
fn small_integer(node: &Node) -> Option<i32> {
    match node {
        Node::Num(x) if x.fract() == 0.0 && x.abs() <= 64.0 => Some(*x as i32),
        _ => None,
    }
}

/// `x^k` by products (`1 / x^-k` for negative `k`).
#[inline]
fn powi(x: f64, k: i32) -> f64 {
    let mut result = 1.0;
    let mut base = x;
    let mut e = k.unsigned_abs();
    while e > 0 {
        if e & 1 == 1 {
            result *= base;
        }
        base *= base;
        e >>= 1;
    }
    if k < 0 { 1.0 / result } else { result }
}

/// The closures of `a op b` for every shape of operands: a variable or a
/// number read directly, anything else called.
macro_rules! binary {
    ($a:expr, $b:expr, |$x:ident, $y:ident| $body:expr) => {{
        match ($a, $b) {
            (Node::Var(i), Node::Var(j)) => {
                let (i, j) = (*i, *j);
                Box::new(move |v: &[f64]| {
                    let ($x, $y) = (v[i], v[j]);
                    $body
                }) as Compiled
            }
            (Node::Var(i), Node::Num(c)) => {
                let (i, $y) = (*i, *c);
                Box::new(move |v: &[f64]| {
                    let $x = v[i];
                    $body
                })
            }
            (Node::Num(c), Node::Var(j)) => {
                let ($x, j) = (*c, *j);
                Box::new(move |v: &[f64]| {
                    let $y = v[j];
                    $body
                })
            }
            (a, Node::Var(j)) => {
                let (a, j) = (compile(a), *j);
                Box::new(move |v: &[f64]| {
                    let ($x, $y) = (a(v), v[j]);
                    $body
                })
            }
            (a, Node::Num(c)) => {
                let (a, $y) = (compile(a), *c);
                Box::new(move |v: &[f64]| {
                    let $x = a(v);
                    $body
                })
            }
            (Node::Var(i), b) => {
                let (i, b) = (*i, compile(b));
                Box::new(move |v: &[f64]| {
                    let ($x, $y) = (v[i], b(v));
                    $body
                })
            }
            (Node::Num(c), b) => {
                let ($x, b) = (*c, compile(b));
                Box::new(move |v: &[f64]| {
                    let $y = b(v);
                    $body
                })
            }
            (a, b) => {
                let (a, b) = (compile(a), compile(b));
                Box::new(move |v: &[f64]| {
                    let ($x, $y) = (a(v), b(v));
                    $body
                })
            }
        }
    }};
}

/// The closure of `node`.
fn compile(node: &Node) -> Compiled {
    match node {
        Node::Num(c) => {
            let c = *c;
            Box::new(move |_: &[f64]| c)
        }
        Node::Var(i) => {
            let i = *i;
            Box::new(move |v: &[f64]| v[i])
        }
        Node::Neg(a) => match a.as_ref() {
            Node::Var(i) => {
                let i = *i;
                Box::new(move |v: &[f64]| -v[i])
            }
            a => {
                let a = compile(a);
                Box::new(move |v: &[f64]| -a(v))
            }
        },
        Node::Bin(BinOp::Pow, a, b) if small_integer(b).is_some() => power(a, b),
        Node::Bin(BinOp::Add | BinOp::Sub, a, _) if is_sum(a) => sum(node),
        Node::Bin(BinOp::Add, a, b) => binary!(a.as_ref(), b.as_ref(), |x, y| x + y),
        Node::Bin(BinOp::Sub, a, b) => binary!(a.as_ref(), b.as_ref(), |x, y| x - y),
        Node::Bin(BinOp::Mul, a, b) => binary!(a.as_ref(), b.as_ref(), |x, y| x * y),
        Node::Bin(BinOp::Div, a, b) => binary!(a.as_ref(), b.as_ref(), |x, y| x / y),
        Node::Bin(BinOp::Pow, a, b) => binary!(a.as_ref(), b.as_ref(), |x, y| x.powf(y)),
        Node::Call1(f, a) => {
            let f = *f;
            match a.as_ref() {
                Node::Var(i) => {
                    let i = *i;
                    Box::new(move |v: &[f64]| f(v[i]))
                }
                a => {
                    let a = compile(a);
                    Box::new(move |v: &[f64]| f(a(v)))
                }
            }
        }
        Node::Call2(f, a, b) => {
            let f = *f;
            binary!(a.as_ref(), b.as_ref(), |x, y| f(x, y))
        }
    }
}

/// True when `node` is itself a sum or difference (so the node above it
/// starts a chain of three or more terms).
fn is_sum(node: &Node) -> bool {
    matches!(node, Node::Bin(BinOp::Add | BinOp::Sub, ..))
}

/// A chain `t0 ± t1 ± ... ± tk` as one closure over its terms, added left
/// to right as the tree says (one call a term instead of one a term and
/// one an addition).
fn sum(node: &Node) -> Compiled {
    let mut terms: Vec<(bool, Compiled)> = Vec::new();
    let mut spine = node;
    while let Node::Bin(op @ (BinOp::Add | BinOp::Sub), a, b) = spine {
        terms.push((*op == BinOp::Sub, compile(b)));
        spine = a;
    }
    let first = compile(spine);
    terms.reverse();
    Box::new(move |v: &[f64]| {
        let mut acc = first(v);
        for (minus, term) in &terms {
            let x = term(v);
            acc = if *minus { acc - x } else { acc + x };
        }
        acc
    })
}

/// `a^k` for a small integer `k` (`b` is the number `k`): `x*x` for 2.
fn power(a: &Node, b: &Node) -> Compiled {
    let k = small_integer(b).unwrap_or(1);
    let a = compile(a);
    match k {
        2 => Box::new(move |v: &[f64]| {
            let x = a(v);
            x * x
        }),
        _ => Box::new(move |v: &[f64]| powi(a(v), k)),
    }
}
