//! The full rendering equation in a closed scene as a family of the
//! experiment layer (`"family": "furnace"`): the inside of an integrating
//! sphere with Lambertian walls of albedo `rho`, emitting `L_e` on a cap of
//! half-angle `alpha` (`alpha = pi`: the white furnace), seen at one wall
//! point ([`crate::rendering::furnace`] has the scene and its closed form).
//!
//! | quantity | what | rules (2-D, over the hemisphere) | `path-tracing` |
//! |---|---|---|---|
//! | `L` | `L(x)`, R-H's recursion in full | the Neumann series to `scene.bounces` reflections (default: as many as a truncation of 1e-16 of `L` needs), each bounce an R-H integral by the rule | unbiased: Russian roulette with survival `rho` |
//! | `L_K` | `L_K(x)`, the series after `K = scene.bounces` reflections | as for `L` | every path ended after `K` bounces |
//!
//! The reference of both is closed (R-H with the sphere's constant kernel):
//! `L(x) = L_e [x in cap] + rho L_e (1 - cos alpha) / (2 (1 - rho))` and
//! `L_K(x) = L_e [x in cap] + rho L_e (1 - cos alpha)/2 (1 - rho^K) / (1 -
//! rho)`. `L` of a rule is then off by its quadrature error and the
//! truncation after `K`; `L_K` by its quadrature error alone. The report's
//! scene section gives the truncation bounce by bounce and the bounces each
//! accuracy needs (about 13800 for 1e-6 at `rho = 0.999`).
//!
//! **Terms left out**: the scene is closed and unoccluded (the sphere's
//! inside sees itself whole), so no visibility is tested; a bounce whose
//! direction misses the cap adds no emission and costs nothing more.
//!
//! ```
//! use lightquad::family::Family;
//! use lightquad::rendering::closed::{Furnace, FurnaceQuantity};
//!
//! let spec = serde_json::from_value(serde_json::json!({
//!     "albedo": 0.999, "emission": 1.0, "point": [0.0, 0.0, -1.0]}))?;
//! let scene = Furnace::build(&spec)?;
//! // The white furnace: L = L_e / (1 - rho) = 1000.
//! let l = Furnace::closed_form(&scene, FurnaceQuantity::L).expect("closed");
//! assert!((l[0] - 1000.0).abs() < 1e-9);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::fmt::Write as _;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::experiment::renamed;
use super::furnace::IntegratingSphere;
use crate::domain::Vec3;
use crate::error::{QuadError, SpecError};
use crate::experiment::tagged;
use crate::family::{self, Family, Measured, Method, Outcome, Quantity as _};
use crate::quadrature::{AnyRule, BaseRule, GenzMalik, Rule};

/// The furnace family.
#[derive(Debug, Clone, Copy)]
pub struct Furnace;

/// The most bounces a Neumann series may take (a loop of two products
/// each; 1e8 take about a tenth of a second).
pub const MAX_BOUNCES: u32 = 100_000_000;

/// The integrating sphere as written in an experiment file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SceneSpec {
    /// `R`, the sphere's radius (default 1).
    #[serde(default = "one")]
    pub radius: f64,
    /// `rho`, the walls' albedo, in `[0, 1)`.
    pub albedo: f64,
    /// `L_e`, the radiance the cap emits.
    pub emission: f64,
    /// `alpha`, the cap's half-angle about `axis` seen from the centre, in
    /// radians (default pi: every wall emits, the white furnace).
    #[serde(default = "pi")]
    pub half_angle: f64,
    /// The cap's axis (default `[0, 0, 1]`).
    #[serde(default = "up", deserialize_with = "tagged::array")]
    pub axis: [f64; 3],
    /// The wall point `x`, as its direction from the centre.
    #[serde(deserialize_with = "tagged::array")]
    pub point: [f64; 3],
    /// `K`, the reflections the Neumann series keeps (default: as many as a
    /// truncation of 1e-16 of `L(x)` needs).
    #[serde(default)]
    pub bounces: Option<u32>,
}

fn one() -> f64 {
    1.0
}

fn pi() -> f64 {
    std::f64::consts::PI
}

fn up() -> [f64; 3] {
    [0.0, 0.0, 1.0]
}

/// The sphere built, the wall point and the series' length.
#[derive(Debug, Clone, PartialEq)]
pub struct Built {
    /// The sphere.
    pub sphere: IntegratingSphere,
    /// The wall point `x`.
    pub x: Vec3,
    /// `K`.
    pub bounces: u32,
}

