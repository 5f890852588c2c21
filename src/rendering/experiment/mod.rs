//! The rendering-equation family (`R-*` in docs/EQUATIONS.md) as the experiment
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
//!
//! `evaluate` computes a job's quantity by its method, `terms` says in the
//! report what the scene evaluates, `reference` holds the closed forms and
//! the converged value, and `spec` the scene format; the family, its
//! quantities and BRDFs are here.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::brdf::{Brdf, Ggx, Lambert, NormalizedPhong, Phong, Sample};
use super::forms::Reach;
use super::mis::Heuristic;
use super::receiver::Receiver;
use super::scene::Scene;
use crate::domain::Vec3;
use crate::error::{QuadError, SpecError};
use crate::family::{self, Family, Measured, Method, Outcome};

mod doubts;
mod evaluate;
mod reference;
mod spec;
mod terms;

pub use evaluate::evaluate_counted;
pub use reference::lit_triangles;
use reference::{closed_form, converged_value};
use spec::build;
pub use spec::{
    BrdfSpec, CapLightSpec, DiskLightSpec, DiskSpec, EmitterSpec, EnvironmentSpec, GgxSpec,
    LambertSpec, MAX_COORDINATE, OccluderSpec, PhongSpec, ReceiverSpec, RectangleLightSpec,
    RectangleSpec, SceneSpec, SphereLightSpec, SphereSpec, TriangleLightSpec, TriangleSpec,
};
pub(crate) use spec::{
    bounded, emitter as build_emitter, emitter_numbers, occluder as build_occluder,
    occluder_numbers, renamed, vec3,
};
use terms::{settings, terms_section};

/// The rendering family.
#[derive(Debug, Clone, Copy)]
pub struct Rendering;

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
    /// Doubts about the scene, each at its JSON path (an emitter facing
    /// away from the receiver).
    pub warnings: Vec<SpecError>,
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
    const BUDGET_UNIT: &'static str = "the points a rule is given (per emitter for the cone and \
                                       area forms; samples per strategy for MIS), not the \
                                       evaluations it spends: those are the evaluations column, \
                                       a rule's error estimate and refinement included";

    type SceneSpec = SceneSpec;
    type Scene = Built;
    type Quantity = RenderingQuantity;
    type Estimator = Mis;

    fn build(spec: &SceneSpec) -> Result<Built, SpecError> {
        build(spec)
    }

    fn warnings(built: &Built) -> Vec<SpecError> {
        built.warnings.clone()
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
        // Each sample's shadow ray tests every occluder and every finite
        // emitter (100 000 triangles made a sample about 1 ms; 100 000
        // sphere lights ran without a bound, each of their cone forms' rays
        // testing the other lights).
        let visibility = 1.0 + blockers(built);
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

    /// [`Self::converged`] at its cap: for each emitter, the light's own
    /// integral and one per blocker (what it hides), each of
    /// [`CONVERGED_PER_N`]` n` evaluations testing every blocker:
    /// `kinds x emitters x 100 n x (1 + B)^2` for `B` occluders and finite
    /// emitters (`(1 + B)` where all are polygons, cut into lit pieces once),
    /// `kinds` 2 where irradiance and reflected radiance are both asked
    /// for. (1000 sphere blockers under a sky were priced as one
    /// integral and ran for more than 400 s.)
    fn converged_cost(built: &Built, n: usize, quantities: &[RenderingQuantity]) -> [f64; 2] {
        let budget = CONVERGED_PER_N.saturating_mul(n);
        let blockers = blockers(built);
        let kinds = [false, true]
            .iter()
            .filter(|&&r| quantities.iter().any(|q| q.reflected() == r))
            .count() as f64;
        let emitters = built.scene.emitters().len() as f64;
        // Polygons behind polygons are cut into lit pieces once and summed
        // by their contours: each blocker is met once, not per evaluation.
        use super::emitter::AnyEmitter;
        use super::occluder::Occluder;
        let polygons = built
            .scene
            .occluders()
            .iter()
            .all(|o| matches!(o, Occluder::Rectangle(_) | Occluder::Triangle(_)))
            && built
                .scene
                .emitters()
                .iter()
                .all(|e| matches!(e, AnyEmitter::Rectangle(_) | AnyEmitter::Triangle(_)));
        let per_light = if polygons {
            1.0 + blockers
        } else {
            (1.0 + blockers).powi(2)
        };
        let evaluations = kinds * emitters * budget as f64 * per_light;
        let rule = Method::Rule(crate::quadrature::AnyRule::Base(
            crate::quadrature::BaseRule::GenzMalik(reference::CONVERGED_RULE),
        ));
        let bytes = quantities
            .iter()
            .map(|&q| Self::memory(built, &rule, budget, q))
            .fold(0.0, f64::max);
        [evaluations, bytes]
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

/// What a ray toward a light may meet: the occluders and every finite
/// emitter.
fn blockers(built: &Built) -> f64 {
    let finite = built
        .scene
        .emitters()
        .iter()
        .filter(|e| !super::emitter::Emitter::at_infinity(*e))
        .count();
    (built.scene.occluders().len() + finite) as f64
}
