//! Whitted ray tracing (`W-*` in docs/EQUATIONS.md) as the experiment layer
//! sees it (`"family": "whitted"`): a scene of spheres, planes and triangles
//! with W-6.1 materials, point and directional lights, an ambient intensity
//! and a pinhole camera; the value of a pixel (or of every pixel) as the
//! integral over its square, estimated by every 2-D rule of the core and by
//! Whitted's own schemes.
//!
//! | quantity | value | channels |
//! |---|---|---:|
//! | `coverage` | the fraction of pixel `scene.pixel` covered by some object (1 where the primary ray hits, 0 where it escapes) | 1 |
//! | `pixel` | the box-filtered intensity of pixel `scene.pixel`, `(1/|P|) int_P I(x, y) dx dy`, I by W-6.1 with W-Phong, traced recursively | 3 (R, G, B) |
//! | `image` | every pixel's, rows from the top | 3 x width x height |
//!
//! Each is an integral over the pixel square (2-D): every 2-D rule
//! integrates it with the budget per pixel (`stratified` is jittered
//! sampling, `sobol` scrambled low-discrepancy points). **Estimators**
//! beside the rules, Whitted's schemes ([`super::pixel`]):
//!
//! | estimator | budget `n` buys | rays |
//! |---|---|---|
//! | `centre` | nothing: one ray per pixel centre | 1 per pixel |
//! | `grid` | W-SS: the `m x m` grid of cell centres, `m = floor(sqrt(n))` (`n = 9`: the document's 3 x 3) | `m^2` per pixel |
//! | `corner` | W-Corner: corners of an `m x m` grid per pixel shared between neighbours, `m = floor(sqrt(n))` (`n < 4`: Whitted's four corners) | `(s m + 1)(z m + 1)` for an `s x z` block |
//! | `adaptive` | Whitted's adaptive subdivision, a square split where its corners differ by more than `threshold`, down to `floor(log4 n)` splits | what the block needs |
//!
//! A measured value's `evaluations` are the rays traced, every kind
//! (primary, shadow, reflection, refraction); [`evaluate_counted`] gives
//! them by kind.
//!
//! **Closed forms.** `coverage` when the scene's only object is a triangle
//! (the film points whose rays meet it: the common part of three film
//! half-planes, one per plane through the eye and an edge, clipped to the
//! pixel: [`super::coverage::convex_fraction`]; a vertex behind the eye or
//! far beyond it is never divided by its depth) or a plane the eye is not on
//! (the film points whose rays meet it form a half-plane of the film:
//! [`super::coverage::half_plane_fraction`]); `pixel` and `image` when, in
//! addition, the object's intensity is the same everywhere (no light
//! reaches its diffuse or specular terms, no mirror or transmitted ray):
//! `background + (I_a k_a C - background) coverage`.
//!
//! **Converged reference** ([`Whitted::converged`]): each pixel cut along
//! the scene's outlines on the film ([`super::pieces`]: triangle edges,
//! plane horizons, the lines bounding a sphere's outline), and adaptive
//! Genz–Malik (its whole budget) on each piece, [`CONVERGED_PER_N`]`
//! n` evaluations per pixel shared between them (`n / 16` of that per pixel
//! for `image`): a covered sliver a millionth of the pixel wide is a piece
//! of its own, so it is sampled. Coverage by triangles and planes is
//! constant on a piece; a sphere's outline, a shadow's or a reflection's
//! edge inside a piece makes it converge algebraically, so the layer's
//! check against `2n` states the accuracy reached.
//!
//! **Terms left out.** No transparent material, no refraction ray; no
//! `k_s`, no reflection ray; no lights, no shadow ray (see
//! [`super::shade`]); the report's settings say which kinds the scene
//! traces.
//!
//! ```
//! use lightquad::family::{Family, Method};
//! use lightquad::whitted::experiment::{Scheme, Whitted, WhittedQuantity};
//! use rand::SeedableRng;
//!
//! // A white triangle on black, ambient only: the pixel is its coverage.
//! let spec = serde_json::from_value(serde_json::json!({
//!     "camera": {"eye": [0.0, 0.0, 0.0], "look_at": [0.0, 0.0, -1.0], "up": [0.0, 1.0, 0.0],
//!                "fov_y": 90.0, "width": 4, "height": 4},
//!     "ambient": [1.0, 1.0, 1.0],
//!     "objects": [{"type": "triangle", "a": [-3.0, -3.0, -1.0], "b": [0.3, -3.0, -1.0],
//!                  "c": [-3.0, 0.7, -1.0], "material": {"k_a": 1.0}}],
//!     "pixel": [2, 1]
//! }))?;
//! let scene = Whitted::build(&spec)?;
//! let exact = Whitted::closed_form(&scene, WhittedQuantity::Coverage).ok_or("none")?[0];
//! let grid: Method<Scheme> = serde_json::from_str(r#"{"rule": "grid"}"#)?;
//! let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
//! let out = Whitted::evaluate(&scene, &grid, 4096, &mut rng, &[WhittedQuantity::Coverage])?;
//! assert!((out[&WhittedQuantity::Coverage].value[0] - exact).abs() < 0.02);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod build;
mod closed_form;
mod render_spec;
mod spec;

