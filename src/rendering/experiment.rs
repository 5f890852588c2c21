//! The rendering-equation family (R-* in docs/EQUATIONS.md) as the experiment
//! layer sees it (`"family": "rendering"`): a receiver (a point, its normal
//! and, for reflected radiance, a BRDF and the direction toward the viewer),
//! emitters and occluders; irradiance and reflected radiance at the receiver
//! by **form**, each form a different integrand over a different domain of
//! the same value, so that a report shows the forms side by side per rule and
//! budget; multiple importance sampling beside the rules; closed forms where
//! the scene has one, a converged adaptive evaluation otherwise.
//!
//! The value (R-H, R-A without the emitted term at the receiver):
//!
//! `E(x, n) = int_H L_i(x, w) cos theta dw`, `L_r(x, wo) = int_H f_r(w, wo)
//! L_i(x, w) cos theta dw`
//!
//! | quantity | form | domain, per evaluation | integrand in `u` |
//! |---|---|---|---|
//! | `E_hemisphere` | R-H | the hemisphere, uniform map `cos theta = u_1`, `J = 2 pi` | `L_i(x, w) cos theta 2 pi`: a ray cast per node |
//! | `E_cosine` | R-H | the hemisphere, Malley's map in projected solid angle, `J = pi` | `L_i(x, w) pi` |
//! | `E_cone` | R-H per emitter | the cone of directions that holds the emitter (exact for a sphere, a cap light, the environment's hemisphere and a disk seen from its axis; a bounding cone otherwise) | `L_i^k(x, w) cos theta J` |
//! | `E_area` | R-A (R-S, R-3P's `g`) per emitter | the emitter's surface through its map with the Jacobian (rectangle, polar disk, Duffy triangle, the visible cap of a sphere; the cap of directions of a light at infinity) | `L_e cos theta cos theta' / r^2 V(x, y) J` |
//! | `L_hemisphere`, `L_cosine`, `L_cone`, `L_area` | as the `E_` forms | as above | the same with `f_r(w, wo)` |
//! | `L_brdf` | R-H | the BRDF-sampled map of `scene.receiver.brdf` for `wo`, `J = 1 / pdf` | `f_r L_i cos theta / pdf` |
//!
//! (`J` is the Jacobian of the domain's map.)
//!
//! The per-emitter forms (`_cone`, `_area`) spend the budget on each emitter
//! and add the parts. Every quantity is a 2-D integral: every 2-D rule
//! integrates it (`genz-malik`, `gauss-legendre`, `trapezoid`, `simpson`,
//! `monte-carlo`, `stratified`, `sobol`, and a product of two 1-D rules);
//! a 1-D rule alone (`gauss-kronrod`) is refused when the experiment is
//! checked. The L quantities need `scene.receiver.brdf` (refused at the
//! quantity without one).
//!
//! **Estimators.** `{"rule": "mis-balance"}` and `{"rule": "mis-power"}`:
//! light sampling and BRDF sampling combined by Veach's balance or power
//! heuristic ([`crate::rendering::mis`]), one sample of each strategy per
//! unit of budget, with a standard error. The light strategy is the
//! quantity's form, so they estimate `E_area`, `L_area` (light sampled by
//! area) and `E_cone`, `L_cone` (light sampled in its cone), and are refused
//! for the other forms; irradiance is `pi` times the reflected radiance of a
//! white Lambertian BRDF (its BRDF sampling is cosine sampling).
//!
//! **Closed forms** ([`crate::exact::rendering`]), for scenes without
//! occluders whose emitters cannot shadow each other (one emitter, or only
//! lights at infinity): a rectangle or triangle light by Lambert's contour
//! formula (clipped at the horizon), a disk light seen from its axis by the
//! parallel coaxial disk, a sphere light and a cap light by Snyder's cap
//! formula (partly below the horizon included), the environment `pi L`;
//! reflected radiance for a Lambertian BRDF `rho / pi E`, and for a Phong
//! lobe under the environment alone at normal incidence (`2 pi / (n + 2)`)
//! or of exponent 1 at any incidence (the clamped-cosine product).
//!
//! **Converged reference** ([`Rendering::converged`]): adaptive Genz–Malik
//! per emitter on the smoothest form the emitter has: its exact cone
//! (sphere, cap light, coaxial disk), the BRDF-sampled map for the
//! environment under a non-Lambertian BRDF (the lobe becomes smooth), the
//! cone for the environment otherwise, and its surface (R-A) for planar
//! lights. Under a non-Lambertian BRDF a finite light's form is checked
//! against the BRDF-sampled map restricted to that light (a lobe narrower
//! than the light is smooth there and a peak in the light's own domain; a
//! lobe across the light's outline the other way round): the one with the
//! smaller error estimate is kept, its error widened to their difference
//! where they disagree beyond ten times their estimates.
//!
//! Where the integrand would kink or jump inside those domains, the
//! converged reference integrates between exact outlines instead, in polar
//! directions with nested adaptive Gauss–Kronrod
//! ([`crate::rendering::blocked`], [`crate::rendering::arcs`]): a flat
//! kernel over an exact cone; a planar light cut by the horizon or the
//! lobe's clamp; and, where something can block a light and its shadow is
//! not a polygon the scene can cut out exactly, the light with nothing in
//! the way less what each blocker hides, cut at the blocker's, the light's,
//! the horizon's, the clamp's and the other blockers' outlines. That needs
//! every blocker wholly in front of the light or wholly behind it
//! ([`crate::rendering::order`]); where one straddles it (a sphere through
//! the plane of a rectangle light) the hidden part is taken over the
//! blocker's domain with a visibility test, and the reference says
//! "unverified" instead of converged.
//!
//! **Terms left out.** R-A's visibility is evaluated only where something
//! can block an emitter ([`crate::rendering::scene::Scene::has_blockers`]):
//! without occluders, and with no other finite emitter, no shadow ray is
//! cast ([`Work::shadow_rays`] counts them); a BRDF kernel or cosine of 0
//! casts no ray either.
//!
//! ```
//! use lightquad::family::{Family, Method};
//! use lightquad::rendering::experiment::{Mis, Rendering, RenderingQuantity, SceneSpec};
//! use rand::SeedableRng;
//!
//! // A disk light of radius 1 at height 2 facing the receiver from its axis.
//! let spec: SceneSpec = serde_json::from_value(serde_json::json!({
//!     "receiver": {"point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0]},
//!     "emitters": [{"type": "disk", "centre": [0.0, 0.0, 2.0], "normal": [0.0, 0.0, -1.0],
//!                   "radius": 1.0, "radiance": 1.5}]
//! }))?;
//! let built = Rendering::build(&spec)?;
//! // E = pi L R^2 / (h^2 + R^2) (Howell's element to a coaxial disk).
//! let want = std::f64::consts::PI * 1.5 / 5.0;
//! let exact = Rendering::closed_form(&built, RenderingQuantity::EArea).ok_or("none")?[0];
//! assert!((exact - want).abs() < 1e-15);
//! // The area and cone forms by Gauss-Legendre, as an experiment's job runs them.
//! let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
//! let gl: Method<Mis> = serde_json::from_str(r#"{"rule": "gauss-legendre"}"#)?;
//! let q = [RenderingQuantity::EArea, RenderingQuantity::ECone];
//! let out = Rendering::evaluate(&built, &gl, 1024, &mut rng, &q)?;
//! for q in q {
//!     assert!((out[&q].value[0] / want - 1.0).abs() < 1e-12, "{q:?}");
//! }
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::cell::Cell;
use std::f64::consts::PI;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::blocked;
use super::brdf::{Brdf, Ggx, Lambert, NormalizedPhong, Phong, Sample};
use super::clipped;
use super::emitter::{
    AnyEmitter, CapLight, DiskLight, Emitter, EnvironmentLight, LightSampling, RectangleLight,
    SphereLight, TriangleLight,
};
use super::forms::{self, BrdfSampled, Irradiance, Kernel, Reach, Reflected};
use super::mis::{Heuristic, mis};
use super::occluder::Occluder;
use super::order;
use super::receiver::Receiver;
use super::scene::Scene;
use crate::domain::{HemisphereMap, Triangle, Vec3, integrate_over};
use crate::error::{QuadError, SpecError};
use crate::estimate::Estimate;
use crate::exact::rendering as exact;
use crate::experiment::tagged;
use crate::family::{self, Family, Measured, Method, Outcome};
use crate::quadrature::{GenzMalik, Rule};

/// The rendering family.
#[derive(Debug, Clone, Copy)]
pub struct Rendering;

/// The scene: the receiver, the emitters and the occluders.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SceneSpec {
    /// Where irradiance and reflected radiance are evaluated.
    pub receiver: ReceiverSpec,
    /// The lights (at least one).
    pub emitters: Vec<EmitterSpec>,
    /// Opaque surfaces between the receiver and the lights (default none).
    #[serde(default, deserialize_with = "tagged::non_empty")]
    pub occluders: Vec<OccluderSpec>,
}

