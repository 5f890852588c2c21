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
//!
//! ```
//! use lightquad::domain::Vec3;
//! use lightquad::volume::audit::{light_corrected, light_printed, s_corrected, s_printed};
//!
//! // From p = (0.6, 0, 0) toward +y the unit sphere is left at s = sqrt(1 - 0.6^2)
//! // = 0.8; the printed s(t), without the radius term, has no real value there.
//! let (p, d) = (Vec3::new(0.6, 0.0, 0.0), Vec3::y());
//! assert!((s_corrected(p, d, 1.0) - 0.8).abs() < 1e-15);
//! assert!(s_printed(p, d).is_nan());
//! // I_p = exp(-lambda kappa s) I_p, here with lambda kappa = 2, I_p = 3.
//! assert!((light_corrected(p, d, 1.0, 2.0, 3.0) - 3.0 * (-1.6f64).exp()).abs() < 1e-15);
//! // On the line through the centre the printed s is real but wrong: from
//! // (0, -0.5, 0) it gives 0.5 where the exit is 1.5 away.
//! let q = Vec3::new(0.0, -0.5, 0.0);
//! assert!((s_corrected(q, d, 1.0) - 1.5).abs() < 1e-15 && (s_printed(q, d) - 0.5).abs() < 1e-15);
//! assert!((light_printed(q, d, 2.0, 1.0) - (-1.0f64).exp()).abs() < 1e-15);
//! ```

use rand::SeedableRng;

use super::{ConstantSphere, Medium};
use crate::domain::Vec3;
use crate::geometry::Ray;
use crate::quadrature::AnyRule;

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

/// The audit as a Markdown section: the printed `s(t)` and `I_p(t)` at four
/// points against the corrected formulas and a quadrature shadow ray.
pub fn markdown() -> String {
    let mut out = String::new();
    out.push_str(
        "\n## Volume family: V-Lp audit: the printed s(t) against the corrected root and a quadrature shadow ray\n\n\
         Sphere of radius 1.5 at the origin, lambda kappa = 0.8, I_p = 1, light direction \
         d = (0.3, 0.8, -0.2)/|.|. `s` by quadrature is the shadow ray's optical depth \
         (64-node Gauss–Legendre) divided by lambda kappa. The printed radicand \
         <p,d>^2 - <p,p><d,d> is never positive (Cauchy–Schwarz): the printed forms are undefined in \
         real arithmetic off the line through the centre (docs/EQUATIONS.md audit points 1 and 2).\n\n\
         | point p | s printed | s corrected | s by quadrature | I_p printed | I_p corrected |\n\
         |---|---:|---:|---:|---:|---:|\n",
    );
    let (r, lk) = (1.5, 0.8);
    let d = Vec3::new(0.3, 0.8, -0.2).normalize();
    let Ok(medium) = ConstantSphere::new(Vec3::zeros(), r, 1.0) else {
        return out;
    };
    // Three points off the line through the centre along d, and one on it
    // (named as the multiple of d it is: its rounded coordinates are not on
    // the line, and the printed forms are undefined there).
    for (p, label) in [
        (Vec3::new(0.1, 0.2, 0.3), None),
        (Vec3::new(-1.0, 0.5, 0.2), None),
        (Vec3::new(0.0, 0.0, 1.4), None),
        (d * 0.5, Some("0.5 d, on the line through the centre")),
    ] {
        let point = match label {
            None => format!("({:.2}, {:.2}, {:.2})", p.x, p.y, p.z),
            Some(l) => format!("{l}: ({:?}, {:?}, {:?})", p.x, p.y, p.z),
        };
        let s_quad = Ray::new(p, d).ok().and_then(|ray| {
            let rule = AnyRule::by_name("gauss-legendre").ok()?;
            let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
            let mut total = 0.0;
            for piece in medium.support(&ray, 0.0, f64::INFINITY) {
                total += piece
                    .integrate(&rule, 64, &mut rng, |t| medium.density(ray.at(t)))
                    .ok()?
                    .value;
            }
            Some(total)
        });
        // The printed forms are undefined in real arithmetic where their
        // radicand is negative: say so, with the radicand, instead of NaN.
        let radicand = p.dot(&d).powi(2) - p.dot(&p) * d.dot(&d);
        let printed = |x: f64| {
            if x.is_nan() {
                format!("undefined: radicand {radicand:.3e} < 0")
            } else {
                format!("{x:.15}")
            }
        };
        out.push_str(&format!(
            "| {point} | {} | {:.15} | {} | {} | {:.15} |\n",
            printed(s_printed(p, d)),
            s_corrected(p, d, r),
            s_quad.map_or("failed".into(), |s| format!("{s:.15}")),
            printed(light_printed(p, d, lk, 1.0)),
            light_corrected(p, d, r, lk, 1.0),
        ));
    }
    out
}