use build::build;
use closed_form::closed_form;

pub use build::{BUSHY_TREE, RESOLVED_SCENE, SMALLEST_RESOLVED, SMALLEST_SIZE};
pub use render_spec::{
    MAX_RENDER_PIXELS, MAX_RENDER_RAYS, RENDER_BYTES_PER_PIXEL, RENDER_RESERVE, render_spec,
    scene_of,
};
pub use spec::{
    CameraSpec, DirectionalLightSpec, LightSpec, MAX_COORDINATE, MaterialSpec, ObjectSpec,
    PlaneSpec, PointLightSpec, SceneSpec, SphereSpec, TriangleSpec,
};

use std::fmt::Write as _;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::error::{QuadError, SpecError};
use crate::family::{self, Family, Flag, Measured, Method, Outcome};
use crate::quadrature::{AnyRule, BaseRule, GenzMalik, Rule};
use crate::value::{Rgb, Value};
use crate::whitted::intersect::Shape;
use crate::whitted::pieces;
use crate::whitted::render::{self, Estimated, Scheme as Render};
use crate::whitted::scene::Scene;
use crate::whitted::shade::RayCount;

/// The Whitted family.
#[derive(Debug, Clone, Copy)]
pub struct Whitted;

/// A quantity of the family (module documentation).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize, JsonSchema,
)]
#[serde(rename_all = "kebab-case")]
pub enum WhittedQuantity {
    /// The covered fraction of `scene.pixel`.
    Coverage,
    /// The RGB value of `scene.pixel`.
    Pixel,
    /// Every pixel's RGB value.
    Image,
}

impl family::Quantity for WhittedQuantity {
    fn name(&self) -> &'static str {
        match self {
            WhittedQuantity::Coverage => "coverage",
            WhittedQuantity::Pixel => "pixel",
            WhittedQuantity::Image => "image",
        }
    }

    fn all() -> &'static [Self] {
        &[
            WhittedQuantity::Coverage,
            WhittedQuantity::Pixel,
            WhittedQuantity::Image,
        ]
    }

    /// Intensities and fractions are never negative.
    fn bounds(&self) -> (f64, f64) {
        match self {
            WhittedQuantity::Coverage => (0.0, 1.0),
            _ => (0.0, f64::INFINITY),
        }
    }
}

/// Whitted's schemes beside the rules (module documentation).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "rule", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Scheme {
    /// One ray through the pixel's centre.
    Centre,
    /// W-SS: an `m x m` grid of cell centres.
    Grid,
    /// W-Corner: shared corner rays, the composite trapezoid rule.
    Corner,
    /// Whitted's adaptive subdivision.
    Adaptive {
        /// The largest spread of a square's corner values (any channel)
        /// left unsplit, finite and `>= 0` (default 0.01).
        #[serde(default = "default_threshold")]
        threshold: f64,
    },
}

