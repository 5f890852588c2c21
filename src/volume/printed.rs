//! The document's printed formulas, runnable (docs/EQUATIONS.md, audit
//! points 1-3): an experiment selects which printed forms to evaluate in its
//! scene, and its report shows each printed value beside the corrected one.
//!
//! The printed `s(t)` (point 1) has the radicand `<p,d>^2 - <p,p><d,d>`,
//! never positive by Cauchy–Schwarz, so it has no real value off the line
//! through the centre. What a program computes from it depends on the
//! arithmetic, and the report gives all three:
//!
//! - real arithmetic: `sqrt` of a negative number is undefined (NaN);
//! - the principal complex square root: `sqrt(x) = i sqrt(-x)` for `x < 0`,
//!   so `I_p(t)` and `I_L` become complex; their real and imaginary parts;
//! - a silently clamped discriminant, `sqrt(max(0, x))`, what defensive code
//!   often does: a finite, wrong number.
//!
//! Point 2 (the exponent multiplies only the first summand,
//! `exp(-lambda kappa (-<p,d>/<d,d>) + sqrt(.)/<d,d>)`) and point 3 (the
//! printed `I_B = tau(t_n, t_f) I_b - int sigma dt`) are real either way.
//!
//! ```
//! use lightquad::domain::Vec3;
//! use lightquad::geometry::Ray;
//! use lightquad::volume::printed::{Printed, Sphere, evaluate};
//! use lightquad::volume::{DirectionalLight, VolumeScene};
//!
//! // A ray at height 0.6 through a unit sphere of sigma = 1 (chord [0, 1.6]),
//! // the light straight ahead, a background of 1.
//! let mut scene = VolumeScene::new(Ray::new(Vec3::new(-0.8, 0.6, 0.0), Vec3::x())?);
//! scene.light = Some(DirectionalLight::new(Vec3::x(), 1.0, None)?);
//! scene.background = Some(1.0);
//! let sphere = Sphere { centre: Vec3::zeros(), radius: 1.0, kappa: 1.0 };
//! let v = evaluate(&scene, &sphere, &[Printed::S, Printed::Background], (0.0, 1.6))?;
//! // Corrected: I_L = I_p L e^{-sigma L} (crate::exact::volume::light_ahead). The
//! // printed s(t) has a negative radicand on the whole chord: no real value.
//! let light = v.light.ok_or("no I_L")?;
//! assert!((light.corrected - 1.6 * (-1.6f64).exp()).abs() < 1e-12);
//! assert!(light.real.is_none() && light.negative_share == 1.0);
//! // Point 3: the printed I_B = tau I_b - sigma L, where tau I_b is meant.
//! let (printed, defined) = v.background.ok_or("no I_B")?;
//! assert!((defined - (-1.6f64).exp()).abs() < 1e-15 && (printed - (defined - 1.6)).abs() < 1e-15);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;

use super::scene::VolumeScene;
use crate::domain::Vec3;
use crate::error::QuadError;
use crate::quadrature::{GaussKronrod, Rule};

/// An audit point whose printed form an experiment evaluates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum Printed {
    /// Point 1: the printed `s(t)`, radius term missing.
    S,
    /// Point 2: the printed exponent, `-lambda kappa` on the first summand only.
    Exponent,
    /// Point 3: the printed `I_B` with its stray `- int sigma dt`.
    Background,
}

/// How the square root of the radicand is taken.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Arithmetic {
    /// `sqrt(x)`, NaN for `x < 0`.
    Real,
    /// `i sqrt(-x)` for `x < 0`.
    Complex,
    /// `sqrt(max(0, x))`.
    Clamped,
}

/// The constant sphere the printed formulas are written for.
#[derive(Debug, Clone, Copy)]
pub struct Sphere {
    /// Centre (the formulas take it at the origin: points are measured from it).
    pub centre: Vec3,
    /// Radius.
    pub radius: f64,
    /// Density.
    pub kappa: f64,
}

