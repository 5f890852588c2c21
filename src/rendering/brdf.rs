//! BRDFs of the rendering family (R-H, R-A, R-rec): the scattering term
//! `f_r(w', w)` of the hemispherical form R-H, with importance sampling,
//! its density and the inverse of the sampling map.
//!
//! Directions are unit vectors in the local shading frame (normal `+z`):
//! `wi` points toward the light, `wo` toward the viewer. Every BRDF here is
//! zero unless both are above the horizon (`z > 0`), and is reciprocal,
//! `f(wi, wo) = f(wo, wi)` (R-rec).
//!
//! | type | `f(wi, wo)` | sampling |
//! |---|---|---|
//! | [`Lambert`] | `rho / pi` | Malley (cosine-weighted) |
//! | [`Phong`] | `k_s max(0, cos alpha)^n` (W-Phong, unnormalised) | the lobe `(n+1)/(2 pi) cos^n alpha` about the mirror direction |
//! | [`NormalizedPhong`] | `k_s (n+2)/(2 pi) max(0, cos alpha)^n` | as [`Phong`] |
//! | [`Ggx`] | `D(h) G2(wi, wo) / (4 cos theta_i cos theta_o)`, Fresnel 1 | visible normals (Heitz 2018) |
//!
//! [`Brdf::pdf`] is the density in solid angle of the sampling map over the
//! whole sphere of directions, so it integrates to 1 over the sphere for
//! every `wo` above the horizon. The Phong lobes and GGX's reflected
//! normals can land below the horizon: [`Brdf::sample`] returns `None`
//! there (the path is absorbed), and the `Some` samples have the density
//! `pdf` restricted to the upper hemisphere, of mass `1 - P(None)`. A
//! renderer's estimator `sum f cos L / pdf` stays unbiased with those
//! `None` counted as zero.
//!
//! Bad directions (not finite, not unit within `1e-9`) give `eval` and
//! `pdf` 0 and `sample` and `invert` `None`, never a panic or a `NaN`; so
//! does a `u` outside `[0, 1]^2`.
//!
//! ```
//! use std::f64::consts::PI;
//! use lightquad::domain::Vec3;
//! use lightquad::rendering::brdf::{Brdf, Lambert, Phong};
//!
//! let wo = Vec3::new(0.6, 0.0, 0.8);
//! // Lambert: f = rho / pi, and a cosine-weighted sample weighs f cos / pdf = rho.
//! let lambert = Lambert::new(0.5)?;
//! let s = lambert.sample(wo, [0.3, 0.7]).ok_or(lightquad::QuadError::invalid("u", 0.3, "a sample"))?;
//! assert!((lambert.eval(s.wi, wo) - 0.5 / PI).abs() < 1e-16);
//! assert!((s.weight - 0.5).abs() < 1e-15);
//! // The inverse of the sampling map recovers u.
//! let u = lambert.invert(wo, s.wi).ok_or(lightquad::QuadError::invalid("wi", 0.0, "a sample"))?;
//! assert!((u[0] - 0.3).abs() < 1e-15 && (u[1] - 0.7).abs() < 1e-15);
//! // Phong: the mirror direction of wo gets the lobe's peak k_s.
//! let phong = Phong::new(0.8, 1e4)?;
//! assert!((phong.eval(Vec3::new(-0.6, 0.0, 0.8), wo) - 0.8).abs() < 1e-15);
//! // Out-of-range parameters are errors that name the parameter.
//! assert!(Lambert::new(1.5).is_err() && Phong::new(0.5, f64::NAN).is_err());
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use std::f64::consts::PI;

use crate::domain::{Frame, Vec3, azimuth_fraction};
use crate::error::QuadError;

/// How far from unit length a direction may be (relative).
const UNIT_TOL: f64 = 1e-9;

/// Largest Phong exponent accepted: the lobe's angular width `1/sqrt(n)`
/// stays at `1e-4` rad or more, far above the `~1e-8` rad (`sqrt(eps)`) at
/// which `cos alpha` of unit vectors in f64 stops resolving angles.
pub const MAX_EXPONENT: f64 = 1e8;

/// Smallest GGX `alpha` accepted (the same `1e-4` rad lobe width as
/// [`MAX_EXPONENT`]; `D`'s peak `1/(pi alpha^2)` is then `3.2e7`).
pub const MIN_ALPHA: f64 = 1e-4;