fn default_threshold() -> f64 {
    0.01
}

impl family::Estimator for Scheme {
    fn name(&self) -> &'static str {
        match self {
            Scheme::Centre => "centre",
            Scheme::Grid => "grid",
            Scheme::Corner => "corner",
            Scheme::Adaptive { .. } => "adaptive",
        }
    }
    fn about(&self) -> &'static str {
        match self {
            Scheme::Centre => "one ray through each pixel's centre (the budget buys nothing)",
            Scheme::Grid => {
                "W-SS: the mean over the centres of an m x m grid of cells, m = floor(sqrt(n)) \
                 (the midpoint product rule; n = 9 is the document's 3 x 3)"
            }
            Scheme::Corner => {
                "W-Corner: rays through the corners of an m x m grid per pixel, m = \
                 floor(sqrt(n)), shared with the neighbours (the composite trapezoid rule; \
                 (s m + 1)(z m + 1) rays for s x z pixels)"
            }
            Scheme::Adaptive { .. } => {
                "Whitted's adaptive subdivision: corner rays, a square split in four where its \
                 corners differ by more than `threshold`, to floor(log4 n) levels, points shared"
            }
        }
    }
    fn min_budget(&self) -> usize {
        1
    }
    fn is_random(&self) -> bool {
        false
    }
    /// Points per axis: `floor(sqrt(n))` for the grid and the corners,
    /// `2^levels` for the finest subdivision; the centre ray's budget buys
    /// nothing (`n`, where its error does not move).
    fn resolution(&self, n: usize, _dim: usize) -> f64 {
        let side = ((n as f64).sqrt().floor()).max(1.0);
        match self {
            Scheme::Centre => n as f64,
            Scheme::Grid | Scheme::Corner => side,
            Scheme::Adaptive { .. } => f64::from(1u32 << levels(n)),
        }
    }
    fn all() -> Vec<Self> {
        vec![
            Scheme::Centre,
            Scheme::Grid,
            Scheme::Corner,
            Scheme::Adaptive {
                threshold: default_threshold(),
            },
        ]
    }
}

/// The built scene: the scene of W-6.1 and the pixel of the one-pixel
/// quantities.
#[derive(Debug, Clone)]
pub struct Built {
    /// The scene.
    pub scene: Scene,
    /// `[i, j]` of `coverage` and `pixel`.
    pub pixel: Option<[usize; 2]>,
    /// Warnings with their JSON paths (materials that are not energy
    /// conserving).
    pub warnings: Vec<SpecError>,
}

/// Evaluations per pixel of the converged reference for each `n` of
/// `{"type": "converged", "n": n}` (400, the default, gives 40000).
pub const CONVERGED_PER_N: usize = 100;

/// The render scheme of `method` at `budget`.
fn scheme(method: &Method<Scheme>, budget: usize) -> Render {
    let side = ((budget as f64).sqrt().floor() as usize).max(1);
    match method {
        Method::Rule(rule) => Render::Rule {
            rule: rule.clone(),
            n: budget,
        },
        Method::Estimator(Scheme::Centre) => Render::Centre,
        Method::Estimator(Scheme::Grid) => Render::Grid { n: side },
        Method::Estimator(Scheme::Corner) => Render::Corner { m: side },
        Method::Estimator(Scheme::Adaptive { threshold }) => Render::Adaptive {
            threshold: *threshold,
            max_level: levels(budget),
        },
    }
}

/// `floor(log4 n)`, at most [`super::pixel::MAX_LEVEL`].
fn levels(n: usize) -> u32 {
    ((usize::BITS - 1 - n.max(1).leading_zeros()) / 2).min(super::pixel::MAX_LEVEL)
}

/// The pixel asked for, or the error naming `scene.pixel`.
fn the_pixel(built: &Built) -> Result<[usize; 2], QuadError> {
    built.pixel.ok_or_else(|| {
        QuadError::invalid(
            "pixel",
            "none",
            "scene.pixel = [i, j] for the coverage and pixel quantities",
        )
    })
}

