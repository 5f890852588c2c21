//! Closed forms of the volume-rendering terms (docs/EQUATIONS.md, `V-*`): V-tau for
//! the constant-density sphere and for Gaussian blobs; V-E and V-L for the
//! constant sphere, `sigma = lambda kappa` on a chord of length `L`.
//!
//! ```
//! use lightquad::domain::Vec3;
//! use lightquad::exact::volume::{emission, emission_field_interval, gaussian_line_integral};
//!
//! // A unit Gaussian blob of width w, crossed through its centre: the line
//! // integral over +-12 w is the whole Gaussian, w sqrt(2 pi); a line at
//! // distance h from the centre sees it scaled by exp(-h^2 / (2 w^2)).
//! let (w, h) = (0.25, 0.1);
//! let whole = w * (2.0 * std::f64::consts::PI).sqrt();
//! let through = gaussian_line_integral(Vec3::zeros(), w, Vec3::new(-5.0, 0.0, 0.0), Vec3::x(), 2.0, 8.0);
//! assert!((through - whole).abs() < 1e-15);
//! let offset = gaussian_line_integral(Vec3::zeros(), w, Vec3::new(-5.0, h, 0.0), Vec3::x(), 2.0, 8.0);
//! assert!((offset - whole * (-h * h / (2.0 * w * w)).exp()).abs() < 1e-15);
//! // An emission field covering exactly the absorbing chord [a, b] is V-E with
//! // constant c: c (1 - e^{-sigma L}) / sigma.
//! let (sigma, a, b, c): (f64, f64, f64, f64) = (1.5, 2.0, 4.0, 0.8);
//! let want = c * (1.0 - (-sigma * (b - a)).exp()) / sigma;
//! assert!((emission(sigma, b - a, c) - want).abs() < 1e-15);
//! assert!((emission_field_interval(sigma, (a, b), c, (a, b)) - want).abs() < 1e-15);
//! ```

use std::f64::consts::PI;

use libm::{erf, erfc};

use crate::domain::Vec3;

/// `erf(b) - erf(a)` for `a <= b`, as a difference of erfcs in either tail,
/// where the difference of erfs would cancel. (libm's erf and erfc are
/// accurate to an ulp; statrs's are only good to ~1e-11.)
pub fn erf_difference(a: f64, b: f64) -> f64 {
    if a >= 0.0 {
        erfc(a) - erfc(b)
    } else if b <= 0.0 {
        erfc(-b) - erfc(-a)
    } else {
        erf(b) - erf(a)
    }
}

/// V-tau's line integral of a unit Gaussian blob
/// `exp(-|x - c|^2 / (2 w^2))` along `p + t d` (unit d) over `[t0, t1]`:
///
/// `|p + t d - c|^2 = h^2 + (t - t_c)^2` with `t_c = (c - p) . d` and `h` the
/// distance of `c` from the line, so the integral is
/// `e^{-h^2/(2w^2)} w sqrt(pi/2) [erf((t1 - t_c)/(w sqrt 2)) - erf((t0 - t_c)/(w sqrt 2))]`.
pub fn gaussian_line_integral(c: Vec3, w: f64, p: Vec3, d: Vec3, t0: f64, t1: f64) -> f64 {
    let tc = (c - p).dot(&d);
    let h2 = (p + d * tc - c).norm_squared();
    let s = w * std::f64::consts::SQRT_2;
    let diff = erf_difference((t0 - tc) / s, (t1.max(t0) - tc) / s);
    (-h2 / (2.0 * w * w)).exp() * w * (PI / 2.0).sqrt() * diff
}

/// V-tau, in log space: `ln tau = -sigma L`.
pub fn log_transmittance(sigma: f64, chord: f64) -> f64 {
    -sigma * chord
}

/// V-E with constant `c`: `int_0^L e^{-sigma t} c dt = c (1 - e^{-sigma L}) / sigma`,
/// written with `expm1` so it stays exact for `sigma L -> 0` (where it is `c L`).
pub fn emission(sigma: f64, chord: f64, c: f64) -> f64 {
    if sigma == 0.0 {
        return c * chord;
    }
    -c * (-sigma * chord).exp_m1() / sigma
}

/// V-E with an emission field of its own, constant `c` on `[e0, e1]`, seen
/// through an extinction constant `sigma` on `[a, b]` and 0 elsewhere along
/// the ray (two spheres of constant value: the density's chord and the
/// field's). The optical depth from the start of the ray to `t` is
/// `sigma |[a, min(t, b)]|`, so `[e0, e1]` splits into three parts:
///
/// - before `a`, `tau = 1`: `c |[e0, e1] ∩ (-inf, a]|`;
/// - `[lo, hi] = [e0, e1] ∩ [a, b]`: `c int_lo^hi e^{-sigma (t - a)} dt =
///   c e^{-sigma (lo - a)} (1 - e^{-sigma (hi - lo)}) / sigma` (`expm1`, and
///   `c (hi - lo)` at `sigma = 0`);
/// - after `b`, `tau = e^{-sigma (b - a)}`: `c e^{-sigma (b - a)} |[e0, e1] ∩ [b, inf)|`.
pub fn emission_field_interval(
    sigma: f64,
    (a, b): (f64, f64),
    c: f64,
    (e0, e1): (f64, f64),
) -> f64 {
    let len = |lo: f64, hi: f64| (hi - lo).max(0.0);
    let before = len(e0, e1.min(a));
    let (lo, hi) = (e0.max(a), e1.min(b));
    let inside = if hi <= lo {
        0.0
    } else if sigma == 0.0 {
        hi - lo
    } else {
        (-sigma * (lo - a)).exp() * -(-sigma * (hi - lo)).exp_m1() / sigma
    };
    let after = (-sigma * (b - a)).exp() * len(e0.max(b), e1);
    c * (before + inside + after)
}

/// The single-scattering factor of V-L: `albedo sigma / (4 pi)`, or 1 for the
/// document's reduced form (`albedo = None`).
fn scattering(sigma: f64, albedo: Option<f64>) -> f64 {
    albedo.map_or(1.0, |a| a * sigma / (4.0 * PI))
}

/// V-L with the light straight ahead along the ray (`d = v`): the shadow ray
/// from `r(t)` runs to the chord's exit, `s(t) = t_f - t`, so
/// `I_L = I_p int_0^L e^{-sigma t} e^{-sigma (L - t)} dt = I_p L e^{-sigma L}`.
pub fn light_ahead(sigma: f64, chord: f64, intensity: f64, albedo: Option<f64>) -> f64 {
    intensity * chord * (-sigma * chord).exp() * scattering(sigma, albedo)
}

/// V-L with the light behind the eye (`d = -v`): `s(t) = t - t_n`, so
/// `I_L = I_p int_0^L e^{-2 sigma t} dt = I_p (1 - e^{-2 sigma L}) / (2 sigma)`.
pub fn light_behind(sigma: f64, chord: f64, intensity: f64, albedo: Option<f64>) -> f64 {
    let integral = if sigma == 0.0 {
        chord
    } else {
        -(-2.0 * sigma * chord).exp_m1() / (2.0 * sigma)
    };
    intensity * integral * scattering(sigma, albedo)
}