/// A sampled direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// The sampled direction toward the light, unit, above the horizon.
    pub wi: Vec3,
    /// Its density in solid angle, [`Brdf::pdf`]`(wo, wi)`.
    pub pdf: f64,
    /// `f(wi, wo) cos(theta_i) / pdf`, the sample's weight in the R-H
    /// estimator.
    pub weight: f64,
}

/// A BRDF over directions in the local shading frame (normal `+z`).
pub trait Brdf {
    /// `f_r(wi, wo)` (R-H), 0 unless both directions are above the horizon.
    fn eval(&self, wi: Vec3, wo: Vec3) -> f64;

    /// The direction `wi` that `u` in `[0, 1]^2` maps to for the viewer at
    /// `wo`, with its pdf and weight; `None` where it lies below the
    /// horizon (the map's mass there is part of [`Brdf::pdf`]'s), where
    /// `wo` is below it, or for bad input.
    fn sample(&self, wo: Vec3, u: [f64; 2]) -> Option<Sample>;

    /// The density in solid angle of [`Brdf::sample`]'s map at `wi`, over
    /// the whole sphere (it integrates to 1 there for `wo` above the
    /// horizon); 0 for `wo` below it.
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f64;

    /// The `u` that [`Brdf::sample`]'s map takes to `wi`, where the map
    /// reaches `wi` (`pdf(wo, wi) > 0`, below the horizon included), else
    /// `None`.
    fn invert(&self, wo: Vec3, wi: Vec3) -> Option<[f64; 2]>;

    /// The unit normal (shading frame) of the plane through the origin
    /// beyond which the lobe for `wo` is clamped to zero with a kink, where
    /// it has one inside the hemisphere: Phong's `max(0, cos alpha)` about
    /// the mirror direction. An integration that splits there sees a
    /// smooth integrand on each side.
    fn clamp(&self, _wo: Vec3) -> Option<Vec3> {
        None
    }
}

/// True for a finite vector of unit length within [`UNIT_TOL`].
fn is_unit(w: Vec3) -> bool {
    w.iter().all(|x| x.is_finite()) && (w.norm_squared() - 1.0).abs() <= 2.0 * UNIT_TOL
}

/// Both unit and above the horizon.
fn both_above(wi: Vec3, wo: Vec3) -> bool {
    is_unit(wi) && is_unit(wo) && wi.z > 0.0 && wo.z > 0.0
}

/// `u` in `[0, 1]^2` (false for `NaN`).
fn valid_u(u: [f64; 2]) -> bool {
    u.iter().all(|x| (0.0..=1.0).contains(x))
}

/// `x` checked to be in `[0, 1]`, else the error naming `name`.
fn unit_interval(name: &str, x: f64) -> Result<f64, QuadError> {
    if (0.0..=1.0).contains(&x) {
        Ok(x)
    } else {
        Err(QuadError::invalid(name, x, "a number in [0, 1]"))
    }
}

/// The Lambertian BRDF (R-H): `f = rho / pi` for both directions above the
/// horizon. Directional albedo `int_H f cos theta_i d w_i = rho` for every `wo`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lambert {
    /// Albedo `rho` in `[0, 1]`.
    pub albedo: f64,
}

impl Lambert {
    /// The Lambertian BRDF of albedo `albedo` in `[0, 1]`.
    pub fn new(albedo: f64) -> Result<Self, QuadError> {
        Ok(Lambert {
            albedo: unit_interval("albedo", albedo)?,
        })
    }
}

impl Brdf for Lambert {
    /// `f = rho / pi` (R-H).
    fn eval(&self, wi: Vec3, wo: Vec3) -> f64 {
        if both_above(wi, wo) {
            self.albedo / PI
        } else {
            0.0
        }
    }

    /// Malley's map: `sin^2 theta = u_1`, `phi = 2 pi u_2`, density
    /// `cos theta / pi` (as [`crate::domain::HemisphereMap::Cosine`]);
    /// weight `rho`.
    fn sample(&self, wo: Vec3, u: [f64; 2]) -> Option<Sample> {
        if !(is_unit(wo) && wo.z > 0.0 && valid_u(u)) {
            return None;
        }
        let (sin_phi, cos_phi) = (2.0 * PI * u[1]).sin_cos();
        let (sin_theta, cos_theta) = (u[0].sqrt(), (1.0 - u[0]).sqrt());
        if cos_theta <= 0.0 {
            return None;
        }
        Some(Sample {
            wi: Vec3::new(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta),
            pdf: cos_theta / PI,
            weight: self.albedo,
        })
    }