/// One quantity by `method` at `budget`, with the rays traced by kind.
pub fn evaluate_counted(
    built: &Built,
    method: &Method<Scheme>,
    budget: usize,
    rng: &mut rand_pcg::Pcg64,
    q: WhittedQuantity,
) -> Result<(Measured, RayCount), QuadError> {
    by_scheme(built, &scheme(method, budget), rng, q)
}

/// One quantity by a render scheme, with the rays traced by kind.
fn by_scheme(
    built: &Built,
    scheme: &Render,
    rng: &mut rand_pcg::Pcg64,
    q: WhittedQuantity,
) -> Result<(Measured, RayCount), QuadError> {
    let scene = &built.scene;
    let cam = &scene.camera;
    let (corner, w, h) = match q {
        WhittedQuantity::Image => ([0, 0], cam.width(), cam.height()),
        _ => (the_pixel(built)?, 1, 1),
    };
    if q == WhittedQuantity::Coverage {
        let (est, rays) = render::coverage_block(scene, corner, w, h, scheme, rng)?;
        return Ok((measured(&est, rays.total()), rays));
    }
    let out = render::render_block(scene, corner, w, h, scheme, rng).map_err(unresolved)?;
    defined(&out.image.values, corner, w)?;
    Ok((measured(&out.image, out.rays.total()), out.rays))
}

/// The image by a deterministic `scheme`, pixel by pixel on rayon's threads:
/// the same values as one block on one thread (each pixel is its own
/// integral), for the converged reference (the test scene's 48 pixels at
/// 51 200 points each took 11.7 s on one thread, most of the bundled
/// suite's report time). The pixels go costliest first, one at a time to
/// whichever thread is free ([`crate::parallel::costliest_first`]), ranked
/// by the rays a pilot at 1/[`PILOT_SHARE`] of the budget traced: an
/// adaptive rule spends its whole budget on a pixel with an edge and next
/// to nothing on a flat one, and in rayon's order the last costly pixels
/// left a thread idle for 8 to 12% of each doubling of the reference (two
/// threads).
fn image_by_pixels(built: &Built, scheme: &Render) -> Result<Measured, QuadError> {
    use crate::parallel::costliest_first;
    use rayon::prelude::*;
    let cam = &built.scene.camera;
    let width = cam.width();
    let pixel = |k: usize, scheme: &Render| {
        let mut rng = <rand_pcg::Pcg64 as rand::SeedableRng>::seed_from_u64(0);
        render::render_block(&built.scene, [k % width, k / width], 1, 1, scheme, &mut rng)
    };
    let count = width * cam.height();
    let costs: Vec<u64> = match pilot(scheme) {
        Some(pilot) => (0..count)
            .into_par_iter()
            .map(|k| pixel(k, &pilot).map_or(0, |r| r.rays.total()))
            .collect(),
        None => vec![0; count],
    };
    let parts = costliest_first(&costs, |k| pixel(k, scheme))
        .into_iter()
        .collect::<Result<Vec<_>, _>>()
        .map_err(unresolved)?;
    let out = render::Rendered::joined(parts);
    defined(&out.image.values, [0, 0], width)?;
    Ok(measured(&out.image, out.rays.total()))
}

/// The pilot of [`image_by_pixels`] spends 1/`PILOT_SHARE` of a rule's
/// budget on each pixel, and so adds about that to the reference's time
/// (1.6%, against 8 to 12% of two threads' time saved).
const PILOT_SHARE: usize = 64;

/// A rule's scheme at 1/[`PILOT_SHARE`] of its budget (at least the rule's
/// least), or none for the other schemes.
fn pilot(scheme: &Render) -> Option<Render> {
    match scheme {
        Render::Rule { rule, n } => Some(Render::Rule {
            rule: rule.clone(),
            n: (n / PILOT_SHARE).max(rule.min_budget(2)),
        }),
        Render::Pieces { rule, n, lines } => Some(Render::Pieces {
            rule: rule.clone(),
            n: (n / PILOT_SHARE).max(rule.min_budget(2)),
            lines: lines.clone(),
        }),
        _ => None,
    }
}

