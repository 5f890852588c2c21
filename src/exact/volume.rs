//! Closed forms of the volume-rendering terms (EQUATIONS.md, V-*) for the
//! constant-density sphere, `sigma = lambda kappa` on a chord of length `L`.

use std::f64::consts::PI;

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