    /// `cos theta_i / pi` above the horizon, 0 below.
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f64 {
        if both_above(wi, wo) { wi.z / PI } else { 0.0 }
    }

    /// `u_1 = sin^2 theta_i = x^2 + y^2`, `u_2 = atan2(y, x) / (2 pi)`.
    fn invert(&self, wo: Vec3, wi: Vec3) -> Option<[f64; 2]> {
        if !both_above(wi, wo) {
            return None;
        }
        Some([
            (wi.x * wi.x + wi.y * wi.y).min(1.0),
            azimuth_fraction(wi.y, wi.x),
        ])
    }
}

/// The mirror reflection of `wo` about the normal `+z`: `r = 2 (wo . n) n - wo`.
fn mirror(wo: Vec3) -> Vec3 {
    Vec3::new(-wo.x, -wo.y, wo.z)
}

/// `max(0, cos alpha)^n` from `1 - cos alpha` (accurate near the peak,
/// where `cos alpha` itself rounds to 1): `exp(n ln(1 - (1 - cos alpha)))`,
/// 0 for `cos alpha <= 0`; never `NaN` for `n` in `[0, MAX_EXPONENT]`.
fn cos_power(one_minus_cos: f64, n: f64) -> f64 {
    if one_minus_cos < 1.0 {
        (n * (-one_minus_cos.max(0.0)).ln_1p()).exp()
    } else {
        0.0
    }
}

/// The cosine-power lobe `(n+1)/(2 pi) max(0, cos alpha)^n` about the
/// mirror direction `r` of `wo` (W-Phong), a density over the sphere.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Lobe {
    n: f64,
}

impl Lobe {
    fn new(n: f64) -> Result<Self, QuadError> {
        if n.is_finite() && (0.0..=MAX_EXPONENT).contains(&n) {
            Ok(Lobe { n })
        } else {
            Err(QuadError::invalid(
                "n",
                n,
                format!("a finite exponent in [0, {MAX_EXPONENT:e}]"),
            ))
        }
    }

    /// `1 - cos alpha = |wi - r|^2 / 2`, exact to rounding for small
    /// angles (where `1 - wi . r` would cancel), `wi . r = 2 z_i z_o - wi . wo`.
    fn one_minus_cos(wi: Vec3, wo: Vec3) -> f64 {
        (wi - mirror(wo)).norm_squared() / 2.0
    }

    /// `max(0, cos alpha)^n` (W-Phong).
    fn shape(&self, wi: Vec3, wo: Vec3) -> f64 {
        cos_power(Self::one_minus_cos(wi, wo), self.n)
    }

    /// The lobe's density `(n+1)/(2 pi) max(0, cos alpha)^n` over the sphere.
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f64 {
        if is_unit(wi) && is_unit(wo) && wo.z > 0.0 {
            (self.n + 1.0) / (2.0 * PI) * self.shape(wi, wo)
        } else {
            0.0
        }
    }

    /// `cos alpha = u_1^(1/(n+1))` (CDF `cos^(n+1) alpha` of the density
    /// `(n+1) cos^n alpha d cos alpha`), `phi = 2 pi u_2` in the frame
    /// about `r` ([`Frame::from_normal`]); `1 - cos alpha = -expm1(ln u_1 /
    /// (n+1))` keeps the small angles of large exponents. Returns `wi`
    /// (possibly below the horizon) and `1 - cos alpha`.
    fn map(&self, wo: Vec3, u: [f64; 2]) -> Option<(Vec3, f64)> {
        if !(is_unit(wo) && wo.z > 0.0 && valid_u(u)) {
            return None;
        }
        let frame = Frame::from_normal(mirror(wo)).ok()?;
        let omc = (-(u[0].ln() / (self.n + 1.0)).exp_m1()).clamp(0.0, 1.0);
        let cos_alpha = 1.0 - omc;
        let sin_alpha = (omc * (2.0 - omc)).sqrt();
        let (sin_phi, cos_phi) = (2.0 * PI * u[1]).sin_cos();
        let local = Vec3::new(sin_alpha * cos_phi, sin_alpha * sin_phi, cos_alpha);
        Some((frame.to_world(local), omc))
    }