/// The receiving point `x` with its normal; for reflected radiance its BRDF
/// and the direction `wo` toward the viewer.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ReceiverSpec {
    /// `x`.
    #[serde(deserialize_with = "tagged::array")]
    pub point: [f64; 3],
    /// `n` (normalised; finite, non-zero).
    #[serde(deserialize_with = "tagged::array")]
    pub normal: [f64; 3],
    /// `f_r`: needed by the `L_` quantities.
    #[serde(default)]
    pub brdf: Option<BrdfSpec>,
    /// `wo`, toward the viewer, above the receiver's horizon (normalised);
    /// given with `brdf` and only with it.
    #[serde(default, deserialize_with = "some_array")]
    pub toward_viewer: Option<[f64; 3]>,
}

fn some_array<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<[f64; 3]>, D::Error> {
    tagged::array(d).map(Some)
}

/// A Lambertian light of radiance `radiance` (finite, `>= 0`):
/// `{"type": <name>, <the variant's fields>}`.
#[derive(Debug, Clone, PartialEq, Serialize, JsonSchema)]
#[serde(tag = "type", rename_all = "kebab-case")]
pub enum EmitterSpec {
    /// A parallelogram `origin + a edge_u + b edge_v` emitting on the side of
    /// `edge_u x edge_v`.
    Rectangle(RectangleLightSpec),
    /// A disk emitting on the side of its normal.
    Disk(DiskLightSpec),
    /// A triangle emitting on the side of `(b - a) x (c - b)`.
    Triangle(TriangleLightSpec),
    /// A sphere emitting outward.
    Sphere(SphereLightSpec),
    /// Uniform radiance from every direction nothing blocks.
    Environment(EnvironmentSpec),
    /// Uniform radiance from the directions within `half_angle` of `axis`,
    /// at infinity.
    Cap(CapLightSpec),
}

/// The documents exclude delta lights and perfect mirrors (R-A's
/// assumptions, docs/EQUATIONS.md): their names get a message of their own.
fn excluded<E: serde::de::Error>(
    value: &serde_json::Value,
    names: &[(&str, &str)],
) -> Result<(), E> {
    let tag = value.get("type").and_then(|t| t.as_str());
    match names.iter().find(|(n, _)| Some(*n) == tag) {
        Some((name, why)) => Err(tagged::below("type", &format!("`{name}` {why}"))),
        None => Ok(()),
    }
}

impl<'de> Deserialize<'de> for EmitterSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        const NAMES: [&str; 6] = [
            "rectangle",
            "disk",
            "triangle",
            "sphere",
            "environment",
            "cap",
        ];
        const DELTA: &str = "lights are excluded: the documents' R-H and R-A assume no point or \
                             directional (delta) lights; a small sphere or cap light stands in \
                             for one. Expected one of `rectangle`, `disk`, `triangle`, `sphere`, \
                             `environment`, `cap`";
        let value = serde_json::Value::deserialize(d)?;
        excluded(
            &value,
            &[("point", DELTA), ("directional", DELTA), ("spot", DELTA)],
        )?;
        let (tag, fields) = tagged::split_tag(value, "type", &NAMES)?;
        match tag.as_str() {
            "rectangle" => tagged::variant(fields).map(EmitterSpec::Rectangle),
            "disk" => tagged::variant(fields).map(EmitterSpec::Disk),
            "triangle" => tagged::variant(fields).map(EmitterSpec::Triangle),
            "sphere" => tagged::variant(fields).map(EmitterSpec::Sphere),
            "environment" => tagged::variant(fields).map(EmitterSpec::Environment),
            _ => tagged::variant(fields).map(EmitterSpec::Cap),
        }
    }
}

/// A parallelogram light.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RectangleLightSpec {
    /// The corner `p(0, 0)`.
    #[serde(deserialize_with = "tagged::array")]
    pub origin: [f64; 3],
    /// The first edge.
    #[serde(deserialize_with = "tagged::array")]
    pub edge_u: [f64; 3],
    /// The second edge (not parallel to the first).
    #[serde(deserialize_with = "tagged::array")]
    pub edge_v: [f64; 3],
    /// `L_e`.
    pub radiance: f64,
}

/// A disk light.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DiskLightSpec {
    /// The centre.
    #[serde(deserialize_with = "tagged::array")]
    pub centre: [f64; 3],
    /// The normal of the emitting side.
    #[serde(deserialize_with = "tagged::array")]
    pub normal: [f64; 3],
    /// The radius (`> 0`).
    pub radius: f64,
    /// `L_e`.
    pub radiance: f64,
}

/// A triangle light.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TriangleLightSpec {
    /// First vertex.
    #[serde(deserialize_with = "tagged::array")]
    pub a: [f64; 3],
    /// Second vertex.
    #[serde(deserialize_with = "tagged::array")]
    pub b: [f64; 3],
    /// Third vertex (off the line through `a` and `b`).
    #[serde(deserialize_with = "tagged::array")]
    pub c: [f64; 3],
    /// `L_e`.
    pub radiance: f64,
}

/// A sphere light.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SphereLightSpec {
    /// The centre.
    #[serde(deserialize_with = "tagged::array")]
    pub centre: [f64; 3],
    /// The radius (`> 0`; the receiver outside).
    pub radius: f64,
    /// `L_e`.
    pub radiance: f64,
}

/// A uniform environment.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentSpec {
    /// `L_e`.
    pub radiance: f64,
}

/// A spherical-cap light at infinity.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CapLightSpec {
    /// The direction of its centre.
    #[serde(deserialize_with = "tagged::array")]
    pub axis: [f64; 3],
    /// Its angular radius in radians, in `(0, pi]`.
    pub half_angle: f64,
    /// `L_e`.
    pub radiance: f64,
}

/// An opaque surface: `{"type": <name>, <the variant's fields>}`.
#[derive(Debug, Clone, PartialEq, Serialize, JsonSchema)]
#[serde(tag = "type", rename_all = "kebab-case")]
pub enum OccluderSpec {
    /// A sphere.
    Sphere(SphereSpec),
    /// A disk.
    Disk(DiskSpec),
    /// A parallelogram.
    Rectangle(RectangleSpec),
    /// A triangle.
    Triangle(TriangleSpec),
}

impl<'de> Deserialize<'de> for OccluderSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        const NAMES: [&str; 4] = ["sphere", "disk", "rectangle", "triangle"];
        let (tag, fields) = tagged::split_tag(serde_json::Value::deserialize(d)?, "type", &NAMES)?;
        match tag.as_str() {
            "sphere" => tagged::variant(fields).map(OccluderSpec::Sphere),
            "disk" => tagged::variant(fields).map(OccluderSpec::Disk),
            "rectangle" => tagged::variant(fields).map(OccluderSpec::Rectangle),
            _ => tagged::variant(fields).map(OccluderSpec::Triangle),
        }
    }
}

/// An opaque sphere.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SphereSpec {
    /// The centre.
    #[serde(deserialize_with = "tagged::array")]
    pub centre: [f64; 3],
    /// The radius (`> 0`).
    pub radius: f64,
}

/// An opaque disk.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DiskSpec {
    /// The centre.
    #[serde(deserialize_with = "tagged::array")]
    pub centre: [f64; 3],
    /// The normal.
    #[serde(deserialize_with = "tagged::array")]
    pub normal: [f64; 3],
    /// The radius (`> 0`).
    pub radius: f64,
}

/// An opaque parallelogram.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RectangleSpec {
    /// The corner `p(0, 0)`.
    #[serde(deserialize_with = "tagged::array")]
    pub origin: [f64; 3],
    /// The first edge.
    #[serde(deserialize_with = "tagged::array")]
    pub edge_u: [f64; 3],
    /// The second edge.
    #[serde(deserialize_with = "tagged::array")]
    pub edge_v: [f64; 3],
}

/// An opaque triangle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TriangleSpec {
    /// First vertex.
    #[serde(deserialize_with = "tagged::array")]
    pub a: [f64; 3],
    /// Second vertex.
    #[serde(deserialize_with = "tagged::array")]
    pub b: [f64; 3],
    /// Third vertex.
    #[serde(deserialize_with = "tagged::array")]
    pub c: [f64; 3],
}

/// A BRDF ([`crate::rendering::brdf`]): `{"type": <name>, <the variant's
/// fields>}`.
#[derive(Debug, Clone, PartialEq, Serialize, JsonSchema)]
#[serde(tag = "type", rename_all = "kebab-case")]
pub enum BrdfSpec {
    /// `rho / pi`.
    Lambert(LambertSpec),
    /// The documents' unnormalised lobe `k_s max(0, cos alpha)^n` (W-Phong).
    Phong(PhongSpec),
    /// `k_s (n + 2) / (2 pi) max(0, cos alpha)^n`.
    NormalizedPhong(PhongSpec),
    /// GGX with Smith masking, Fresnel 1.
    Ggx(GgxSpec),
}