/// The furnace's quantities (module table).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize, JsonSchema,
)]
pub enum FurnaceQuantity {
    /// `L(x)`.
    L,
    /// `L_K(x)`.
    #[serde(rename = "L_K")]
    LK,
}

impl family::Quantity for FurnaceQuantity {
    fn name(&self) -> &'static str {
        match self {
            FurnaceQuantity::L => "L",
            FurnaceQuantity::LK => "L_K",
        }
    }

    fn all() -> &'static [Self] {
        &[FurnaceQuantity::L, FurnaceQuantity::LK]
    }

    /// A radiance.
    fn bounds(&self) -> (f64, f64) {
        (0.0, f64::INFINITY)
    }
}

/// Path tracing with Russian roulette, the family's estimator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "rule", rename_all = "kebab-case")]
pub enum PathTracing {
    /// Paths from `x` along cosine-sampled directions, each bounce survived
    /// with probability `rho` (the analog estimator); for `L_K` every path
    /// ends after `K` bounces.
    PathTracing,
}

impl family::Estimator for PathTracing {
    fn name(&self) -> &'static str {
        "path-tracing"
    }
    fn about(&self) -> &'static str {
        "path tracing from the wall point: cosine-sampled bounces, Russian roulette with \
         survival rho, L_e added at every wall point reached; one path per unit of budget, \
         1 / (1 - rho) bounces a path on average; standard error"
    }
    /// Two paths: a standard error needs them.
    fn min_budget(&self) -> usize {
        2
    }
    fn is_random(&self) -> bool {
        true
    }
    fn all() -> Vec<Self> {
        vec![PathTracing::PathTracing]
    }
}

/// The largest radiance in the sphere accepted (its sums over bounces and
/// paths stay finite).
pub const MAX_RADIANCE: f64 = 1e300;

/// The relative truncation the default series length reaches.
const DEFAULT_TRUNCATION: f64 = 1e-16;

fn build(spec: &SceneSpec) -> Result<Built, SpecError> {
    let vec3 = |v: [f64; 3]| Vec3::new(v[0], v[1], v[2]);
    let sphere = IntegratingSphere::new(
        spec.radius,
        spec.albedo,
        spec.emission,
        spec.half_angle,
        vec3(spec.axis),
    )
    // The library's `alpha` is the file's `half_angle`.
    .map_err(|e| SpecError::from_quad("scene", renamed(e, "alpha", "half_angle")))?;
    // The answer is the same at every size; sizes whose chords overflow, or
    // radiances whose sum over the bounces does, are refused.
    if !(1e-100..=1e100).contains(&spec.radius) {
        return Err(SpecError::at(
            "scene.radius",
            format!("{:e}: expected a radius in [1e-100, 1e100]", spec.radius),
        ));
    }
    let most = spec.emission / (1.0 - spec.albedo);
    if most > MAX_RADIANCE {
        return Err(SpecError::at(
            "scene.emission",
            format!(
                "{:e} at albedo {}: the radiance in the sphere, up to L_e / (1 - rho) = {most:e}, \
                 would pass {MAX_RADIANCE:e}: expected a smaller emission",
                spec.emission, spec.albedo
            ),
        ));
    }
    let d = vec3(spec.point);
    let norm = d.norm();
    if !(norm.is_finite() && norm > 0.0) {
        return Err(SpecError::at(
            "scene.point",
            format!(
                "{:?}: expected a non-zero direction from the centre whose length f64 holds \
                 (components up to about 1e154)",
                spec.point
            ),
        ));
    }
    let x = sphere.wall(d);
    let bounces = match spec.bounces {
        Some(k) if k > MAX_BOUNCES => {
            return Err(SpecError::at(
                "scene.bounces",
                format!("{k}: expected at most {MAX_BOUNCES}"),
            ));
        }
        Some(k) => k,
        None => match sphere.bounces_needed(&x, DEFAULT_TRUNCATION) {
            None => 0,
            Some(k) if k <= f64::from(MAX_BOUNCES) => k as u32,
            Some(k) => {
                return Err(SpecError::at(
                    "scene.albedo",
                    format!(
                        "{}: a truncation of {DEFAULT_TRUNCATION:e} needs {k:.2e} bounces, more \
                         than {MAX_BOUNCES}: expected an albedo further from 1, or scene.bounces \
                         given",
                        spec.albedo
                    ),
                ));
            }
        },
    };
    Ok(Built { sphere, x, bounces })
}