/// Whitted's own schemes average rays without a rule's check: the first
/// pixel of a block (at `corner`, `width` across) that is not a number is
/// named as a fault of the scene.
fn defined(values: &[Rgb], corner: [usize; 2], width: usize) -> Result<(), QuadError> {
    match values.iter().position(|v| !v.all_finite()) {
        Some(k) => Err(QuadError::invalid(
            "scene",
            format!(
                "pixel [{}, {}] came out not a number",
                corner[0] + k % width.max(1),
                corner[1] + k / width.max(1)
            ),
            RESOLVED_SCENE,
        )),
        None => Ok(()),
    }
}

/// A ray the scene's numbers leave undefined, said as a fault of the scene
/// (it was "integrand returned NaN at unit-cube point …").
fn unresolved(e: QuadError) -> QuadError {
    match e {
        QuadError::NonFiniteIntegrand { point, .. } => QuadError::invalid(
            "scene",
            format!("a value that is not a number from the ray through point {point:?}"),
            RESOLVED_SCENE,
        ),
        other => other,
    }
}

/// The channels of a block's estimates as one measured value.
fn measured<V: Value>(est: &Estimated<V>, rays: u64) -> Measured {
    let flat = |vs: &[V]| -> Vec<f64> {
        vs.iter()
            .flat_map(|v| (0..V::CHANNELS).map(move |c| v.channel(c)))
            .collect()
    };
    let m = Measured {
        value: flat(&est.values),
        error: flat(&est.errors),
        evaluations: rays,
        flags: Vec::new(),
        seconds: None,
        program_seconds: None,
    };
    let m = if est.reliable {
        m
    } else {
        m.flagged(Flag::UnreliableEstimate)
    };
    if est.alike {
        m.flagged(Flag::AllNodesAlike { evaluations: rays })
    } else {
        m
    }
}