impl<'de> Deserialize<'de> for BrdfSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        const NAMES: [&str; 4] = ["lambert", "phong", "normalized-phong", "ggx"];
        let value = serde_json::Value::deserialize(d)?;
        excluded(
            &value,
            &[(
                "mirror",
                "BRDFs are excluded: the documents assume no perfect mirrors (a delta BRDF has \
                 no density to integrate); `phong` with a large exponent or `ggx` with a small \
                 alpha stands in for one. Expected one of `lambert`, `phong`, \
                 `normalized-phong`, `ggx`",
            )],
        )?;
        let (tag, fields) = tagged::split_tag(value, "type", &NAMES)?;
        match tag.as_str() {
            "lambert" => tagged::variant(fields).map(BrdfSpec::Lambert),
            "phong" => tagged::variant(fields).map(BrdfSpec::Phong),
            "normalized-phong" => tagged::variant(fields).map(BrdfSpec::NormalizedPhong),
            _ => tagged::variant(fields).map(BrdfSpec::Ggx),
        }
    }
}

/// A Lambertian BRDF.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LambertSpec {
    /// `rho` in `[0, 1]`.
    pub albedo: f64,
}

/// A Phong lobe.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PhongSpec {
    /// `k_s` in `[0, 1]`.
    pub k_s: f64,
    /// `n` in `[0, 1e8]`.
    pub exponent: f64,
}

/// A GGX microfacet BRDF.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GgxSpec {
    /// Roughness in `[1e-4, 1]`.
    pub alpha: f64,
}

/// Any BRDF of the family, dispatched to its type.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AnyBrdf {
    /// [`Lambert`].
    Lambert(Lambert),
    /// [`Phong`].
    Phong(Phong),
    /// [`NormalizedPhong`].
    NormalizedPhong(NormalizedPhong),
    /// [`Ggx`].
    Ggx(Ggx),
}

/// Forwards a method to the variant's type.
macro_rules! forward_brdf {
    ($self:ident, $b:ident => $call:expr) => {
        match $self {
            AnyBrdf::Lambert($b) => $call,
            AnyBrdf::Phong($b) => $call,
            AnyBrdf::NormalizedPhong($b) => $call,
            AnyBrdf::Ggx($b) => $call,
        }
    };
}

impl Brdf for AnyBrdf {
    fn eval(&self, wi: Vec3, wo: Vec3) -> f64 {
        forward_brdf!(self, b => b.eval(wi, wo))
    }
    fn sample(&self, wo: Vec3, u: [f64; 2]) -> Option<Sample> {
        forward_brdf!(self, b => b.sample(wo, u))
    }
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f64 {
        forward_brdf!(self, b => b.pdf(wo, wi))
    }
    fn invert(&self, wo: Vec3, wi: Vec3) -> Option<[f64; 2]> {
        forward_brdf!(self, b => b.invert(wo, wi))
    }
    fn clamp(&self, wo: Vec3) -> Option<Vec3> {
        forward_brdf!(self, b => b.clamp(wo))
    }
}

impl Reach for AnyBrdf {
    fn reach(&self, wo: Vec3) -> f64 {
        forward_brdf!(self, b => b.reach(wo))
    }
}

/// A quantity of the rendering family: a value (irradiance `E`, reflected
/// radiance `L`) by a form (module documentation).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize, JsonSchema,
)]
pub enum RenderingQuantity {
    /// `E` by R-H over the hemisphere, uniform in solid angle.
    #[serde(rename = "E_hemisphere")]
    EHemisphere,
    /// `E` by R-H over the hemisphere, cosine-weighted (projected solid angle).
    #[serde(rename = "E_cosine")]
    ECosine,
    /// `E` by R-H over each emitter's cone of directions.
    #[serde(rename = "E_cone")]
    ECone,
    /// `E` by R-A over each emitter's surface.
    #[serde(rename = "E_area")]
    EArea,
    /// `L_r` by R-H over the hemisphere, uniform in solid angle.
    #[serde(rename = "L_hemisphere")]
    LHemisphere,
    /// `L_r` by R-H over the hemisphere, cosine-weighted.
    #[serde(rename = "L_cosine")]
    LCosine,
    /// `L_r` by R-H over the BRDF-sampled map.
    #[serde(rename = "L_brdf")]
    LBrdf,
    /// `L_r` by R-H over each emitter's cone of directions.
    #[serde(rename = "L_cone")]
    LCone,
    /// `L_r` by R-A over each emitter's surface.
    #[serde(rename = "L_area")]
    LArea,
}

/// The domain a quantity is integrated over.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Form {
    /// The hemisphere, uniform map.
    Hemisphere,
    /// The hemisphere, projected (cosine-weighted) map.
    Cosine,
    /// The BRDF-sampled map.
    Brdf,
    /// Each emitter's cone of directions.
    Cone,
    /// Each emitter's surface.
    Area,
}

impl RenderingQuantity {
    /// True for reflected radiance (`L_`), false for irradiance (`E_`).
    pub fn reflected(&self) -> bool {
        use RenderingQuantity::*;
        matches!(self, LHemisphere | LCosine | LBrdf | LCone | LArea)
    }

    /// The form.
    pub fn form(&self) -> Form {
        use RenderingQuantity::*;
        match self {
            EHemisphere | LHemisphere => Form::Hemisphere,
            ECosine | LCosine => Form::Cosine,
            LBrdf => Form::Brdf,
            ECone | LCone => Form::Cone,
            EArea | LArea => Form::Area,
        }
    }
}

impl family::Quantity for RenderingQuantity {
    fn name(&self) -> &'static str {
        use RenderingQuantity::*;
        match self {
            EHemisphere => "E_hemisphere",
            ECosine => "E_cosine",
            ECone => "E_cone",
            EArea => "E_area",
            LHemisphere => "L_hemisphere",
            LCosine => "L_cosine",
            LBrdf => "L_brdf",
            LCone => "L_cone",
            LArea => "L_area",
        }
    }

    fn all() -> &'static [Self] {
        use RenderingQuantity::*;
        &[
            EHemisphere,
            ECosine,
            ECone,
            EArea,
            LHemisphere,
            LCosine,
            LBrdf,
            LCone,
            LArea,
        ]
    }

    /// Irradiance and radiance are never negative: emitters' radiances and
    /// the BRDFs are `>= 0` (checked where the scene is read), so a literal
    /// reference below 0 is a mistake, refused at its path.
    fn bounds(&self) -> (f64, f64) {
        (0.0, f64::INFINITY)
    }
}

/// Multiple importance sampling of light and BRDF samples, the family's
/// estimators beside the rules (module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "rule", rename_all = "kebab-case")]
pub enum Mis {
    /// Veach's balance heuristic.
    MisBalance,
    /// Veach's power heuristic (`beta = 2`).
    MisPower,
}

impl Mis {
    fn heuristic(&self) -> Heuristic {
        match self {
            Mis::MisBalance => Heuristic::Balance,
            Mis::MisPower => Heuristic::Power,
        }
    }
}

impl family::Estimator for Mis {
    fn name(&self) -> &'static str {
        match self {
            Mis::MisBalance => "mis-balance",
            Mis::MisPower => "mis-power",
        }
    }
    fn about(&self) -> &'static str {
        match self {
            Mis::MisBalance => {
                "multiple importance sampling, balance heuristic: a light sample (by area for \
                 E_area, L_area; in its cone for E_cone, L_cone) and a BRDF sample per unit of \
                 budget; standard error"
            }
            Mis::MisPower => {
                "multiple importance sampling, power heuristic (beta = 2): a light sample (by \
                 area for E_area, L_area; in its cone for E_cone, L_cone) and a BRDF sample per \
                 unit of budget; standard error"
            }
        }
    }
    /// Two samples: a standard error needs them.
    fn min_budget(&self) -> usize {
        2
    }
    fn is_random(&self) -> bool {
        true
    }
    fn all() -> Vec<Self> {
        vec![Mis::MisBalance, Mis::MisPower]
    }
}

/// The built scene.
#[derive(Debug, Clone)]
pub struct Built {
    /// Emitters and occluders.
    pub scene: Scene<f64>,
    /// The receiving point and its frame.
    pub receiver: Receiver,
    /// The BRDF, if the scene has one.
    pub brdf: Option<AnyBrdf>,
    /// `wo`, unit, above the horizon (with the BRDF).
    pub toward_viewer: Option<Vec3>,
}

/// The work of one evaluation beyond the integrand evaluations of the
/// [`Measured`] it gives: the terms a scene does not need are left out, and
/// this says so in numbers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Work {
    /// R-A's shadow rays (visibility tests `V(x, y)`): 0 where nothing can
    /// block the emitters. Counted for the area forms, whose visibility is a
    /// term of its own; in the R-H forms visibility is the ray cast that
    /// finds `L_i`, and MIS tests it inside [`crate::rendering::mis`].
    pub shadow_rays: u64,
}

/// `L_` quantities need a BRDF.
const NEEDS_BRDF: &str = "reflected radiance needs the receiver's BRDF and the direction toward \
                          the viewer: give scene.receiver.brdf and scene.receiver.toward_viewer, \
                          or ask for the E_ quantities";

