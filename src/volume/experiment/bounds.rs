//! Bounds from the scene's numbers alone: of the terms I_E, I_B and I_L,
//! which refuse the quantity I (the terms may still be asked for alone) where
//! their sum could pass the f64 range, and a bound rounded down to print.

use std::sync::Arc;

use crate::volume::{EmissionMap, Medium, VolumeScene};

/// `x` with two significant digits, rounded toward 0 (a bound to print).
pub(super) fn round_down(x: f64) -> f64 {
    if !(x.is_finite() && x > 0.0) {
        return x;
    }
    let scale = 10f64.powi(x.log10().floor() as i32 - 1);
    (x / scale).floor() * scale
}

/// Upper bounds of I_E, I_B and I_L from the scene's numbers: V-E's largest
/// emitted radiance on each piece of the support times its length (for
/// emission proportional to the density, `k v`, at most `k / lambda` as
/// well: `int tau lambda v = 1 - tau`); I_b; and I_p albedo / (4 pi) times
/// `min(1, the depth bound)` with an albedo (the scattered fraction of the
/// light), I_p times the chord in the document's reduced form.
pub(super) fn term_bounds(scene: &VolumeScene) -> (f64, f64, f64) {
    let (scene, _) = scene.anchored();
    let pieces = |m: &Arc<dyn Medium>| -> Vec<(f64, f64)> {
        m.support(&scene.ray, scene.t_min, scene.t_max)
            .iter()
            .map(|p| {
                (
                    m.max_density(&scene.ray, p.start(), p.end()),
                    p.end() - p.start(),
                )
            })
            .collect()
    };
    let medium = scene.medium.as_ref().map(pieces).unwrap_or_default();
    let chord: f64 = medium.iter().map(|(_, len)| len).sum();
    let mass: f64 = medium.iter().map(|(v, len)| v * len).sum();
    let emission = match &scene.emission {
        None => 0.0,
        Some(EmissionMap::Constant(c)) => c * chord,
        Some(EmissionMap::Proportional(k)) if scene.lambda > 0.0 => {
            k * mass.min(1.0 / scene.lambda)
        }
        Some(EmissionMap::Proportional(k)) => k * mass,
        Some(EmissionMap::Table(t)) => t.points().iter().map(|p| p.1).fold(0.0, f64::max) * chord,
        Some(EmissionMap::Field(f)) => pieces(f).iter().map(|(v, len)| v * len).sum(),
    };
    let light = scene.light.as_ref().map_or(0.0, |l| match l.albedo {
        Some(a) => l.intensity * a / (4.0 * std::f64::consts::PI) * (scene.lambda * mass).min(1.0),
        None => l.intensity * chord,
    });
    (emission, scene.background.unwrap_or(0.0), light)
}