    /// The sample for `wo` and `u`, `f` and `weight` from the caller's `scale`
    /// (`f = scale cos^n alpha`), `None` below the horizon.
    fn sample(&self, wo: Vec3, u: [f64; 2], scale: f64) -> Option<Sample> {
        let (wi, omc) = self.map(wo, u)?;
        if wi.z <= 0.0 {
            return None;
        }
        let pdf = (self.n + 1.0) / (2.0 * PI) * cos_power(omc, self.n);
        if pdf <= 0.0 {
            return None;
        }
        // f cos / pdf = scale 2 pi cos theta_i / (n + 1): the cos^n cancels.
        Some(Sample {
            wi,
            pdf,
            weight: scale * 2.0 * PI * wi.z / (self.n + 1.0),
        })
    }

    /// `u_1 = cos^(n+1) alpha`, `u_2` the azimuth about `r` in the frame of
    /// [`Lobe::map`]; `None` outside the lobe (`cos alpha <= 0`).
    fn invert(&self, wo: Vec3, wi: Vec3) -> Option<[f64; 2]> {
        if !(is_unit(wi) && is_unit(wo) && wo.z > 0.0) {
            return None;
        }
        let omc = Self::one_minus_cos(wi, wo);
        if omc >= 1.0 {
            return None;
        }
        let frame = Frame::from_normal(mirror(wo)).ok()?;
        let l = frame.to_local(wi);
        let u1 = ((self.n + 1.0) * (-omc).ln_1p()).exp().min(1.0);
        Some([u1, azimuth_fraction(l.y, l.x)])
    }
}

/// The documents' unnormalised Phong lobe (W-Phong, as the scattering term
/// of R-H): `f = k_s max(0, cos alpha)^n`, `alpha` the angle between `wi`
/// and the mirror reflection `r = (-x_o, -y_o, z_o)` of `wo`, 0 unless both
/// directions are above the horizon. `cos alpha = 2 z_i z_o - wi . wo` is
/// symmetric in `wi`, `wo`, so `f` is reciprocal (R-rec).
///
/// Directional albedo at normal incidence `a(n) = k_s 2 pi / (n + 2)`
/// ([`crate::exact::rendering::phong_albedo_normal`]). Off normal incidence
/// it is smaller (measured by quadrature, see tests/it/rendering_brdf.rs), so
/// the lobe conserves energy exactly when `k_s 2 pi / (n + 2) <= 1`: for
/// every `k_s <= 1` once `n >= 2 pi - 2 = 4.28`, but not at `n = 0`, `k_s >
/// 1/pi` (albedo `pi k_s`).
///
/// Sampling: the lobe `(n+1)/(2 pi) cos^n alpha` about `r`; directions below
/// the horizon are returned as `None` (their mass, up to 1/2 at grazing
/// `wo`, stays in [`Brdf::pdf`]). Weight `k_s 2 pi cos theta_i / (n + 1)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Phong {
    /// Specular coefficient `k_s` in `[0, 1]`.
    pub k_s: f64,
    lobe: Lobe,
}

impl Phong {
    /// The lobe `k_s cos^n alpha`, `k_s` in `[0, 1]`, `n` finite in `[0,
    /// MAX_EXPONENT]`.
    pub fn new(k_s: f64, n: f64) -> Result<Self, QuadError> {
        Ok(Phong {
            k_s: unit_interval("k_s", k_s)?,
            lobe: Lobe::new(n)?,
        })
    }

    /// The exponent `n`.
    pub fn exponent(&self) -> f64 {
        self.lobe.n
    }
}

impl Brdf for Phong {
    /// `k_s max(0, cos alpha)^n` (W-Phong).
    fn eval(&self, wi: Vec3, wo: Vec3) -> f64 {
        if both_above(wi, wo) {
            self.k_s * self.lobe.shape(wi, wo)
        } else {
            0.0
        }
    }

    fn sample(&self, wo: Vec3, u: [f64; 2]) -> Option<Sample> {
        self.lobe.sample(wo, u, self.k_s)
    }