impl Family for Rendering {
    const NAME: &'static str = "rendering";
    const ABOUT: &'static str = "irradiance and reflected radiance at a point from area lights, \
                                 spheres, caps and an environment, with occluders, by the \
                                 hemispherical (R-H) and area (R-A) forms and MIS";
    const EQUATIONS: &'static [&'static str] = &["R-3P", "R-H", "R-A", "R-S"];
    const BUDGET_UNIT: &'static str = "integrand evaluations (per emitter for the cone and area \
                                       forms; samples per strategy for MIS)";

    type SceneSpec = SceneSpec;
    type Scene = Built;
    type Quantity = RenderingQuantity;
    type Estimator = Mis;

    fn build(spec: &SceneSpec) -> Result<Built, SpecError> {
        build(spec)
    }

    /// Every form is an integral over a 2-D domain.
    fn dimension(_: &Built, _: RenderingQuantity) -> usize {
        2
    }

    /// Radiance is a scalar here.
    fn channels(_: &Built, _: RenderingQuantity) -> usize {
        1
    }

    fn lacks(built: &Built, q: RenderingQuantity) -> Option<String> {
        (q.reflected() && built.brdf.is_none()).then(|| NEEDS_BRDF.to_string())
    }

    /// The light-sampled forms: MIS's light strategy is the quantity's form.
    fn estimates(_: &Mis) -> &'static [RenderingQuantity] {
        use RenderingQuantity::*;
        &[EArea, ECone, LArea, LCone]
    }

    /// The per-emitter forms cost the budget per emitter; MIS two samples
    /// per unit of budget.
    fn cost(built: &Built, method: &Method<Mis>, budget: usize, q: RenderingQuantity) -> f64 {
        let n = budget as f64;
        let emitters = built.scene.emitters().len() as f64;
        // Each sample's shadow ray tests every occluder (100 000 triangles
        // made a sample about 1 ms).
        let visibility = 1.0 + built.scene.occluders().len() as f64;
        visibility
            * match (method, q.form()) {
                (Method::Estimator(_), _) => 2.0 * n,
                (_, Form::Cone | Form::Area) => n * emitters,
                _ => n,
            }
    }

    fn evaluate(
        built: &Built,
        method: &Method<Mis>,
        budget: usize,
        rng: &mut rand_pcg::Pcg64,
        quantities: &[RenderingQuantity],
    ) -> Result<Outcome<RenderingQuantity>, QuadError> {
        quantities
            .iter()
            .map(|&q| Ok((q, evaluate_counted(built, method, budget, rng, q)?.0)))
            .collect()
    }

    fn closed_form(built: &Built, q: RenderingQuantity) -> Option<Vec<f64>> {
        closed_form(built, q).map(|v| vec![v])
    }

    fn closed_forms_available() -> &'static str {
        "closed forms without occluders and with one emitter (or only lights at infinity): \
         rectangle and triangle lights (Lambert's contour formula), a disk light seen from its \
         axis with a parallel receiver, sphere and cap lights (Snyder's cap, below the horizon \
         included), the environment; L for a Lambertian BRDF, and for a Phong lobe under the \
         environment alone at normal incidence or of exponent 1"
    }

    /// Adaptive Genz–Malik (relative tolerance 1e-14) with up to
    /// [`CONVERGED_PER_N`]` n` evaluations per emitter, on the smoothest
    /// form each emitter has (module documentation); every `E_` quantity
    /// gets the one irradiance value, every `L_` quantity the one reflected
    /// radiance.
    fn converged(
        built: &Built,
        n: usize,
        quantities: &[RenderingQuantity],
    ) -> Result<Outcome<RenderingQuantity>, QuadError> {
        let budget = CONVERGED_PER_N.saturating_mul(n);
        let mut irradiance = None;
        let mut reflected = None;
        let mut out = Outcome::new();
        for &q in quantities {
            let slot = if q.reflected() {
                &mut reflected
            } else {
                &mut irradiance
            };
            let m = match slot {
                Some(m) => m,
                None => slot.insert(converged_value(built, q.reflected(), budget)?),
            };
            out.insert(q, Measured::from(*m));
        }
        Ok(out)
    }

    fn settings(spec: &SceneSpec) -> String {
        settings(spec)
    }

    fn scene_audit(built: &Built) -> Option<String> {
        Some(terms_section(built))
    }

    /// R-S as printed, without the area element ([`super::audit`]).
    fn audit() -> Option<String> {
        Some(super::audit::markdown())
    }
}

/// Evaluations per emitter of the converged reference for each `n` of
/// `{"type": "converged", "n": n}`: 400 (the default) gives 40000, about
/// 2350 Genz–Malik boxes.
pub const CONVERGED_PER_N: usize = 100;

/// One quantity by `method` at `budget`, with the work it took beside the
/// integrand evaluations ([`Work`]).
pub fn evaluate_counted(
    built: &Built,
    method: &Method<Mis>,
    budget: usize,
    rng: &mut rand_pcg::Pcg64,
    q: RenderingQuantity,
) -> Result<(Measured, Work), QuadError> {
    let shadow_rays = Cell::new(0);
    let estimate = match method {
        Method::Rule(rule) => by_rule(built, rule, q, budget, rng, &shadow_rays)?,
        Method::Estimator(mis) => by_mis(built, *mis, q, budget, rng)?,
    };
    Ok((
        Measured::from(estimate),
        Work {
            shadow_rays: shadow_rays.get(),
        },
    ))
}

/// The reflected-radiance kernel of the scene's BRDF for its viewer, or
/// the error naming what is missing.
fn reflected_kernel(built: &Built) -> Result<Reflected<'_, AnyBrdf>, QuadError> {
    let (Some(brdf), Some(wo)) = (built.brdf.as_ref(), built.toward_viewer) else {
        return Err(QuadError::invalid("brdf", "none", NEEDS_BRDF));
    };
    Reflected::new(brdf, &built.receiver, wo)
}

/// `q` by a quadrature rule.
fn by_rule<R: Rule>(
    built: &Built,
    rule: &R,
    q: RenderingQuantity,
    n: usize,
    rng: &mut rand_pcg::Pcg64,
    shadow_rays: &Cell<u64>,
) -> Result<Estimate<f64>, QuadError> {
    if !q.reflected() {
        return by_form(built, &Irradiance, q.form(), rule, n, rng, shadow_rays);
    }
    let kernel = reflected_kernel(built)?;
    if q.form() == Form::Brdf {
        return forms::brdf_sampled(rule, &built.scene, &built.receiver, &kernel, n, rng);
    }
    by_form(built, &kernel, q.form(), rule, n, rng, shadow_rays)
}

/// The form `form` of the integral of kernel `K` ([`forms`]).
fn by_form<K: Kernel, R: Rule>(
    built: &Built,
    kernel: &K,
    form: Form,
    rule: &R,
    n: usize,
    rng: &mut rand_pcg::Pcg64,
    shadow_rays: &Cell<u64>,
) -> Result<Estimate<f64>, QuadError> {
    let (scene, receiver) = (&built.scene, &built.receiver);
    match form {
        Form::Hemisphere => forms::hemispherical(
            rule,
            scene,
            receiver,
            kernel,
            HemisphereMap::Uniform,
            n,
            rng,
        ),
        Form::Cosine => forms::hemispherical(
            rule,
            scene,
            receiver,
            kernel,
            HemisphereMap::Projected,
            n,
            rng,
        ),
        Form::Cone => forms::cone(rule, scene, receiver, kernel, n, rng),
        Form::Area => area_counted(built, kernel, rule, n, rng, shadow_rays),
        Form::Brdf => Err(QuadError::invalid(
            "quantity",
            "a BRDF-sampled irradiance",
            "L_brdf (irradiance has no BRDF to sample)",
        )),
    }
}

/// R-A as [`forms::area`] evaluates it, each shadow ray counted (by
/// wrapping [`forms::area_visibility`]).
fn area_counted<K: Kernel, R: Rule>(
    built: &Built,
    kernel: &K,
    rule: &R,
    n: usize,
    rng: &mut rand_pcg::Pcg64,
    shadow_rays: &Cell<u64>,
) -> Result<Estimate<f64>, QuadError> {
    let (scene, receiver) = (&built.scene, &built.receiver);
    let mut total = Estimate::zero();
    for (k, e) in scene.emitters().iter().enumerate() {
        let domain = e.surface(receiver)?;
        let skip = if e.at_infinity() { None } else { Some(k) };
        let tested = scene.has_blockers(skip);
        let base = forms::area_visibility(scene, receiver.point(), k);
        let visible = |y: Vec3| {
            if tested {
                shadow_rays.set(shadow_rays.get() + 1);
            }
            base(y)
        };
        let g = forms::area_integrand_with(scene, receiver, kernel, k, visible)?;
        total = total.combine(integrate_over(rule, &domain, n, rng, g)?);
    }
    Ok(total)
}