impl Family for Whitted {
    const NAME: &'static str = "whitted";
    const ABOUT: &'static str = "Whitted ray tracing: W-6.1 with Phong, shadow, reflection and \
                                 refraction rays; a pixel's value as the integral over its \
                                 square by every 2-D rule and Whitted's grid, corner and \
                                 adaptive schemes";
    const EQUATIONS: &'static [&'static str] = &["W-6.1", "W-Phong", "W-Grey", "W-SS", "W-Corner"];
    const OVER_BUDGET: &'static str = "n is primary rays per pixel, while evaluations count \
        every ray traced for the whole quantity: for `image`, every pixel's (width x height \
        times n primary rays; the corner scheme's lattice adds a row and a column); for each \
        primary ray the shadow rays it spawns (one per light above the surface at each hit \
        with k_d or k_s > 0) and its reflection and refraction rays, recursively to \
        max_depth; and a rule's own error estimate takes more points than n (Gauss–Legendre \
        about 3.5 n)";
    const BUDGET_UNIT: &'static str = "primary rays per pixel (the corner and adaptive schemes \
                                       share rays between pixels; evaluations count every ray \
                                       traced)";

    type SceneSpec = SceneSpec;
    type Scene = Built;
    type Quantity = WhittedQuantity;
    type Estimator = Scheme;

    fn build(spec: &SceneSpec) -> Result<Built, SpecError> {
        build(spec)
    }

    /// The image quantity is the camera's image.
    fn image(built: &Built, q: WhittedQuantity) -> Option<[usize; 2]> {
        let cam = &built.scene.camera;
        (q == WhittedQuantity::Image).then(|| [cam.width(), cam.height()])
    }

    /// W-Grey's 8-bit image of pixels and images (not of coverage, which
    /// is no intensity).
    fn display(q: WhittedQuantity) -> Option<family::Display> {
        (q != WhittedQuantity::Coverage).then_some(family::Display {
            name: "8-bit (W-Grey)",
            half_step: 1.0 / 510.0,
            quantize: super::image::grey,
        })
    }

    /// The pixel square.
    fn dimension(_: &Built, _: WhittedQuantity) -> usize {
        2
    }

    fn channels(built: &Built, q: WhittedQuantity) -> usize {
        let cam = &built.scene.camera;
        match q {
            WhittedQuantity::Coverage => 1,
            WhittedQuantity::Pixel => 3,
            WhittedQuantity::Image => 3 * cam.width() * cam.height(),
        }
    }

    fn lacks(built: &Built, q: WhittedQuantity) -> Option<String> {
        (q != WhittedQuantity::Image && built.pixel.is_none()).then(|| {
            "the coverage and pixel quantities are of one pixel: give scene.pixel = [i, j] \
             (column from the left, row from the top)"
                .to_string()
        })
    }

    fn estimates(_: &Scheme) -> &'static [WhittedQuantity] {
        WhittedQuantity::all_quantities()
    }

    /// An adaptive threshold that is negative or not finite.
    fn check_estimator(scheme: &Scheme) -> Result<(), QuadError> {
        match scheme {
            Scheme::Adaptive { threshold } if !(threshold.is_finite() && *threshold >= 0.0) => {
                Err(QuadError::invalid(
                    "threshold",
                    threshold,
                    "a finite spread >= 0 of a square's corner values",
                ))
            }
            _ => Ok(()),
        }
    }

    fn warnings(built: &Built) -> Vec<SpecError> {
        built.warnings.clone()
    }

    /// Primary rays per pixel times the pixels, times the rays each primary
    /// ray can spawn (shadow rays per light, two secondary rays per level
    /// where mirrors and transparency are both present).
    fn cost(built: &Built, method: &Method<Scheme>, budget: usize, q: WhittedQuantity) -> f64 {
        let cam = &built.scene.camera;
        let (w, h) = match q {
            WhittedQuantity::Image => (cam.width() as f64, cam.height() as f64),
            _ => (1.0, 1.0),
        };
        let primary = match scheme(method, budget) {
            Render::Corner { m } => (w * m as f64 + 1.0) * (h * m as f64 + 1.0),
            Render::Adaptive { max_level, .. } => {
                let s = (1u64 << max_level) as f64;
                (w * s + 1.0) * (h * s + 1.0)
            }
            other => render::rays_per_pixel(&other).unwrap_or(1.0) * w * h,
        };
        if q == WhittedQuantity::Coverage {
            return primary;
        }
        primary * per_primary(&built.scene)
    }

    fn evaluate(
        built: &Built,
        method: &Method<Scheme>,
        budget: usize,
        rng: &mut rand_pcg::Pcg64,
        quantities: &[WhittedQuantity],
    ) -> Result<Outcome<WhittedQuantity>, QuadError> {
        quantities
            .iter()
            .map(|&q| Ok((q, evaluate_counted(built, method, budget, rng, q)?.0)))
            .collect()
    }

    fn closed_form(built: &Built, q: WhittedQuantity) -> Option<Vec<f64>> {
        closed_form(built, q)
    }

    fn closed_forms_available() -> &'static str {
        "coverage when the scene's one object is a triangle or a plane the \
         eye is not on; pixel and image when, besides, the object's intensity is the same \
         everywhere (ambient only: no light reaches its k_d or k_s terms, no mirror or \
         transmitted ray)"
    }

    /// Adaptive Genz–Malik (its whole budget) on each piece of each
    /// pixel cut along the scene's outlines, [`CONVERGED_PER_N`]` n`
    /// evaluations per pixel (`/ 16` for `image`).
    fn converged(
        built: &Built,
        n: usize,
        quantities: &[WhittedQuantity],
    ) -> Result<Outcome<WhittedQuantity>, QuadError> {
        let rule = converged_rule();
        let budget = |q| converged_budget(n, q);
        converged_affordable(built, n, quantities.iter().map(|&q| (q, budget(q))))?;
        let mut rng = <rand_pcg::Pcg64 as rand::SeedableRng>::seed_from_u64(0);
        quantities
            .iter()
            .map(|&q| {
                let budget = budget(q);
                let scheme = Render::Pieces {
                    rule: rule.clone(),
                    n: budget,
                    lines: pieces::outlines(&built.scene),
                };
                if q == WhittedQuantity::Image {
                    return Ok((q, image_by_pixels(built, &scheme)?));
                }
                Ok((q, by_scheme(built, &scheme, &mut rng, q)?.0))
            })
            .collect()
    }

    /// [`Self::converged`]'s Genz–Malik over each pixel's pieces at
    /// the converged budget, priced by [`Whitted::cost`] (the ray tree
    /// counted).
    fn converged_cost(built: &Built, n: usize, quantities: &[WhittedQuantity]) -> [f64; 2] {
        let rule = Method::Rule(converged_rule());
        let evaluations = quantities
            .iter()
            .map(|&q| Whitted::cost(built, &rule, converged_budget(n, q), q))
            .sum();
        let bytes = quantities
            .iter()
            .map(|&q| Whitted::memory(built, &rule, converged_budget(n, q), q))
            .fold(0.0, f64::max);
        [evaluations, bytes]
    }

    fn settings(spec: &SceneSpec) -> String {
        settings(spec)
    }

    fn scene_audit(built: &Built) -> Option<String> {
        Some(terms_section(built))
    }
}