/// `I_L` with the selected printed forms in one arithmetic, as (real,
/// imaginary) parts: `int_{t_n}^{t_f} e^{-sigma (t - t_n)} e^{z(t)} I_p f dt`
/// with `z = -sigma s(t)` (corrected), `z = -sigma (-<p,d>) + root` (printed
/// exponent) and `root` the radicand's square root in that arithmetic
/// (`<d,d> = 1`); `f` the single-scattering factor. Adaptive Gauss–Kronrod on
/// the real and imaginary parts; an undefined root is an error.
fn light(
    scene: &VolumeScene,
    sphere: &Sphere,
    printed: &[Printed],
    arithmetic: Arithmetic,
    chord: (f64, f64),
) -> Result<(f64, f64), QuadError> {
    let Some(light) = scene.light else {
        return Ok((0.0, 0.0));
    };
    let sigma = scene.lambda * sphere.kappa;
    let d = light.toward_light;
    let scattering = light
        .albedo
        .map_or(1.0, |a| a * sigma / (4.0 * std::f64::consts::PI));
    let (t_n, t_f) = chord;
    let printed_s = printed.contains(&Printed::S);
    let printed_exponent = printed.contains(&Printed::Exponent);
    // z(t) = a + i b.
    let exponent = |t: f64| -> Result<(f64, f64), QuadError> {
        let p = scene.ray.at(t) - sphere.centre;
        let pd = p.dot(&d);
        let radius_term = if printed_s {
            0.0
        } else {
            sphere.radius * sphere.radius
        };
        let radicand = pd * pd - (p.dot(&p) - radius_term);
        let (re_root, im_root) = match (arithmetic, radicand >= 0.0) {
            (_, true) => (radicand.sqrt(), 0.0),
            (Arithmetic::Real, false) => {
                return Err(QuadError::NonFiniteIntegrand {
                    point: vec![t],
                    value: format!("sqrt({radicand:e}) in real arithmetic"),
                });
            }
            (Arithmetic::Complex, false) => (0.0, (-radicand).sqrt()),
            (Arithmetic::Clamped, false) => (0.0, 0.0),
        };
        Ok(if printed_exponent {
            (sigma * pd + re_root, im_root)
        } else {
            (-sigma * (-pd + re_root), -sigma * im_root)
        })
    };
    let rule = GaussKronrod {
        abs_tol: 0.0,
        rel_tol: 1e-13,
    };
    let mut rng = <rand_pcg::Pcg64 as rand::SeedableRng>::seed_from_u64(0);
    let len = t_f - t_n;
    let mut part = |imaginary: bool| -> Result<f64, QuadError> {
        let est = rule.try_integrate::<1, f64, _, _>(60_015, &mut rng, |u: [f64; 1]| {
            let t = t_n + len * u[0];
            let (a, b) = exponent(t)?;
            let tau = (-sigma * (t - t_n)).exp();
            let phase = if imaginary { b.sin() } else { b.cos() };
            Ok(tau * a.exp() * phase * light.intensity * scattering)
        })?;
        Ok(est.value * len)
    };
    Ok((part(false)?, part(true)?))
}

/// The share of the chord where the radicand of the selected `s(t)` is
/// negative, on 1001 equally spaced points.
fn negative_share(
    scene: &VolumeScene,
    sphere: &Sphere,
    printed: &[Printed],
    chord: (f64, f64),
) -> f64 {
    let Some(light) = scene.light else {
        return 0.0;
    };
    let d = light.toward_light;
    let radius_term = if printed.contains(&Printed::S) {
        0.0
    } else {
        sphere.radius * sphere.radius
    };
    let negative = (0..=1000)
        .filter(|&k| {
            let t = chord.0 + (chord.1 - chord.0) * k as f64 / 1000.0;
            let p = scene.ray.at(t) - sphere.centre;
            let pd = p.dot(&d);
            pd * pd - (p.dot(&p) - radius_term) < 0.0
        })
        .count();
    negative as f64 / 1001.0
}

/// The selected printed forms evaluated in one scene, beside the corrected values.
#[derive(Debug, Clone, PartialEq)]
pub struct Values {
    /// `I_L`, when a printed `s` or exponent was selected and the scene has a light.
    pub light: Option<LightValues>,
    /// `I_B` as printed and as defined, when the printed background was selected.
    pub background: Option<(f64, f64)>,
}