/// `q` by MIS: light samples by the quantity's form, BRDF samples of the
/// scene's BRDF (of a white Lambertian one, times `pi`, for irradiance).
fn by_mis(
    built: &Built,
    mis_kind: Mis,
    q: RenderingQuantity,
    n: usize,
    rng: &mut rand_pcg::Pcg64,
) -> Result<Estimate<f64>, QuadError> {
    let sampling = match q.form() {
        Form::Area => LightSampling::Area,
        Form::Cone => LightSampling::Cone,
        _ => {
            return Err(QuadError::invalid(
                "quantity",
                family::Quantity::name(&q),
                "one of E_area, E_cone, L_area, L_cone for MIS (its light strategy is the form)",
            ));
        }
    };
    let (scene, receiver) = (&built.scene, &built.receiver);
    let heuristic = mis_kind.heuristic();
    if q.reflected() {
        let kernel = reflected_kernel(built)?;
        return mis(scene, receiver, &kernel, sampling, heuristic, n, rng);
    }
    let white = Lambert::new(1.0)?;
    let kernel = Reflected::new(&white, receiver, receiver.normal())?;
    Ok(mis(scene, receiver, &kernel, sampling, heuristic, n, rng)?.scaled(PI))
}

/// True when the emitter's cone from the receiver is exactly the emitter
/// ([`Emitter::cone`]): a sphere, a cap light, the environment's
/// hemisphere, a disk seen from its axis.
fn exact_cone(e: &AnyEmitter<f64>, receiver: &Receiver) -> bool {
    match e {
        AnyEmitter::Sphere(_) | AnyEmitter::Cap(_) | AnyEmitter::Environment(_) => true,
        AnyEmitter::Disk(d) => coaxial(d, receiver.point()).is_some(),
        AnyEmitter::Rectangle(_) | AnyEmitter::Triangle(_) => false,
    }
}

/// True when the receiver's horizon or the kernel's lobe clamp
/// ([`Kernel::clamp`]) cuts a finite emitter: the plane through the
/// receiver has points of the light strictly on both sides.
fn crosses<K: Kernel>(e: &AnyEmitter<f64>, receiver: &Receiver, kernel: &K) -> bool {
    let x = receiver.point();
    e.occluder().is_some_and(|o| {
        order::straddles(&o, x, receiver.normal())
            || kernel.clamp().is_some_and(|r| order::straddles(&o, x, r))
    })
}

/// The height of `x` above the plane of a disk light (signed: positive on
/// its emitting side), when `x` is on the disk's axis (lateral offset at
/// most `1e-14 (|h| + R)`, as [`DiskLight`]'s cone takes it) and off its
/// plane.
fn coaxial(d: &DiskLight<f64>, x: Vec3) -> Option<f64> {
    let shape = d.shape();
    let local = shape.frame().to_local(x - shape.centre());
    let (h, lateral) = (local.z, local.x.hypot(local.y));
    (h != 0.0 && lateral <= 1e-14 * (h.abs() + shape.radius())).then_some(h)
}

/// The value of irradiance (or reflected radiance) by the converged method:
/// adaptive Genz–Malik on each emitter's smoothest form.
fn converged_value(
    built: &Built,
    reflected: bool,
    budget: usize,
) -> Result<Estimate<f64>, QuadError> {
    if !reflected {
        return converged_by_emitter(built, &Irradiance, None, budget);
    }
    let kernel = reflected_kernel(built)?;
    // A Lambertian lobe is flat: the cone is as smooth as the BRDF map.
    let lobe = match built.brdf {
        Some(AnyBrdf::Lambert(_)) => None,
        _ => Some(&kernel),
    };
    converged_by_emitter(built, &kernel, lobe, budget)
}

fn converged_by_emitter<K: Kernel>(
    built: &Built,
    kernel: &K,
    lobe: Option<&Reflected<'_, AnyBrdf>>,
    budget: usize,
) -> Result<Estimate<f64>, QuadError> {
    let rule = GenzMalik {
        abs_tol: 0.0,
        rel_tol: 1e-14,
    };
    let mut rng = <rand_pcg::Pcg64 as rand::SeedableRng>::seed_from_u64(0);
    let (scene, receiver) = (&built.scene, &built.receiver);
    let mut total = Estimate::zero();
    for (k, e) in scene.emitters().iter().enumerate() {
        // Under a peaked lobe the lit polygons' area integrand holds the
        // lobe's peak where the lobe is narrower than them; the blockers'
        // exact arcs with adaptive pieces resolve it instead.
        let lit = match lobe {
            None => lit_triangles(scene, receiver.point(), k),
            Some(_) => None,
        };
        // Where something can stand in the way and the shadow boundaries are
        // not computed, the light is taken with nothing in the way, and what
        // each blocker hides is subtracted over the blocker's own cone (an
        // adaptive rule over the light's domain can miss a small blocker:
        // crate::rendering::blocked).
        let split = lit.is_none() && scene.has_blockers(Some(k));
        let along = || {
            let free = blocked::unblocked(e, receiver, kernel);
            let seen = forms::cone_integrand(scene, receiver, kernel, k);
            move |w: Vec3| if split { free(w) } else { seen(w) }
        };
        let by_lobe = |lobe: &Reflected<'_, AnyBrdf>, rng: &mut rand_pcg::Pcg64| {
            integrate_over(&rule, &BrdfSampled::new(*lobe), budget, rng, along())
        };
        let part = match (e, lobe) {
            // Under a peaked lobe the environment's integrand is the lobe:
            // smooth in the BRDF's own map, but for the horizon where it
            // cuts the lobe; a Phong lobe is split there (clipped.rs), the
            // two checked against each other.
            (AnyEmitter::Environment(_), Some(lobe)) => match phong_cone(built)? {
                Some(pieces) => {
                    let mut sum = Estimate::zero();
                    for piece in &pieces {
                        sum = sum.combine(integrate_over(&rule, piece, budget, &mut rng, along())?);
                    }
                    cross_checked(sum, by_lobe(lobe, &mut rng)?)
                }
                None => by_lobe(lobe, &mut rng)?,
            },
            _ => {
                let own = if exact_cone(e, receiver) && lobe.is_none() {
                    // A flat kernel over an exact cone: exact pieces (a rule
                    // over the cone ends at one box and cannot vouch for it).
                    blocked::over_cone(receiver, kernel, e, &e.cone(receiver)?)?
                } else if exact_cone(e, receiver) {
                    integrate_over(&rule, &e.cone(receiver)?, budget, &mut rng, along())?
                } else if crosses(e, receiver, kernel)
                    && (split || !scene.has_blockers(Some(k)))
                    && let Some(own) = blocked::over_shape(receiver, kernel, e)?
                {
                    // Cut where the horizon or the lobe's clamp crosses the
                    // light: over its surface the integrand kinks there.
                    own
                } else if let Some(lit) = &lit {
                    // Split at the shadow boundaries: smooth on every piece.
                    let g = forms::area_integrand_with(scene, receiver, kernel, k, |_| true)?;
                    let per = (budget / lit.len().max(1)).max(rule.min_budget(2));
                    let mut sum = Estimate::zero();
                    for t in lit {
                        sum = sum.combine(integrate_over(&rule, t, per, &mut rng, &g)?);
                    }
                    sum
                } else if split {
                    let g = forms::area_integrand_with(scene, receiver, kernel, k, |_| true)?;
                    integrate_over(&rule, &e.surface(receiver)?, budget, &mut rng, g)?
                } else {
                    let g = forms::area_integrand(scene, receiver, kernel, k)?;
                    integrate_over(&rule, &e.surface(receiver)?, budget, &mut rng, g)?
                };
                match lobe {
                    // A lobe narrower than the light is smooth in the BRDF's
                    // map and a peak in the light's; one crossing the
                    // light's outline the other way round: both, the one
                    // with the smaller error kept, checked by the other.
                    Some(lobe) => cross_checked(own, by_lobe(lobe, &mut rng)?),
                    None => own,
                }
            }
        };
        let part = if split {
            // Where each blocker is wholly in front of the light or behind
            // it, piece by piece between the exact outlines; else over each
            // blocker's domain with a visibility test, trusted only where
            // nothing cuts it.
            let exact = blocked::hidden_by_arcs(scene, receiver, kernel, k)?;
            let mut hidden = exact.unwrap_or_else(Estimate::zero);
            let fallback = if exact.is_some() {
                Vec::new()
            } else {
                blocked::blockers(scene, k)
            };
            for (j, o) in fallback.iter().enumerate() {
                let h = blocked::hidden(scene, receiver, kernel, k, j)?;
                let domain = blocked::domain(o, receiver.point())?;
                let own = integrate_over(&rule, &domain, budget, &mut rng, &h)?;
                let checked = match lobe {
                    Some(lobe) => cross_checked(
                        own,
                        integrate_over(
                            &rule,
                            &BrdfSampled::new(*lobe),
                            budget,
                            &mut rng,
                            blocked::hidden_along(scene, receiver, kernel, k, j)?,
                        )?,
                    ),
                    None => own,
                };
                // Outlines, the horizon or other blockers crossing the
                // domain make the evaluation's own error estimate unsafe.
                let trusted = blocked::smooth(scene, receiver, k, j);
                hidden = hidden.combine(Estimate {
                    reliable: checked.reliable && trusted,
                    ..checked
                });
            }
            part.combine(Estimate {
                value: -hidden.value,
                ..hidden
            })
        } else {
            part
        };
        total = total.combine(part);
    }
    Ok(total)
}

