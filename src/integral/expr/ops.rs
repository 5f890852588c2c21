//! The constants and functions an expression may name.

use std::f64::consts::{E, PI};

/// A function of one argument.
pub(super) type Unary = fn(f64) -> f64;

/// A function of two arguments.
pub(super) type Binary = fn(f64, f64) -> f64;

/// The constants, by name.
pub(super) const CONSTANTS: [(&str, f64); 2] = [("pi", PI), ("e", E)];

/// The functions of one argument, by name (`log` is the natural logarithm).
pub(super) const UNARY: [(&str, Unary); 18] = [
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

/// The functions of two arguments, by name.
pub(super) const BINARY: [(&str, Binary); 3] =
    [("atan2", f64::atan2), ("min", f64::min), ("max", f64::max)];

/// Heaviside's step: 1 for `a >= 0`, else 0 (NaN included).
fn step(a: f64) -> f64 {
    if a >= 0.0 { 1.0 } else { 0.0 }
}

/// The value of the constant `name`, if it is one.
pub(super) fn constant(name: &str) -> Option<f64> {
    CONSTANTS.iter().find(|c| c.0 == name).map(|c| c.1)
}

/// The function of one argument named `name`, if it is one.
pub(super) fn unary(name: &str) -> Option<Unary> {
    UNARY.iter().find(|f| f.0 == name).map(|f| f.1)
}

/// The function of two arguments named `name`, if it is one.
pub(super) fn binary(name: &str) -> Option<Binary> {
    BINARY.iter().find(|f| f.0 == name).map(|f| f.1)
}