impl Family for Furnace {
    const NAME: &'static str = "furnace";
    const ABOUT: &'static str = "the full rendering equation in a closed scene: an integrating \
                                 sphere (the white furnace when every wall emits) by its Neumann \
                                 series with any 2-D rule per bounce, and by path tracing";
    const EQUATIONS: &'static [&'static str] = &["R-H", "R-3P"];
    const BUDGET_UNIT: &'static str = "points per hemisphere integral (rules: the series \
                                       reuses them every bounce; the evaluations column counts \
                                       what they spent); paths (path-tracing)";
    const OVER_BUDGET: &'static str = "the series integrates two functions over the hemisphere \
        (the cap's emission and 1), each with the rule's own error estimate: about 2 n, or 7 n \
        for Gauss–Legendre";

    type SceneSpec = SceneSpec;
    type Scene = Built;
    type Quantity = FurnaceQuantity;
    type Estimator = PathTracing;

    fn build(spec: &SceneSpec) -> Result<Built, SpecError> {
        build(spec)
    }

    /// The hemisphere of each bounce.
    fn dimension(_: &Built, _: FurnaceQuantity) -> usize {
        2
    }

    fn channels(_: &Built, _: FurnaceQuantity) -> usize {
        1
    }

    fn estimates(_: &PathTracing) -> &'static [FurnaceQuantity] {
        &[FurnaceQuantity::L, FurnaceQuantity::LK]
    }

    /// Two hemisphere integrals and the series' loop; a path costs its
    /// bounces, `1 / (1 - rho)` on average.
    fn cost(built: &Built, method: &Method<PathTracing>, budget: usize, _: FurnaceQuantity) -> f64 {
        match method {
            Method::Rule(rule) => 2.0 * rule.evaluations(budget, 2) + f64::from(built.bounces),
            Method::Estimator(_) => budget as f64 / (1.0 - built.sphere.albedo()),
        }
    }

    fn evaluate(
        built: &Built,
        method: &Method<PathTracing>,
        budget: usize,
        rng: &mut rand_pcg::Pcg64,
        quantities: &[FurnaceQuantity],
    ) -> Result<Outcome<FurnaceQuantity>, QuadError> {
        let (s, x, k) = (&built.sphere, &built.x, built.bounces);
        match method {
            // One series serves both: L_K is L of this K.
            Method::Rule(rule) => {
                let value = Measured::from(s.neumann_estimate(x, rule, budget, k, rng)?);
                Ok(quantities.iter().map(|&q| (q, value.clone())).collect())
            }
            Method::Estimator(PathTracing::PathTracing) => quantities
                .iter()
                .map(|&q| {
                    let most = match q {
                        FurnaceQuantity::L => u64::MAX,
                        FurnaceQuantity::LK => u64::from(k),
                    };
                    Ok((q, Measured::from(s.path_trace_to(x, budget, most, rng)?)))
                })
                .collect(),
        }
    }

    fn closed_form(built: &Built, q: FurnaceQuantity) -> Option<Vec<f64>> {
        Some(vec![match q {
            FurnaceQuantity::L => built.sphere.radiance(&built.x),
            FurnaceQuantity::LK => built.sphere.truncated(&built.x, built.bounces),
        }])
    }

    fn closed_forms_available() -> &'static str {
        "every furnace quantity has one"
    }

    /// [`Self::converged`]'s Genz–Malik at `n^2` evaluations a hemisphere
    /// integral, priced as a job of it.
    fn converged_cost(built: &Built, n: usize, quantities: &[FurnaceQuantity]) -> [f64; 2] {
        let method = Method::Rule(converged_rule());
        family::job_cost::<Self>(built, &method, converged_budget(n), quantities)
    }

    /// The series with adaptive Genz–Malik (relative tolerance 1e-12) at
    /// `n^2` evaluations per hemisphere integral: for `L_K` to the file's
    /// `K`, for `L` to as many bounces as a truncation of 1e-16 of `L` needs
    /// whatever the file's `K` (the converged value of `L` is `L`, not the
    /// rules' truncated series), the truncation left added to its error.
    fn converged(
        built: &Built,
        n: usize,
        quantities: &[FurnaceQuantity],
    ) -> Result<Outcome<FurnaceQuantity>, QuadError> {
        let rule = converged_rule();
        let mut out = Outcome::new();
        for &q in quantities {
            let mut series = built.clone();
            if q == FurnaceQuantity::L {
                series.bounces = built
                    .sphere
                    .bounces_needed(&built.x, DEFAULT_TRUNCATION)
                    .map_or(0, |k| k.min(f64::from(MAX_BOUNCES)) as u32);
            }
            let mut rng = <rand_pcg::Pcg64 as rand::SeedableRng>::seed_from_u64(0);
            let mut m = Self::evaluate(
                &series,
                &Method::Rule(rule.clone()),
                converged_budget(n),
                &mut rng,
                &[q],
            )?
            .remove(&q)
            .ok_or_else(|| QuadError::invalid("quantity", q.name(), "a furnace quantity"))?;
            if q == FurnaceQuantity::L {
                let left = built.sphere.radiance(&built.x)
                    - built.sphere.truncated(&built.x, series.bounces);
                for e in &mut m.error {
                    *e += left.abs();
                }
            }
            out.insert(q, m);
        }
        Ok(out)
    }

    fn settings(spec: &SceneSpec) -> String {
        format!(
            "integrating sphere of radius {}, albedo {}, emission {} on a cap of half-angle {} \
             rad about {:?}; wall point toward {:?}; {}",
            spec.radius,
            spec.albedo,
            spec.emission,
            spec.half_angle,
            spec.axis,
            spec.point,
            match spec.bounces {
                Some(k) => format!("the series keeps {k} bounces"),
                None => format!(
                    "the series keeps the bounces a truncation of {DEFAULT_TRUNCATION:e} needs"
                ),
            }
        )
    }

    fn scene_audit(built: &Built) -> Option<String> {
        Some(truncation_section(built))
    }
}