/// The pieces of a Phong lobe's cone about its mirror direction, cut at
/// the receiver's horizon ([`clipped::pieces`]), out to where `cos^n alpha`
/// falls below 1e-30 of its peak; `None` for other BRDFs or no viewer.
fn phong_cone(built: &Built) -> Result<Option<Vec<clipped::ClippedCone>>, QuadError> {
    let n = match built.brdf {
        Some(AnyBrdf::Phong(p)) => p.exponent(),
        Some(AnyBrdf::NormalizedPhong(p)) => p.exponent(),
        _ => return Ok(None),
    };
    let Some(wo) = built.toward_viewer else {
        return Ok(None);
    };
    let normal = built.receiver.normal();
    let mirror = normal * (2.0 * normal.dot(&wo)) - wo;
    // cos^n alpha_max = 1e-30, at most 90 degrees (the lobe is clamped there).
    let one_minus_cos = if n > 0.0 {
        (-(1e-30_f64.ln() / n).exp_m1()).min(1.0)
    } else {
        1.0
    };
    clipped::pieces(mirror.normalize(), normal, one_minus_cos).map(Some)
}

/// The lit part of planar emitter `k` seen from `x`, as triangles, when the
/// shadow boundaries can be computed: every blocker is a planar polygon
/// (rectangle or triangle occluder) whose plane separates `x` from the
/// whole light, so that a point `y` of the light is in its shadow exactly
/// when `y` is inside the wedge of planes through `x` and the blocker's
/// edges. The lit part, the light less each wedge, is cut into convex
/// pieces (`L - C = union_i L cap H_1 cap .. cap H_(i-1) cap not H_i` for
/// the wedge's half-spaces `H_i`), each fanned into triangles. `None` where
/// some blocker is another shape (a sphere, a disk, another emitter) or
/// straddles the light's side.
pub fn lit_triangles(scene: &Scene<f64>, x: Vec3, k: usize) -> Option<Vec<Triangle>> {
    let light = match scene.emitters().get(k)? {
        AnyEmitter::Rectangle(r) => {
            let s = r.shape();
            let (o, a, b) = (s.origin(), s.edge_u(), s.edge_v());
            vec![o, o + a, o + a + b, o + b]
        }
        AnyEmitter::Triangle(t) => t.shape().vertices().to_vec(),
        _ => return None,
    };
    let others = scene
        .emitters()
        .iter()
        .enumerate()
        .any(|(i, e)| i != k && e.occluder().is_some());
    if others {
        return None;
    }
    let mut pieces = vec![light.clone()];
    for o in scene.occluders() {
        let (corners, normal) = match o {
            Occluder::Rectangle(r) => {
                let (p, a, b) = (r.origin(), r.edge_u(), r.edge_v());
                (vec![p, p + a, p + a + b, p + b], r.normal())
            }
            Occluder::Triangle(t) => (t.vertices().to_vec(), t.normal()),
            _ => return None,
        };
        // The blocker's plane separates x from every corner of the light.
        let side = |p: Vec3| normal.dot(&(p - corners[0]));
        let sx = side(x);
        if !(sx != 0.0 && light.iter().all(|&p| side(p) * sx < 0.0)) {
            return None;
        }
        // Inward normals of the wedge's planes through x and each edge.
        let centroid = corners.iter().fold(Vec3::zeros(), |s, p| s + p) / corners.len() as f64;
        let planes: Vec<Vec3> = (0..corners.len())
            .map(|i| {
                let m = (corners[i] - x).cross(&(corners[(i + 1) % corners.len()] - x));
                if m.dot(&(centroid - x)) < 0.0 { -m } else { m }
            })
            .collect();
        let mut next = Vec::new();
        for piece in pieces {
            let mut inside = piece;
            for m in &planes {
                // The part outside this plane is lit; the rest goes on.
                let outside = clip(&inside, |p| -m.dot(&(p - x)));
                if outside.len() >= 3 {
                    next.push(outside);
                }
                inside = clip(&inside, |p| m.dot(&(p - x)));
                if inside.len() < 3 {
                    break;
                }
            }
        }
        pieces = next;
    }
    let mut triangles = Vec::new();
    for piece in &pieces {
        for i in 1..piece.len() - 1 {
            // Slivers of zero area (a cut through a corner) hold nothing.
            if let Ok(t) = Triangle::new(piece[0], piece[i], piece[i + 1]) {
                triangles.push(t);
            }
        }
    }
    Some(triangles)
}

/// The part of the convex polygon `poly` where `side >= 0` (Sutherland–
/// Hodgman against one plane).
fn clip(poly: &[Vec3], side: impl Fn(Vec3) -> f64) -> Vec<Vec3> {
    let mut out = Vec::with_capacity(poly.len() + 1);
    for (i, &a) in poly.iter().enumerate() {
        let b = poly[(i + 1) % poly.len()];
        let (sa, sb) = (side(a), side(b));
        if sa >= 0.0 {
            out.push(a);
        }
        if (sa >= 0.0) != (sb >= 0.0) {
            out.push(a + (b - a) * (sa / (sa - sb)));
        }
    }
    out
}

/// The estimate of `a` and `b` (two forms of one integral) with the smaller
/// error, its error widened to their difference where they disagree by
/// more than ten times their errors together (one of them missed a feature
/// its own estimate could not see).
fn cross_checked(a: Estimate<f64>, b: Estimate<f64>) -> Estimate<f64> {
    let (best, other) = if a.error <= b.error { (a, b) } else { (b, a) };
    let difference = (best.value - other.value).abs();
    let error = if difference > 10.0 * (best.error + other.error) {
        best.error.max(difference)
    } else {
        best.error
    };
    Estimate {
        error,
        evaluations: a.evaluations + b.evaluations,
        ..best
    }
}

/// The closed form of `q` in this scene (module documentation).
fn closed_form(built: &Built, q: RenderingQuantity) -> Option<f64> {
    let scene = &built.scene;
    let emitters = scene.emitters();
    let apart = emitters.len() == 1 || emitters.iter().all(|e| e.at_infinity());
    if !scene.occluders().is_empty() || !apart {
        return None;
    }
    let irradiance = || -> Option<f64> {
        emitters
            .iter()
            .map(|e| irradiance_from(e, &built.receiver))
            .sum::<Option<f64>>()
    };
    if !q.reflected() {
        return irradiance();
    }
    let wo = built.receiver.frame().to_local(built.toward_viewer?);
    match built.brdf? {
        AnyBrdf::Lambert(b) => Some(b.albedo / PI * irradiance()?),
        AnyBrdf::Phong(p) => phong_under_environment(emitters, wo, p.exponent(), p.k_s),
        AnyBrdf::NormalizedPhong(p) => {
            let n = p.exponent();
            phong_under_environment(emitters, wo, n, p.k_s * (n + 2.0) / (2.0 * PI))
        }
        AnyBrdf::Ggx(_) => None,
    }
}

/// `int_H k max(0, cos alpha)^n cos theta dw L` under the environment alone
/// (`alpha` from the mirror direction of the local `wo`): `2 pi / (n + 2)`
/// at normal incidence, the clamped-cosine product for `n = 1`.
fn phong_under_environment(
    emitters: &[AnyEmitter<f64>],
    wo: Vec3,
    n: f64,
    scale: f64,
) -> Option<f64> {
    let [AnyEmitter::Environment(env)] = emitters else {
        return None;
    };
    let lobe = if wo.x == 0.0 && wo.y == 0.0 {
        exact::phong_albedo_normal(n).ok()?
    } else if n == 1.0 {
        // The mirror direction makes theta_o with the normal.
        exact::clamped_cosine_product(wo.x.hypot(wo.y).atan2(wo.z)).ok()?
    } else {
        return None;
    };
    Some(env.radiance() * scale * lobe)
}

/// `E` at the receiver from one emitter alone, when it has a closed form.
fn irradiance_from(e: &AnyEmitter<f64>, receiver: &Receiver) -> Option<f64> {
    let (x, n) = (receiver.point(), receiver.normal());
    // A planar light seen from its dark side (or edge on) sends nothing.
    let facing = |normal: Vec3, on_plane: Vec3| normal.dot(&(x - on_plane)) > 0.0;
    let l = e.radiance();
    match e {
        AnyEmitter::Rectangle(r) => {
            let s = r.shape();
            let (o, a, b) = (s.origin(), s.edge_u(), s.edge_v());
            if !facing(s.normal(), o) {
                return Some(0.0);
            }
            let f = exact::polygon_form_factor(x, n, &[o, o + a, o + a + b, o + b]).ok()?;
            Some(PI * l * f)
        }
        AnyEmitter::Triangle(t) => {
            let s = t.shape();
            let v = s.vertices();
            if !facing(s.normal(), v[0]) {
                return Some(0.0);
            }
            Some(PI * l * exact::polygon_form_factor(x, n, &v).ok()?)
        }
        AnyEmitter::Disk(d) => {
            let h = coaxial(d, x)?;
            if h < 0.0 {
                return Some(0.0);
            }
            // The receiver's normal along the axis, toward the disk or away.
            let axis = d.shape().frame().n;
            let cos = n.dot(&axis);
            if n.cross(&axis).norm() > 1e-15 {
                return None;
            }
            if cos > 0.0 {
                return Some(0.0);
            }
            Some(PI * l * exact::disk_coaxial(h, d.shape().radius()).ok()?)
        }
        AnyEmitter::Sphere(s) => {
            let sphere = s.shape();
            let to_centre = sphere.centre - x;
            let d = to_centre.norm();
            let cos_omega = (n.dot(&to_centre) / d).clamp(-1.0, 1.0);
            let e = exact::spherical_cap_irradiance(cos_omega, sphere.radius / d).ok()?;
            Some(l * e)
        }
        AnyEmitter::Environment(_) => Some(PI * l),
        AnyEmitter::Cap(c) => Some(l * cap_irradiance(c, n)?),
    }
}