/// `I_L` in the three arithmetics and corrected.
#[derive(Debug, Clone, PartialEq)]
pub struct LightValues {
    /// Real arithmetic: None where the root is undefined somewhere on the chord.
    pub real: Option<f64>,
    /// The share of the chord where the printed radicand is negative.
    pub negative_share: f64,
    /// The principal complex square root: (real part, imaginary part).
    pub complex: (f64, f64),
    /// The clamped discriminant.
    pub clamped: f64,
    /// The corrected `I_L`.
    pub corrected: f64,
}

/// Evaluates the selected printed forms. `scene` is re-anchored at the
/// chord's middle (VolumeScene::anchored) by the caller; `chord` is where the
/// ray is inside the sphere.
pub fn evaluate(
    scene: &VolumeScene,
    sphere: &Sphere,
    printed: &[Printed],
    chord: (f64, f64),
) -> Result<Values, QuadError> {
    let light_values = if scene.light.is_some()
        && (printed.contains(&Printed::S) || printed.contains(&Printed::Exponent))
    {
        Some(LightValues {
            real: light(scene, sphere, printed, Arithmetic::Real, chord)
                .ok()
                .map(|v| v.0),
            negative_share: negative_share(scene, sphere, printed, chord),
            complex: light(scene, sphere, printed, Arithmetic::Complex, chord)?,
            clamped: light(scene, sphere, printed, Arithmetic::Clamped, chord)?.0,
            corrected: light(scene, sphere, &[], Arithmetic::Real, chord)?.0,
        })
    } else {
        None
    };
    // `tau I_b - sigma L` as printed, `tau I_b` as defined; no root, so every
    // arithmetic agrees.
    let background = match (scene.background, printed.contains(&Printed::Background)) {
        (Some(b), true) => {
            let depth = scene.lambda * sphere.kappa * (chord.1 - chord.0);
            Some(((-depth).exp() * b - depth, (-depth).exp() * b))
        }
        _ => None,
    };
    Ok(Values {
        light: light_values,
        background,
    })
}

/// The report section: each selected printed form's value in the three
/// arithmetics beside the corrected value (see [`evaluate`]).
pub fn section(
    scene: &VolumeScene,
    sphere: &Sphere,
    printed: &[Printed],
    chord: Option<(f64, f64)>,
) -> String {
    let mut md = String::from(
        "## The document's printed formulas in this scene (EQUATIONS.md audit points 1-3)\n\n",
    );
    let names: Vec<&str> = printed
        .iter()
        .map(|p| match p {
            Printed::S => "1: s(t) without the radius term",
            Printed::Exponent => "2: -lambda kappa on the first summand only",
            Printed::Background => "3: I_B with a stray - int sigma dt",
        })
        .collect();
    let _ = writeln!(
        md,
        "Printed forms evaluated: {}. Real arithmetic leaves the printed root undefined where its \
         radicand is negative; the principal complex square root gives a complex value (real and \
         imaginary part shown); a clamped discriminant `sqrt(max(0, x))` gives a finite, wrong \
         number. Values by adaptive Gauss–Kronrod (relative tolerance 1e-13).\n",
        names.join("; ")
    );
    let Some(chord) = chord else {
        md.push_str("The ray misses the sphere: every printed and corrected value is 0.\n");
        return md;
    };
    let values = match evaluate(scene, sphere, printed, chord) {
        Ok(v) => v,
        Err(e) => {
            let _ = writeln!(md, "The evaluation failed: {e}.");
            return md;
        }
    };
    md.push_str(
        "| quantity | real arithmetic | principal complex square root | clamped discriminant | corrected |\n\
         |---|---:|---:|---:|---:|\n",
    );
    if let Some(l) = &values.light {
        let real = l.real.map_or_else(
            || {
                format!(
                    "undefined: radicand < 0 on {:.1}% of the chord",
                    100.0 * l.negative_share
                )
            },
            |v| format!("{v:.12e}"),
        );
        let (re, im) = l.complex;
        let complex = if im == 0.0 {
            format!("{re:.12e}")
        } else {
            format!("{re:.12e} {im:+.12e} i")
        };
        let _ = writeln!(
            md,
            "| I_L | {real} | {complex} | {:.12e} | {:.12e} |",
            l.clamped, l.corrected
        );
    }
    if let Some((printed_value, corrected)) = values.background {
        let _ = writeln!(
            md,
            "| I_B | {printed_value:.12e} | {printed_value:.12e} | {printed_value:.12e} | {corrected:.12e} |"
        );
    }
    md
}