/// The converged evaluation's rule: Genz–Malik spending its whole budget
/// (no tolerance stops it).
fn converged_rule() -> AnyRule {
    AnyRule::Base(BaseRule::GenzMalik(GenzMalik {
        abs_tol: 0.0,
        rel_tol: 0.0,
    }))
}

/// The converged evaluation's budget for `q` at `n`: [`CONVERGED_PER_N`]
/// `n` a pixel, a sixteenth of it for each pixel of an image (at least
/// Genz–Malik's one region).
fn converged_budget(n: usize, q: WhittedQuantity) -> usize {
    let per_pixel = CONVERGED_PER_N.saturating_mul(n);
    if q == WhittedQuantity::Image {
        (per_pixel / 16).max(converged_rule().min_budget(2))
    } else {
        per_pixel
    }
}

/// Refuses a converged evaluation at `n` whose ray tree makes it cost more
/// than [`MAX_JOB_EVALUATIONS`](crate::experiment::validate::MAX_JOB_EVALUATIONS)
/// ray-object tests (unless `--no-cost-limit`): Genz–Malik's `budget`
/// points per pixel of each quantity (`(q, budget)`), each a primary ray
/// with up to `sum_(d <= max_depth) b^d` rays below it ([`per_primary`]; `b
/// = 2` with mirrors and glass). Four glass spheres at depth 16 ran for
/// more than 300 s before any report; each doubling of `n` doubles it.
fn converged_affordable(
    built: &Built,
    n: usize,
    budgets: impl Iterator<Item = (WhittedQuantity, usize)>,
) -> Result<(), QuadError> {
    use crate::experiment::validate::{MAX_JOB_EVALUATIONS, cost_limit_lifted};
    let rule = Method::Rule(converged_rule());
    let cost: f64 = budgets
        .map(|(q, budget)| Whitted::cost(built, &rule, budget, q))
        .sum();
    if cost_limit_lifted() || cost <= MAX_JOB_EVALUATIONS {
        return Ok(());
    }
    let scene = &built.scene;
    Err(QuadError::invalid(
        "reference.n",
        n,
        format!(
            "a converged evaluation of at most {MAX_JOB_EVALUATIONS:.0e} ray-object tests; at \
             n = {n} it costs about {cost:.1e}, the scene's ray tree counted (scene.max_depth \
             {}: up to {:.0} rays below each primary ray, {} light(s), {} object(s)): lower \
             scene.max_depth or reference.n, or pass --no-cost-limit",
            scene.max_depth,
            tree_rays(scene),
            scene.lights.len(),
            scene.objects.len()
        ),
    ))
}

impl WhittedQuantity {
    /// Every quantity (for the estimators, which estimate them all).
    fn all_quantities() -> &'static [WhittedQuantity] {
        <WhittedQuantity as family::Quantity>::all()
    }
}