    /// `(n+1)/(2 pi) max(0, cos alpha)^n` over the sphere.
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f64 {
        self.lobe.pdf(wo, wi)
    }

    fn invert(&self, wo: Vec3, wi: Vec3) -> Option<[f64; 2]> {
        self.lobe.invert(wo, wi)
    }

    /// The plane normal to the mirror direction `(-x_o, -y_o, z_o)`.
    fn clamp(&self, wo: Vec3) -> Option<Vec3> {
        Some(Vec3::new(-wo.x, -wo.y, wo.z))
    }
}

/// The energy-normalised Phong lobe: `f = k_s (n+2)/(2 pi) max(0, cos
/// alpha)^n`, [`Phong`] scaled by `(n+2)/(2 pi)`, so that its directional
/// albedo at normal incidence is `k_s (n+2)/(2 pi) 2 pi/(n+2) = k_s`
/// exactly, and at every other incidence at most that: it conserves energy
/// for every `k_s <= 1` and `n` (R-H). Reciprocal as [`Phong`] (R-rec).
///
/// Sampling as [`Phong`]; weight `k_s (n+2)/(n+1) cos theta_i`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NormalizedPhong {
    /// Albedo at normal incidence `k_s` in `[0, 1]`.
    pub k_s: f64,
    lobe: Lobe,
}

impl NormalizedPhong {
    /// The lobe `k_s (n+2)/(2 pi) cos^n alpha`, `k_s` in `[0, 1]`, `n` finite
    /// in `[0, MAX_EXPONENT]`.
    pub fn new(k_s: f64, n: f64) -> Result<Self, QuadError> {
        Ok(NormalizedPhong {
            k_s: unit_interval("k_s", k_s)?,
            lobe: Lobe::new(n)?,
        })
    }

    /// The exponent `n`.
    pub fn exponent(&self) -> f64 {
        self.lobe.n
    }

    /// `k_s (n+2)/(2 pi)`.
    fn scale(&self) -> f64 {
        self.k_s * (self.lobe.n + 2.0) / (2.0 * PI)
    }
}

impl Brdf for NormalizedPhong {
    /// `k_s (n+2)/(2 pi) max(0, cos alpha)^n` (W-Phong normalised).
    fn eval(&self, wi: Vec3, wo: Vec3) -> f64 {
        if both_above(wi, wo) {
            self.scale() * self.lobe.shape(wi, wo)
        } else {
            0.0
        }
    }

    fn sample(&self, wo: Vec3, u: [f64; 2]) -> Option<Sample> {
        self.lobe.sample(wo, u, self.scale())
    }

    /// `(n+1)/(2 pi) max(0, cos alpha)^n` over the sphere.
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f64 {
        self.lobe.pdf(wo, wi)
    }

    fn invert(&self, wo: Vec3, wi: Vec3) -> Option<[f64; 2]> {
        self.lobe.invert(wo, wi)
    }

    /// The plane normal to the mirror direction `(-x_o, -y_o, z_o)`.
    fn clamp(&self, wo: Vec3) -> Option<Vec3> {
        Some(Vec3::new(-wo.x, -wo.y, wo.z))
    }
}

/// The GGX (Trowbridge–Reitz) microfacet BRDF, isotropic, with Fresnel 1
/// (a perfect conductor, so that the white furnace measures only the
/// energy lost to single scattering) and the height-correlated Smith
/// masking-shadowing function (E. Heitz, "Understanding the masking-shadowing
/// function in microfacet-based BRDFs", JCGT 3(2), 2014):
///
/// `f(wi, wo) = D(h) G2(wi, wo) / (4 cos theta_i cos theta_o)`, `h = (wi + wo) / |wi + wo|`,
/// `D(h) = alpha^2 / (pi (alpha^2 h_z^2 + h_x^2 + h_y^2)^2)`,
/// `Lambda(w) = (sqrt(1 + alpha^2 tan^2 theta) - 1) / 2`,
/// `G1(w) = 1 / (1 + Lambda(w))`, `G2(wi, wo) = 1 / (1 + Lambda(wi) + Lambda(wo))`.
///
/// Symmetric in `wi`, `wo` (R-rec). Sampling: the visible normals
/// `D_wo(h) = G1(wo) max(0, wo . h) D(h) / cos theta_o` by E. Heitz,
/// "Sampling the GGX distribution of visible normals", JCGT 7(4), 2018,
/// reflected, `wi = 2 (wo . h) h - wo`; pdf `D_wo(h) / (4 wo . h) = G1(wo)
/// D(h) / (4 cos theta_o)` over the sphere, `None` for the reflections
/// below the horizon; weight `G2(wi, wo) / G1(wo)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ggx {
    /// Roughness `alpha` in `[MIN_ALPHA, 1]`.
    pub alpha: f64,
}

