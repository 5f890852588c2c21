//! The document's printed formulas for the light reaching a point (V-Lp), kept
//! verbatim so reports can show where they go wrong (docs/EQUATIONS.md, audit
//! points 1 and 2), beside the corrected ones.
//!
//! For a sphere of radius R centred at the origin and a point `p` inside it,
//! the distance to the boundary along `d` is the positive root of
//! `|p + s d|^2 = R^2`:
//!
//! - corrected: `s = (-<p,d> + sqrt(<p,d>^2 - <d,d> (<p,p> - R^2))) / <d,d>`;
//! - printed:   `s = -<p,d>/<d,d> + sqrt(<p,d>^2 - <p,p><d,d>)/<d,d>`, whose
//!   radicand is never positive (Cauchy–Schwarz), so it is NaN for every point
//!   off the line through the centre along `d` (and 0 or `-<p,d>/<d,d>` on it).
//!
//! And the light reaching `p`, `I_p(t) = exp(-lambda kappa s(t)) I_p`:
//!
//! - printed: `exp(-lambda kappa (-<p,d>/<d,d>) + sqrt(<p,d>^2 - <p,p><d,d>)/<d,d>) I_p`
//!   (the factor reaches only the first summand, audit point 2).

use crate::domain::Vec3;

/// `s(p)` as corrected: the positive root of `|p + s d|^2 = R^2`, written
/// exactly as the document's formula with the radius term restored.
pub fn s_corrected(p: Vec3, d: Vec3, radius: f64) -> f64 {
    let pd = p.dot(&d);
    let dd = d.dot(&d);
    (-pd + (pd * pd - dd * (p.dot(&p) - radius * radius)).sqrt()) / dd
}

/// `s(p)` as printed (radius term missing): NaN off the line through the centre.
pub fn s_printed(p: Vec3, d: Vec3) -> f64 {
    let pd = p.dot(&d);
    let dd = d.dot(&d);
    -pd / dd + (pd * pd - p.dot(&p) * dd).sqrt() / dd
}

/// `I_p(t)` as corrected: `exp(-lambda kappa s) I_p`.
pub fn light_corrected(p: Vec3, d: Vec3, radius: f64, lambda_kappa: f64, intensity: f64) -> f64 {
    (-lambda_kappa * s_corrected(p, d, radius)).exp() * intensity
}

/// `I_p(t)` as printed: the radius term missing and `-lambda kappa` applied to
/// the first summand only.
pub fn light_printed(p: Vec3, d: Vec3, lambda_kappa: f64, intensity: f64) -> f64 {
    let pd = p.dot(&d);
    let dd = d.dot(&d);
    (-lambda_kappa * (-pd / dd) + (pd * pd - p.dot(&p) * dd).sqrt() / dd).exp() * intensity
}