/// `int_cap max(0, cos theta) dw` of a cap light for the receiver normal
/// `n`: Snyder's formula for a cap of half-angle up to `pi/2`, and for a
/// wider one `pi` less the formula for the complementary cap about `-axis`.
fn cap_irradiance(c: &CapLight<f64>, n: Vec3) -> Option<f64> {
    let cap = c.cap();
    let k = cap.one_minus_cos();
    let sin_alpha = (k * (2.0 - k)).max(0.0).sqrt();
    let cos_omega = n.dot(&cap.axis()).clamp(-1.0, 1.0);
    if k <= 1.0 {
        return exact::spherical_cap_irradiance(cos_omega, sin_alpha).ok();
    }
    if sin_alpha == 0.0 {
        return Some(PI);
    }
    Some(PI - exact::spherical_cap_irradiance(-cos_omega, sin_alpha).ok()?)
}

/// Coordinates and sizes beyond this are refused: squared distances of
/// larger ones overflow f64.
pub const MAX_COORDINATE: f64 = 1e100;

/// `[x, y, z]` as a vector.
fn vec3(v: [f64; 3]) -> Vec3 {
    Vec3::new(v[0], v[1], v[2])
}

/// A library error renamed from the library's parameter `from` to the
/// file's field `to`.
pub(crate) fn renamed(e: QuadError, from: &str, to: &str) -> QuadError {
    match e {
        QuadError::InvalidParameter {
            name,
            value,
            accepted,
        } if name == from => QuadError::InvalidParameter {
            name: to.to_string(),
            value,
            accepted,
        },
        other => other,
    }
}

/// The position and size fields of an emitter, by name.
fn emitter_numbers(spec: &EmitterSpec) -> Vec<(&'static str, Vec<f64>)> {
    match spec {
        EmitterSpec::Rectangle(r) => vec![
            ("origin", r.origin.to_vec()),
            ("edge_u", r.edge_u.to_vec()),
            ("edge_v", r.edge_v.to_vec()),
        ],
        EmitterSpec::Disk(d) => vec![("centre", d.centre.to_vec()), ("radius", vec![d.radius])],
        EmitterSpec::Triangle(t) => {
            vec![
                ("a", t.a.to_vec()),
                ("b", t.b.to_vec()),
                ("c", t.c.to_vec()),
            ]
        }
        EmitterSpec::Sphere(s) => vec![("centre", s.centre.to_vec()), ("radius", vec![s.radius])],
        EmitterSpec::Environment(_) | EmitterSpec::Cap(_) => vec![],
    }
}

/// The position and size fields of an occluder, by name.
fn occluder_numbers(spec: &OccluderSpec) -> Vec<(&'static str, Vec<f64>)> {
    match spec {
        OccluderSpec::Sphere(s) => vec![("centre", s.centre.to_vec()), ("radius", vec![s.radius])],
        OccluderSpec::Disk(d) => vec![("centre", d.centre.to_vec()), ("radius", vec![d.radius])],
        OccluderSpec::Rectangle(r) => vec![
            ("origin", r.origin.to_vec()),
            ("edge_u", r.edge_u.to_vec()),
            ("edge_v", r.edge_v.to_vec()),
        ],
        OccluderSpec::Triangle(t) => {
            vec![
                ("a", t.a.to_vec()),
                ("b", t.b.to_vec()),
                ("c", t.c.to_vec()),
            ]
        }
    }
}

/// Refuses a surface whose coordinates pass [`MAX_COORDINATE`]: at the
/// field of `fields` (its name and numbers) holding a number beyond it
/// (`scene.emitters[0].centre[0]`), or at the surface where only the sum of
/// fields reaches beyond it (an origin and an edge each of 6e99).
fn bounded(path: &str, o: &Occluder, fields: &[(&str, Vec<f64>)]) -> Result<(), SpecError> {
    let extent = o.extent();
    if extent.is_finite() && extent <= MAX_COORDINATE {
        return Ok(());
    }
    for (field, values) in fields {
        if let Some((i, v)) = values
            .iter()
            .enumerate()
            .find(|(_, v)| v.is_nan() || v.abs() > MAX_COORDINATE)
        {
            let at = if values.len() > 1 {
                format!("{path}.{field}[{i}]")
            } else {
                format!("{path}.{field}")
            };
            return Err(SpecError::at(
                at,
                format!(
                    "{v:e} is beyond {MAX_COORDINATE:e}: expected coordinates and sizes up to \
                     {MAX_COORDINATE:e} (squared distances of larger ones overflow f64)"
                ),
            ));
        }
    }
    Err(SpecError::at(
        path,
        format!(
            "a surface reaching coordinates of {extent:e}: expected coordinates and sizes up to \
             {MAX_COORDINATE:e} (squared distances of larger ones overflow f64)"
        ),
    ))
}

fn emitter(spec: &EmitterSpec) -> Result<AnyEmitter<f64>, QuadError> {
    Ok(match spec {
        EmitterSpec::Rectangle(r) => {
            RectangleLight::new(vec3(r.origin), vec3(r.edge_u), vec3(r.edge_v), r.radiance)?.into()
        }
        EmitterSpec::Disk(d) => {
            DiskLight::new(vec3(d.centre), vec3(d.normal), d.radius, d.radiance)?.into()
        }
        EmitterSpec::Triangle(t) => {
            TriangleLight::new(vec3(t.a), vec3(t.b), vec3(t.c), t.radiance)?.into()
        }
        EmitterSpec::Sphere(s) => SphereLight::new(vec3(s.centre), s.radius, s.radiance)?.into(),
        EmitterSpec::Environment(e) => EnvironmentLight::new(e.radiance)?.into(),
        EmitterSpec::Cap(c) => CapLight::new(vec3(c.axis), c.half_angle, c.radiance)
            .map_err(|e| match e {
                // 1 - cos of an angle below ~1e-162 rad underflows to 0.
                QuadError::InvalidParameter { name, .. } if name == "one_minus_cos" => {
                    QuadError::invalid(
                        "half_angle",
                        c.half_angle,
                        "an angle in (0, pi] whose 1 - cos is a positive f64 (at least about \
                         1e-161 rad)",
                    )
                }
                other => other,
            })?
            .into(),
    })
}

fn occluder(spec: &OccluderSpec) -> Result<Occluder, QuadError> {
    match spec {
        OccluderSpec::Sphere(s) => Occluder::sphere(vec3(s.centre), s.radius),
        OccluderSpec::Disk(d) => Occluder::disk(vec3(d.centre), vec3(d.normal), d.radius),
        OccluderSpec::Rectangle(r) => {
            Occluder::rectangle(vec3(r.origin), vec3(r.edge_u), vec3(r.edge_v))
        }
        OccluderSpec::Triangle(t) => Occluder::triangle(vec3(t.a), vec3(t.b), vec3(t.c)),
    }
}

fn brdf(spec: &BrdfSpec) -> Result<AnyBrdf, QuadError> {
    Ok(match spec {
        BrdfSpec::Lambert(l) => AnyBrdf::Lambert(Lambert::new(l.albedo)?),
        BrdfSpec::Phong(p) => {
            AnyBrdf::Phong(Phong::new(p.k_s, p.exponent).map_err(|e| renamed(e, "n", "exponent"))?)
        }
        BrdfSpec::NormalizedPhong(p) => AnyBrdf::NormalizedPhong(
            NormalizedPhong::new(p.k_s, p.exponent).map_err(|e| renamed(e, "n", "exponent"))?,
        ),
        BrdfSpec::Ggx(g) => AnyBrdf::Ggx(Ggx::new(g.alpha)?),
    })
}