impl Ggx {
    /// GGX of roughness `alpha` in `[MIN_ALPHA, 1]`.
    pub fn new(alpha: f64) -> Result<Self, QuadError> {
        if (MIN_ALPHA..=1.0).contains(&alpha) {
            Ok(Ggx { alpha })
        } else {
            Err(QuadError::invalid(
                "alpha",
                alpha,
                format!("a roughness in [{MIN_ALPHA:e}, 1]"),
            ))
        }
    }

    /// The normal distribution `D(h) = alpha^2 / (pi (alpha^2 h_z^2 + h_x^2
    /// + h_y^2)^2)` for unit `h` above the horizon (`alpha^2 cos^2 + sin^2`,
    /// free of the cancellation of `cos^2 (alpha^2 - 1) + 1` near the
    /// peak), 0 below; `int D(h) cos theta_h dh = 1`.
    pub fn d(&self, h: Vec3) -> f64 {
        if !(is_unit(h) && h.z > 0.0) {
            return 0.0;
        }
        let a2 = self.alpha * self.alpha;
        let q = a2 * h.z * h.z + h.x * h.x + h.y * h.y;
        a2 / (PI * q * q)
    }

    /// Smith's `Lambda(w) = (sqrt(1 + alpha^2 tan^2 theta) - 1) / 2`,
    /// evaluated as `t / (2 (1 + sqrt(1 + t)))`, `t = alpha^2 tan^2 theta`
    /// (no cancellation near the normal); `w` above the horizon.
    pub fn lambda(&self, w: Vec3) -> f64 {
        let t = self.alpha * self.alpha * (w.x * w.x + w.y * w.y) / (w.z * w.z);
        if t.is_finite() {
            t / (2.0 * (1.0 + (1.0 + t).sqrt()))
        } else {
            f64::INFINITY
        }
    }

    /// Smith's masking `G1(w) = 1 / (1 + Lambda(w))`, 0 at or below the horizon.
    pub fn g1(&self, w: Vec3) -> f64 {
        if is_unit(w) && w.z > 0.0 {
            1.0 / (1.0 + self.lambda(w))
        } else {
            0.0
        }
    }

    /// Height-correlated masking-shadowing `G2(wi, wo) = 1 / (1 +
    /// Lambda(wi) + Lambda(wo))`, 0 unless both are above the horizon.
    pub fn g2(&self, wi: Vec3, wo: Vec3) -> f64 {
        if both_above(wi, wo) {
            1.0 / (1.0 + self.lambda(wi) + self.lambda(wo))
        } else {
            0.0
        }
    }

    /// The distribution of visible normals `D_wo(h) = G1(wo) max(0, wo . h)
    /// D(h) / cos theta_o` (Heitz 2018, eq. 1); `int D_wo(h) dh = 1`.
    pub fn visible_normals(&self, wo: Vec3, h: Vec3) -> f64 {
        let g1 = self.g1(wo);
        if g1 == 0.0 {
            return 0.0;
        }
        g1 * wo.dot(&h).max(0.0) * self.d(h) / wo.z
    }

    /// `wo` stretched to the unit-roughness configuration and the frame
    /// `(T1, T2, Vh)` of Heitz's listing, with `s = (1 + Vh_z) / 2`.
    fn stretched_frame(&self, wo: Vec3) -> (Vec3, Vec3, Vec3, f64) {
        let vh = Vec3::new(self.alpha * wo.x, self.alpha * wo.y, wo.z).normalize();
        let lensq = vh.x * vh.x + vh.y * vh.y;
        let t1 = if lensq > 0.0 {
            Vec3::new(-vh.y, vh.x, 0.0) / lensq.sqrt()
        } else {
            Vec3::x()
        };
        let t2 = vh.cross(&t1);
        (t1, t2, vh, 0.5 * (1.0 + vh.z))
    }