/// About how much work one primary ray costs in `scene`, in ray-object
/// tests: itself, a shadow ray per light per hit, and up to two secondary
/// rays per level, each tested against every object.
fn per_primary(scene: &Scene) -> f64 {
    let lights = scene.lights.len() as f64;
    // Every ray tests every object (50 000 spheres made a ray 0.3 ms).
    let objects = scene.objects.len().max(1) as f64;
    tree_rays(scene) * (1.0 + lights) * objects
}

/// The most rays of one primary ray's tree, itself included: `sum_(d = 0)^
/// max_depth b^d`, `b` the secondary rays a hit spawns (one for mirrors,
/// one for glass, two with both; 131071 at depth 16 with both).
fn tree_rays(scene: &Scene) -> f64 {
    let branches = f64::from(u8::from(scene.has_mirrors()) + u8::from(scene.has_transparency()));
    (0..=scene.max_depth).map(|d| branches.powi(d as i32)).sum()
}

/// The ray kinds the scene traces, in words.
fn kinds(scene: &Scene) -> String {
    let mut kinds = vec!["primary rays".to_string()];
    let lit = !scene.lights.is_empty()
        && scene
            .objects
            .iter()
            .any(|o| o.material.k_d > 0.0 || o.material.k_s > 0.0);
    kinds.push(if lit {
        format!("shadow rays ({} light(s))", scene.lights.len())
    } else {
        "no shadow rays (no light, or no object with k_d or k_s)".into()
    });
    let deep = scene.max_depth > 0;
    kinds.push(if deep && scene.has_mirrors() {
        "reflection rays (k_s > 0)".into()
    } else {
        "no reflection rays (no k_s, or max_depth 0)".into()
    });
    kinds.push(if deep && scene.has_transparency() {
        "refraction rays (k_t > 0)".into()
    } else {
        "no refraction rays (nothing transparent, or max_depth 0)".into()
    });
    kinds.join(", ")
}

fn settings(spec: &SceneSpec) -> String {
    match build(spec) {
        Ok(built) => format!(
            "{} x {} image, {} object(s), {} light(s), max_depth {}; traced: {}",
            spec.camera.width,
            spec.camera.height,
            spec.objects.len(),
            spec.lights.len(),
            spec.max_depth,
            kinds(&built.scene)
        ),
        Err(e) => format!("scene not built: {e}"),
    }
}

/// The report's section on this scene.
fn terms_section(built: &Built) -> String {
    let scene = &built.scene;
    let mut s = String::from("## Terms and rays of this scene\n\n");
    let _ = writeln!(s, "Traced: {}.\n", kinds(scene));
    s.push_str("| object | shape | k_a | k_d | k_s | k_t | n | ior | W-6.1 terms |\n");
    s.push_str("|---|---|---|---|---|---|---|---|---|\n");
    for (k, o) in scene.objects.iter().enumerate() {
        let m = &o.material;
        let shape = match o.shape {
            Shape::Sphere { .. } => "sphere",
            Shape::Plane { .. } => "plane",
            Shape::Triangle { .. } => "triangle",
        };
        let mut terms = Vec::new();
        if m.k_a > 0.0 {
            terms.push("I_a k_a");
        }
        if m.k_d > 0.0 && !scene.lights.is_empty() {
            terms.push("I_q k_d (N . L_q)");
        }
        if m.k_s > 0.0 && !scene.lights.is_empty() {
            terms.push("k_s I_q (R_q . A)^n");
        }
        if m.k_s > 0.0 && scene.max_depth > 0 {
            terms.push("k_s I_r");
        }
        if m.k_t > 0.0 && scene.max_depth > 0 {
            terms.push("k_t I_t");
        }
        let _ = writeln!(
            s,
            "| {k} | {shape} | {} | {} | {} | {} | {} | {} | {} |",
            m.k_a,
            m.k_d,
            m.k_s,
            m.k_t,
            m.phong,
            m.ior,
            if terms.is_empty() {
                "none (black)".to_string()
            } else {
                terms.join(" + ")
            }
        );
    }
    for w in &built.warnings {
        let _ = writeln!(s, "\n**Warning** at `{}`: {}", w.path, w.message);
    }
    s
}