/// The truncation of the Neumann series bounce by bounce, and the bounces
/// each accuracy needs, in closed form.
fn truncation_section(built: &Built) -> String {
    let s = &built.sphere;
    let l = s.radiance(&built.x);
    let mut md = String::from("## The Neumann series bounce by bounce\n\n");
    let _ = writeln!(
        md,
        "`L(x)` = {l:.10e} (closed form). `L_K` keeps {} bounces. What stopping after `K` \
         bounces misses, `L_e (1 - cos alpha)/2 rho^(K+1) / (1 - rho)`, relative to `L(x)`:\n",
        built.bounces
    );
    md.push_str("| K | L_K (closed form) | truncation, relative |\n|---:|---:|---:|\n");
    let mut ks: Vec<u32> = [0u32, 1, 2, 5, 10, 20, 50, 100, 1000, 10_000, 100_000]
        .into_iter()
        .filter(|&k| k <= built.bounces)
        .collect();
    if ks.last() != Some(&built.bounces) {
        ks.push(built.bounces);
    }
    for k in ks {
        // The truncation by its own formula: L - L_K in f64 is one rounding
        // step of L where the truncation is below it (1.1e-16 for 1.0e-16).
        let _ = writeln!(
            md,
            "| {k} | {:.10e} | {:.2e} |",
            s.truncated(&built.x, k),
            if l > 0.0 { s.truncation(k) / l } else { 0.0 }
        );
    }
    md.push('\n');
    let needs: Vec<String> = [1e-3, 1e-6, 1e-10, 1e-15]
        .into_iter()
        .map(|tol| match s.bounces_needed(&built.x, tol) {
            Some(k) => format!("{tol:.0e}: {k:.0}"),
            None => format!("{tol:.0e}: 0"),
        })
        .collect();
    let _ = writeln!(
        md,
        "Bounces a relative truncation needs: {} (the smallest `K` with `rho^(K+1)` times \
         `L_e (1 - cos alpha) / (2 (1 - rho) L(x))` at most the tolerance).",
        needs.join("; ")
    );
    md
}

/// The converged evaluation's rule: adaptive Genz–Malik to a relative
/// tolerance of 1e-12.
fn converged_rule() -> AnyRule {
    AnyRule::Base(BaseRule::GenzMalik(GenzMalik {
        abs_tol: 0.0,
        rel_tol: 1e-12,
    }))
}

/// The converged evaluation's budget a hemisphere integral at `n`: `n^2`,
/// at least Genz–Malik's 17 of one region.
fn converged_budget(n: usize) -> usize {
    n.saturating_mul(n).max(17)
}