    /// Heitz 2018's listing: stretch `wo`, sample the projected disk with
    /// `r = sqrt(u_1)`, `phi = 2 pi u_2`, warp its second coordinate to the
    /// visible half `t_2 <- (1 - s) sqrt(1 - t_1^2) + s t_2`, lift to the
    /// hemisphere and unstretch: the microfacet normal `h`.
    fn sample_normal(&self, wo: Vec3, u: [f64; 2]) -> Vec3 {
        let (t1v, t2v, vh, s) = self.stretched_frame(wo);
        let r = u[0].sqrt();
        let (sin_phi, cos_phi) = (2.0 * PI * u[1]).sin_cos();
        let t1 = r * cos_phi;
        let t2 = (1.0 - s) * (1.0 - t1 * t1).max(0.0).sqrt() + s * r * sin_phi;
        let nh = t1v * t1 + t2v * t2 + vh * (1.0 - t1 * t1 - t2 * t2).max(0.0).sqrt();
        Vec3::new(self.alpha * nh.x, self.alpha * nh.y, nh.z.max(0.0)).normalize()
    }
}

impl Brdf for Ggx {
    /// `D(h) G2(wi, wo) / (4 cos theta_i cos theta_o)` (R-H, Fresnel 1).
    fn eval(&self, wi: Vec3, wo: Vec3) -> f64 {
        if !both_above(wi, wo) {
            return 0.0;
        }
        let h = (wi + wo).normalize();
        self.d(h) * self.g2(wi, wo) / (4.0 * wi.z * wo.z)
    }

    fn sample(&self, wo: Vec3, u: [f64; 2]) -> Option<Sample> {
        if !(is_unit(wo) && wo.z > 0.0 && valid_u(u)) {
            return None;
        }
        let h = self.sample_normal(wo, u);
        let cos_oh = wo.dot(&h);
        let wi = h * (2.0 * cos_oh) - wo;
        if !(wi.z > 0.0 && cos_oh > 0.0) {
            return None;
        }
        // D_wo(h) / (4 wo . h) with D_wo = G1(wo) (wo . h) D(h) / cos theta_o.
        let g1 = self.g1(wo);
        let pdf = g1 * self.d(h) / (4.0 * wo.z);
        if !(pdf > 0.0 && pdf.is_finite()) {
            return None;
        }
        Some(Sample {
            wi,
            pdf,
            weight: self.g2(wi, wo) / g1,
        })
    }

    /// `G1(wo) D(h) / (4 cos theta_o)`, `h = (wi + wo)/|wi + wo|`, over the
    /// sphere (0 where `h` is below the horizon).
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f64 {
        if !(is_unit(wi) && is_unit(wo) && wo.z > 0.0) {
            return 0.0;
        }
        let sum = wi + wo;
        let len = sum.norm();
        if len <= 0.0 {
            return 0.0;
        }
        self.g1(wo) * self.d(sum / len) / (4.0 * wo.z)
    }

    /// `h = (wi + wo)/|wi + wo|`, stretched: `N_h ~ (h_x / alpha, h_y /
    /// alpha, h_z)`; `t_1 = N_h . T1`, `t_2 = (N_h . T2 - (1 - s) sqrt(1 -
    /// t_1^2)) / s` undo the warp (`s >= 1/2`), `u_1 = t_1^2 + t_2^2`,
    /// `u_2 = atan2(t_2, t_1) / (2 pi)`.
    fn invert(&self, wo: Vec3, wi: Vec3) -> Option<[f64; 2]> {
        if self.pdf(wo, wi) <= 0.0 {
            return None;
        }
        let h = (wi + wo).normalize();
        let nh = Vec3::new(h.x / self.alpha, h.y / self.alpha, h.z).normalize();
        let (t1v, t2v, _, s) = self.stretched_frame(wo);
        let t1 = nh.dot(&t1v);
        let t2 = (nh.dot(&t2v) - (1.0 - s) * (1.0 - t1 * t1).max(0.0).sqrt()) / s;
        Some([(t1 * t1 + t2 * t2).min(1.0), azimuth_fraction(t2, t1)])
    }
}