/// Checks every number of the scene and builds it; errors name the JSON
/// path from the file's root.
fn build(spec: &SceneSpec) -> Result<Built, SpecError> {
    let r = &spec.receiver;
    let receiver = Receiver::new(vec3(r.point), vec3(r.normal))
        .map_err(|e| SpecError::from_quad("scene.receiver", e))?;
    if let Some((i, v)) = r
        .point
        .iter()
        .enumerate()
        .find(|(_, v)| v.abs() > MAX_COORDINATE)
    {
        return Err(SpecError::at(
            format!("scene.receiver.point[{i}]"),
            format!(
                "{v:e} is beyond {MAX_COORDINATE:e}: expected coordinates up to \
                 {MAX_COORDINATE:e} (squared distances of larger ones overflow f64)"
            ),
        ));
    }
    let (brdf, toward_viewer) = match (&r.brdf, r.toward_viewer) {
        (None, None) => (None, None),
        (Some(b), Some(w)) => {
            let b = brdf(b).map_err(|e| SpecError::from_quad("scene.receiver.brdf", e))?;
            let at = "scene.receiver.toward_viewer";
            let w = crate::geometry::normalize("toward_viewer", vec3(w))
                .map_err(|e| SpecError::from_quad(at, e))?;
            if receiver.normal().dot(&w) <= 0.0 {
                return Err(SpecError::at(
                    at,
                    format!(
                        "{:?} is not above the receiver's horizon (normal {:?}): expected a \
                         direction w with n . w > 0 (below it every BRDF, and L_r, is 0)",
                        r.toward_viewer.unwrap_or_default(),
                        r.normal
                    ),
                ));
            }
            (Some(b), Some(w))
        }
        (Some(_), None) => {
            return Err(SpecError::at(
                "scene.receiver",
                "missing field `toward_viewer`: a BRDF is evaluated for a viewer; give the \
                 direction toward it, [x, y, z] above the receiver's horizon",
            ));
        }
        (None, Some(_)) => {
            return Err(SpecError::at(
                "scene.receiver.toward_viewer",
                "given without a BRDF, and nothing uses it: give scene.receiver.brdf too (for \
                 the L_ quantities), or leave toward_viewer out",
            ));
        }
    };
    if spec.emitters.is_empty() {
        return Err(SpecError::at(
            "scene.emitters",
            "an empty list: give at least one emitter (without light every quantity is 0)",
        ));
    }
    let mut emitters = Vec::with_capacity(spec.emitters.len());
    for (i, e_spec) in spec.emitters.iter().enumerate() {
        let at = format!("scene.emitters[{i}]");
        let e = emitter(e_spec).map_err(|err| SpecError::from_quad(&at, err))?;
        if let Some(o) = e.occluder() {
            bounded(&at, &o, &emitter_numbers(e_spec))?;
        }
        // Every form's domain must exist from the receiver: a receiver
        // inside a sphere light has none, nor does a light too small to
        // subtend a solid angle in f64.
        if let AnyEmitter::Sphere(s) = &e {
            let (c, radius) = (s.shape().centre, s.shape().radius);
            if (receiver.point() - c).norm() <= radius {
                return Err(SpecError::at(
                    at,
                    format!(
                        "the receiver at {:?} is inside or on this sphere light (centre {:?}, \
                         radius {radius}), which emits outward: expected a receiver outside \
                         every sphere light",
                        r.point,
                        c.as_slice()
                    ),
                ));
            }
        }
        if let Err(err) = e.surface(&receiver).and_then(|_| e.cone(&receiver)) {
            return Err(SpecError::at(
                at,
                format!(
                    "its domains seen from the receiver cannot be built ({err}): expected an \
                     emitter whose cone of directions from the receiver is representable in f64 \
                     (an angular radius above about 1e-154 rad)"
                ),
            ));
        }
        emitters.push(e);
    }
    let mut occluders = Vec::with_capacity(spec.occluders.len());
    for (j, o_spec) in spec.occluders.iter().enumerate() {
        let at = format!("scene.occluders[{j}]");
        let o = occluder(o_spec).map_err(|err| SpecError::from_quad(&at, err))?;
        bounded(&at, &o, &occluder_numbers(o_spec))?;
        occluders.push(o);
    }
    Ok(Built {
        scene: Scene::new(emitters, occluders),
        receiver,
        brdf,
        toward_viewer,
    })
}

/// True when R-A needs visibility for some emitter of `spec`: an occluder,
/// or a finite emitter that can shadow another emitter.
fn needs_visibility(spec: &SceneSpec) -> bool {
    let finite = spec
        .emitters
        .iter()
        .filter(|e| !matches!(e, EmitterSpec::Environment(_) | EmitterSpec::Cap(_)))
        .count();
    !spec.occluders.is_empty() || (finite >= 1 && spec.emitters.len() >= 2)
}

fn settings(spec: &SceneSpec) -> String {
    let (e, o) = (spec.emitters.len(), spec.occluders.len());
    let visibility = if needs_visibility(spec) {
        format!(
            "visibility V (R-A's shadow rays, the V of R-3P's g) evaluated: one shadow ray per \
             area-form evaluation whose other factors are non-zero, tested against {o} \
             occluder(s) and the other finite emitters"
        )
    } else {
        "visibility V (R-A's shadow rays, the V of R-3P's g) not evaluated: no occluder, and no \
         emitter can shadow another, so V = 1 and no shadow ray is cast"
            .to_string()
    };
    format!(
        "{e} emitter(s), {o} occluder(s); {visibility}; the R-H forms find L_i by one ray per \
         evaluation against the emitters and occluders (none where the kernel times cos theta \
         is 0); the cone and area forms spend the budget on each emitter; MIS draws one light \
         and one BRDF sample per unit of budget"
    )
}

/// The report's section on this scene: the forms and the terms each
/// evaluates.
fn terms_section(built: &Built) -> String {
    use std::fmt::Write as _;
    let scene = &built.scene;
    let mut s = String::from("## Forms and terms of this scene\n\n");
    let names: Vec<&str> = scene
        .emitters()
        .iter()
        .map(|e| match e {
            AnyEmitter::Rectangle(_) => "rectangle",
            AnyEmitter::Disk(_) => "disk",
            AnyEmitter::Triangle(_) => "triangle",
            AnyEmitter::Sphere(_) => "sphere",
            AnyEmitter::Environment(_) => "environment",
            AnyEmitter::Cap(_) => "cap",
        })
        .collect();
    let cones: Vec<&str> = scene
        .emitters()
        .iter()
        .map(|e| {
            if exact_cone(e, &built.receiver) {
                "exact"
            } else {
                "bounding"
            }
        })
        .collect();
    let _ = writeln!(
        s,
        "Emitters: {} (cones from the receiver: {}); occluders: {}.\n",
        names.join(", "),
        cones.join(", "),
        scene.occluders().len()
    );
    let shadow: Vec<String> = scene
        .emitters()
        .iter()
        .enumerate()
        .map(|(k, e)| {
            let skip = if e.at_infinity() { None } else { Some(k) };
            if scene.has_blockers(skip) {
                format!("emitter {k}: tested")
            } else {
                format!("emitter {k}: not evaluated (nothing can block it; 0 shadow rays)")
            }
        })
        .collect();
    s.push_str("| quantity | form | domain | integrand | terms evaluated per node |\n");
    s.push_str("|---|---|---|---|---|\n");
    let brdf = built.brdf.is_some();
    let kernel = |q: RenderingQuantity| if q.reflected() { "f_r " } else { "" };
    for &q in <RenderingQuantity as family::Quantity>::all() {
        if q.reflected() && !brdf {
            continue;
        }
        let k = kernel(q);
        let (form, domain, integrand, terms) = match q.form() {
            Form::Hemisphere => (
                "R-H",
                "hemisphere, uniform map",
                format!("2 pi {k}L_i cos theta"),
                "L_i: one ray against every surface",
            ),
            Form::Cosine => (
                "R-H",
                "hemisphere, projected (Malley) map",
                format!("pi {k}L_i"),
                "L_i: one ray against every surface",
            ),
            Form::Brdf => (
                "R-H",
                "BRDF-sampled map",
                "f_r L_i cos theta / pdf".to_string(),
                "L_i: one ray against every surface",
            ),
            Form::Cone => (
                "R-H per emitter",
                "the emitter's cone of directions",
                format!("{k}L_i^k cos theta J"),
                "L_i^k: one ray against every surface",
            ),
            Form::Area => (
                "R-A (R-S, g of R-3P) per emitter",
                "the emitter's surface, its map's Jacobian",
                format!("L_e {k}cos theta cos theta' / r^2 V J"),
                "V: a shadow ray where tested (below)",
            ),
        };
        let name = family::Quantity::name(&q);
        let _ = writeln!(s, "| {name} | {form} | {domain} | {integrand} | {terms} |");
    }
    let _ = writeln!(
        s,
        "\nJ is the Jacobian of the domain's map. Visibility of the area forms: {}.",
        shadow.join("; ")
    );
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed form of a cap light wider than a hemisphere is `pi` less
    /// its complement's: a cap of half-angle `pi` is the environment.
    #[test]
    fn a_cap_light_of_half_angle_pi_is_the_environment() -> Result<(), QuadError> {
        let whole = CapLight::new(Vec3::new(0.3, 0.1, -1.0), PI, 1.0)?;
        let e = cap_irradiance(&whole, Vec3::z()).ok_or(QuadError::invalid("cap", 0, "a value"))?;
        assert!((e - PI).abs() < 1e-15, "{e}");
        // A cap of 3 pi / 4 about the normal misses only the lower directions.
        let wide = CapLight::new(Vec3::z(), 0.75 * PI, 1.0)?;
        let e = cap_irradiance(&wide, Vec3::z()).ok_or(QuadError::invalid("cap", 0, "a value"))?;
        assert!((e - PI).abs() < 1e-15, "{e}");
        Ok(())
    }
}
