//! Whitted ray tracing (W-* in docs/EQUATIONS.md) as the experiment layer
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
//! in front of the eye (its projection, clipped to the pixel:
//! [`super::coverage::polygon_fraction`]) or a plane the eye is not on
//! (the film points whose rays meet it form a half-plane of the film:
//! [`super::coverage::half_plane_fraction`]); `pixel` and `image` when, in
//! addition, the object's intensity is the same everywhere (no light
//! reaches its diffuse or specular terms, no mirror or transmitted ray):
//! `background + (I_a k_a C - background) coverage`.
//!
//! **Converged reference** ([`Whitted::converged`]): adaptive Genz–Malik
//! (relative tolerance 1e-12) on each pixel with [`CONVERGED_PER_N`]` n`
//! evaluations (`n / 16` of that per pixel for `image`); an edge inside
//! the pixel makes it converge algebraically, so the layer's check against
//! `2n` states the accuracy reached.
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

use std::fmt::Write as _;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::coverage::{HalfPlane, half_plane_fraction, polygon_fraction};
use super::intersect::Shape;
use super::render::{self, Estimated, Scheme as Render};
use super::scene::{Camera, Light, Material, Object, Scene};
use super::shade::RayCount;
use crate::domain::{Pixel, Vec3};
use crate::error::{QuadError, SpecError};
use crate::experiment::tagged;
use crate::family::{self, Family, Flag, Measured, Method, Outcome};
use crate::quadrature::{AnyRule, BaseRule, GenzMalik, Rule};
use crate::value::{Rgb, Value};

/// The Whitted family.
#[derive(Debug, Clone, Copy)]
pub struct Whitted;

/// Coordinates, sizes and intensities beyond this are refused: squared
/// distances of larger ones overflow f64.
pub const MAX_COORDINATE: f64 = 1e100;

/// The scene as written in an experiment file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SceneSpec {
    /// The pinhole camera and the image size.
    pub camera: CameraSpec,
    /// `I_a`, R, G, B (each `>= 0`).
    #[serde(deserialize_with = "tagged::array")]
    pub ambient: [f64; 3],
    /// The intensity of rays that meet nothing (default black).
    #[serde(default, deserialize_with = "tagged::array")]
    pub background: [f64; 3],
    /// The lights (default none: no shadow rays).
    #[serde(default)]
    pub lights: Vec<LightSpec>,
    /// The objects.
    pub objects: Vec<ObjectSpec>,
    /// The deepest recursion of reflected and transmitted rays, `0..=16`
    /// (default 5; the primary ray is depth 0).
    #[serde(default = "default_depth")]
    pub max_depth: usize,
    /// `[i, j]`: the pixel of the `coverage` and `pixel` quantities (column
    /// from the left, row from the top).
    #[serde(default, deserialize_with = "some_pixel")]
    pub pixel: Option<[usize; 2]>,
}

fn default_depth() -> usize {
    5
}

fn some_pixel<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<[usize; 2]>, D::Error> {
    tagged::array(d).map(Some)
}

/// A pinhole camera.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CameraSpec {
    /// The eye.
    #[serde(deserialize_with = "tagged::array")]
    pub eye: [f64; 3],
    /// A point the camera looks at (not the eye).
    #[serde(deserialize_with = "tagged::array")]
    pub look_at: [f64; 3],
    /// The image's up direction (not along the viewing direction).
    #[serde(deserialize_with = "tagged::array")]
    pub up: [f64; 3],
    /// The vertical field of view in degrees, in `[1e-4, 180)`.
    pub fov_y: f64,
    /// Pixels across, `1..=16384`.
    #[schemars(range(min = 1, max = 16384))]
    pub width: usize,
    /// Pixels down, `1..=16384`.
    #[schemars(range(min = 1, max = 16384))]
    pub height: usize,
}

/// A light: `{"type": "point" | "directional", ...}`.
#[derive(Debug, Clone, PartialEq, Serialize, JsonSchema)]
#[serde(tag = "type", rename_all = "kebab-case")]
pub enum LightSpec {
    /// A point light.
    Point(PointLightSpec),
    /// A light at infinity.
    Directional(DirectionalLightSpec),
}

impl<'de> Deserialize<'de> for LightSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let (tag, fields) = tagged::split_tag(
            serde_json::Value::deserialize(d)?,
            "type",
            &["point", "directional"],
        )?;
        match tag.as_str() {
            "point" => tagged::variant(fields).map(LightSpec::Point),
            _ => tagged::variant(fields).map(LightSpec::Directional),
        }
    }
}

/// A point light of W-6.1 (no fall-off with distance).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PointLightSpec {
    /// Where it is.
    #[serde(deserialize_with = "tagged::array")]
    pub position: [f64; 3],
    /// `I_q`, R, G, B.
    #[serde(deserialize_with = "tagged::array")]
    pub intensity: [f64; 3],
}

/// A directional light.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DirectionalLightSpec {
    /// The direction from the scene toward the light.
    #[serde(deserialize_with = "tagged::array")]
    pub toward_light: [f64; 3],
    /// `I_q`, R, G, B.
    #[serde(deserialize_with = "tagged::array")]
    pub intensity: [f64; 3],
}

/// An object: `{"type": "sphere" | "plane" | "triangle", ..., "material": {..}}`.
#[derive(Debug, Clone, PartialEq, Serialize, JsonSchema)]
#[serde(tag = "type", rename_all = "kebab-case")]
pub enum ObjectSpec {
    /// A sphere.
    Sphere(SphereSpec),
    /// A plane.
    Plane(PlaneSpec),
    /// A triangle.
    Triangle(TriangleSpec),
}

impl<'de> Deserialize<'de> for ObjectSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let (tag, fields) = tagged::split_tag(
            serde_json::Value::deserialize(d)?,
            "type",
            &["sphere", "plane", "triangle"],
        )?;
        match tag.as_str() {
            "sphere" => tagged::variant(fields).map(ObjectSpec::Sphere),
            "plane" => tagged::variant(fields).map(ObjectSpec::Plane),
            _ => tagged::variant(fields).map(ObjectSpec::Triangle),
        }
    }
}

/// A sphere.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SphereSpec {
    /// The centre.
    #[serde(deserialize_with = "tagged::array")]
    pub centre: [f64; 3],
    /// The radius (`> 0`).
    pub radius: f64,
    /// Its material.
    pub material: MaterialSpec,
}

/// A plane.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PlaneSpec {
    /// A point of it.
    #[serde(deserialize_with = "tagged::array")]
    pub point: [f64; 3],
    /// Its normal (the outside; the back is the inside for refraction).
    #[serde(deserialize_with = "tagged::array")]
    pub normal: [f64; 3],
    /// Its material.
    pub material: MaterialSpec,
}

/// A triangle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TriangleSpec {
    /// First vertex.
    #[serde(deserialize_with = "tagged::array")]
    pub a: [f64; 3],
    /// Second vertex.
    #[serde(deserialize_with = "tagged::array")]
    pub b: [f64; 3],
    /// Third vertex (off the line through the first two).
    #[serde(deserialize_with = "tagged::array")]
    pub c: [f64; 3],
    /// Its material.
    pub material: MaterialSpec,
}

/// W-6.1's coefficients; each left out is 0 (`phong` 1, `ior` 1, `colour`
/// white).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// `k_a` in `[0, 1]`.
    #[serde(default)]
    pub k_a: f64,
    /// `k_d` in `[0, 1]`.
    #[serde(default)]
    pub k_d: f64,
    /// `k_s` in `[0, 1]`.
    #[serde(default)]
    pub k_s: f64,
    /// `k_t` in `[0, 1]`.
    #[serde(default)]
    pub k_t: f64,
    /// The Phong exponent `n` in `[0, 1e8]`. `n = 0` is legal, a constant
    /// lobe: `(R . V)^0 = 1`, so the highlight is `k_s I_j` for every light
    /// `j` above the surface's horizon and unshadowed, wherever the viewer is.
    #[serde(default = "one")]
    pub phong: f64,
    /// The index of refraction inside, in `[0.001, 1000]`.
    #[serde(default = "one")]
    pub ior: f64,
    /// The colour of the ambient and diffuse terms, each in `[0, 1]`.
    #[serde(default = "white", deserialize_with = "tagged::array")]
    pub colour: [f64; 3],
}

fn one() -> f64 {
    1.0
}

fn white() -> [f64; 3] {
    [1.0; 3]
}

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
    let scheme = scheme(method, budget);
    let scene = &built.scene;
    let cam = &scene.camera;
    let (corner, w, h) = match q {
        WhittedQuantity::Image => ([0, 0], cam.width(), cam.height()),
        _ => (the_pixel(built)?, 1, 1),
    };
    if q == WhittedQuantity::Coverage {
        let (est, rays) = render::coverage_block(scene, corner, w, h, &scheme, rng)?;
        return Ok((measured(&est, rays.total()), rays));
    }
    let out = render::render_block(scene, corner, w, h, &scheme, rng).map_err(unresolved)?;
    defined(&out.image.values, corner, w)?;
    Ok((measured(&out.image, out.rays.total()), out.rays))
}

/// The image by a deterministic `scheme`, pixel by pixel on rayon's threads:
/// the same values as one block on one thread (each pixel is its own
/// integral), for the converged reference (the test scene's 48 pixels at
/// 51 200 points each took 11.7 s on one thread, most of the bundled
/// suite's report time).
fn image_by_pixels(built: &Built, scheme: &Render) -> Result<Measured, QuadError> {
    use rayon::prelude::*;
    let cam = &built.scene.camera;
    let width = cam.width();
    let parts = (0..width * cam.height())
        .into_par_iter()
        .map(|k| {
            let mut rng = <rand_pcg::Pcg64 as rand::SeedableRng>::seed_from_u64(0);
            render::render_block(&built.scene, [k % width, k / width], 1, 1, scheme, &mut rng)
        })
        .collect::<Result<Vec<_>, _>>()
        .map_err(unresolved)?;
    let out = render::Rendered::joined(parts);
    defined(&out.image.values, [0, 0], width)?;
    Ok(measured(&out.image, out.rays.total()))
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

/// The least size of an object beside its distance from the eye that f64
/// resolves along the rays meeting it: their rounding is about 1e-16 of
/// their length, so below 1e-12 a hit point is uncertain by more than
/// 1e-4 of the object.
pub const SMALLEST_RESOLVED: f64 = 1e-12;

/// The least size of an object whose squared sizes stay normal f64
/// numbers (1e-150 squared is 1e-300).
pub const SMALLEST_SIZE: f64 = 1e-150;

/// What a scene must be for its rays to be defined: said when a pixel comes
/// out not a number (`render`) or a pixel's integrand does (a job).
pub const RESOLVED_SCENE: &str = "a scene whose coordinates and sizes f64 resolves along its \
     rays: extents and distances within about 1e12 of each other (an object of size 1e30 \
     around the camera, a sphere of radius 1e-20 seen from 1e19 or an eye 1e16 from the scene \
     are not)";

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
    };
    if est.reliable {
        m
    } else {
        m.flagged(Flag::UnreliableEstimate)
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
        "coverage when the scene's one object is a triangle in front of the eye or a plane the \
         eye is not on; pixel and image when, besides, the object's intensity is the same \
         everywhere (ambient only: no light reaches its k_d or k_s terms, no mirror or \
         transmitted ray)"
    }

    /// Adaptive Genz–Malik (relative tolerance 1e-12) per pixel with
    /// [`CONVERGED_PER_N`]` n` evaluations (`/ 16` for `image`).
    fn converged(
        built: &Built,
        n: usize,
        quantities: &[WhittedQuantity],
    ) -> Result<Outcome<WhittedQuantity>, QuadError> {
        let rule = AnyRule::Base(BaseRule::GenzMalik(GenzMalik {
            abs_tol: 0.0,
            rel_tol: 1e-12,
        }));
        let per_pixel = CONVERGED_PER_N.saturating_mul(n);
        let mut rng = <rand_pcg::Pcg64 as rand::SeedableRng>::seed_from_u64(0);
        quantities
            .iter()
            .map(|&q| {
                let budget = if q == WhittedQuantity::Image {
                    (per_pixel / 16).max(rule.min_budget(2))
                } else {
                    per_pixel
                };
                let method = Method::Rule(rule.clone());
                if q == WhittedQuantity::Image {
                    return Ok((q, image_by_pixels(built, &scheme(&method, budget))?));
                }
                Ok((q, evaluate_counted(built, &method, budget, &mut rng, q)?.0))
            })
            .collect()
    }

    fn settings(spec: &SceneSpec) -> String {
        settings(spec)
    }

    fn scene_audit(built: &Built) -> Option<String> {
        Some(terms_section(built))
    }
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
    let branches = f64::from(u8::from(scene.has_mirrors()) + u8::from(scene.has_transparency()));
    let hits: f64 = (0..=scene.max_depth).map(|d| branches.powi(d as i32)).sum();
    // Every ray tests every object (50 000 spheres made a ray 0.3 ms).
    let objects = scene.objects.len().max(1) as f64;
    hits * (1.0 + lights) * objects
}

/// The film region whose primary rays meet a shape, when it is a convex
/// polygon or a half-plane of the film.
enum Footprint {
    Polygon(Vec<[f64; 2]>),
    HalfPlane(HalfPlane),
}

fn footprint(cam: &Camera, shape: &Shape) -> Option<Footprint> {
    match *shape {
        Shape::Triangle { vertices, .. } => {
            let mut poly = Vec::with_capacity(3);
            for v in vertices {
                poly.push(cam.project(v)?);
            }
            Some(Footprint::Polygon(poly))
        }
        Shape::Plane { point, normal } => {
            // d(x, y) . n is affine in the film point; the ray meets the
            // plane where its sign is opposite to the eye's side.
            let side = (cam.eye() - point).dot(&normal);
            if side == 0.0 {
                return None;
            }
            let at = |p: [f64; 2]| cam.direction(p).dot(&normal);
            let (o, x, y) = (at([0.0, 0.0]), at([1.0, 0.0]), at([0.0, 1.0]));
            let (a, b, c) = (x - o, y - o, -o);
            // Hit where s (a x + b y - c) < 0 with s the eye's side.
            Some(Footprint::HalfPlane(if side > 0.0 {
                HalfPlane { a, b, c }
            } else {
                HalfPlane {
                    a: -a,
                    b: -b,
                    c: -c,
                }
            }))
        }
        Shape::Sphere { .. } => None,
    }
}

/// The closed form of `q` (module documentation).
fn closed_form(built: &Built, q: WhittedQuantity) -> Option<Vec<f64>> {
    let scene = &built.scene;
    let [object] = scene.objects.as_slice() else {
        return None;
    };
    let cam = &scene.camera;
    let print = footprint(cam, &object.shape)?;
    let fraction = |i: usize, j: usize| -> Option<f64> {
        let p = Pixel::new(i as f64, j as f64, 1.0, 1.0).ok()?;
        Some(match &print {
            Footprint::Polygon(poly) => polygon_fraction(&p, poly),
            Footprint::HalfPlane(h) => half_plane_fraction(&p, *h),
        })
    };
    if q == WhittedQuantity::Coverage {
        let [i, j] = built.pixel?;
        return Some(vec![fraction(i, j)?]);
    }
    let flat = flat_intensity(scene, object)?;
    let pixel = |i, j| -> Option<[f64; 3]> {
        let f = fraction(i, j)?;
        let v = scene.background + (flat - scene.background) * f;
        Some([v.x, v.y, v.z])
    };
    match q {
        WhittedQuantity::Pixel => {
            let [i, j] = built.pixel?;
            Some(pixel(i, j)?.to_vec())
        }
        _ => {
            let mut out = Vec::with_capacity(3 * cam.width() * cam.height());
            for j in 0..cam.height() {
                for i in 0..cam.width() {
                    out.extend(pixel(i, j)?);
                }
            }
            Some(out)
        }
    }
}

/// The intensity of `object` where it is seen, when it is the same at every
/// point: `I_a k_a C` with no light term (no lights, or `k_d = k_s = 0`) and
/// no mirror or transmitted ray (`k_s = k_t = 0`, or `max_depth = 0`).
fn flat_intensity(scene: &Scene, object: &Object) -> Option<Rgb> {
    let m = &object.material;
    let lit = !scene.lights.is_empty() && (m.k_d > 0.0 || m.k_s > 0.0);
    let recursive = scene.max_depth > 0 && (m.k_s > 0.0 || m.k_t > 0.0);
    (!lit && !recursive).then(|| scene.ambient.component_mul(&m.colour) * m.k_a)
}

fn vec3(v: [f64; 3]) -> Vec3 {
    Vec3::new(v[0], v[1], v[2])
}

fn rgb(v: [f64; 3]) -> Rgb {
    Rgb::new(v[0], v[1], v[2])
}

/// Refuses a number beyond [`MAX_COORDINATE`] among `values`, the array
/// (or the one number) at `path`, at its own path (`scene.camera.eye[0]`).
fn bounded(path: &str, values: &[f64]) -> Result<(), SpecError> {
    match values
        .iter()
        .enumerate()
        .find(|(_, v)| v.is_nan() || v.abs() > MAX_COORDINATE)
    {
        None => Ok(()),
        Some((i, v)) => Err(SpecError::at(
            if values.len() > 1 {
                format!("{path}[{i}]")
            } else {
                path.to_string()
            },
            format!(
                "{v:e} is beyond {MAX_COORDINATE:e}: expected coordinates, sizes and \
                 intensities up to {MAX_COORDINATE:e} (squared distances of larger ones \
                 overflow f64)"
            ),
        )),
    }
}

fn material(spec: &MaterialSpec) -> Material {
    Material {
        k_a: spec.k_a,
        k_d: spec.k_d,
        k_s: spec.k_s,
        k_t: spec.k_t,
        phong: spec.phong,
        ior: spec.ior,
        colour: rgb(spec.colour),
    }
}

fn object(spec: &ObjectSpec, at: &str) -> Result<Object, SpecError> {
    let (shape, m, fields): (_, _, Vec<(&str, &[f64])>) = match spec {
        ObjectSpec::Sphere(s) => (
            Shape::sphere(vec3(s.centre), s.radius),
            &s.material,
            vec![
                ("centre", &s.centre[..]),
                ("radius", std::slice::from_ref(&s.radius)),
            ],
        ),
        ObjectSpec::Plane(p) => (
            Shape::plane(vec3(p.point), vec3(p.normal)),
            &p.material,
            vec![("point", &p.point[..]), ("normal", &p.normal[..])],
        ),
        ObjectSpec::Triangle(t) => (
            Shape::triangle(vec3(t.a), vec3(t.b), vec3(t.c)),
            &t.material,
            vec![("a", &t.a[..]), ("b", &t.b[..]), ("c", &t.c[..])],
        ),
    };
    for (field, values) in fields {
        bounded(&format!("{at}.{field}"), values)?;
    }
    let shape = shape.map_err(|e| SpecError::from_quad(at, e))?;
    let material = material(m);
    material
        .check()
        .map_err(|e| SpecError::from_quad(&format!("{at}.material"), e))?;
    Ok(Object { shape, material })
}

/// Checks every number of the scene and builds it; errors name the JSON
/// path from the file's root.
fn build(spec: &SceneSpec) -> Result<Built, SpecError> {
    let c = &spec.camera;
    bounded("scene.camera.eye", &c.eye)?;
    bounded("scene.camera.look_at", &c.look_at)?;
    bounded("scene.camera.up", &c.up)?;
    let forward = vec3(c.look_at) - vec3(c.eye);
    if forward == Vec3::zeros() {
        return Err(SpecError::at(
            "scene.camera.look_at",
            format!(
                "{:?} is the eye: expected a point the camera looks at, away from the eye",
                c.look_at
            ),
        ));
    }
    let camera = Camera::new(vec3(c.eye), forward, vec3(c.up), c.fov_y, c.width, c.height)
        .map_err(|e| SpecError::from_quad("scene.camera", e))?;
    bounded("scene.ambient", &spec.ambient)?;
    bounded("scene.background", &spec.background)?;
    let mut lights = Vec::with_capacity(spec.lights.len());
    for (k, l) in spec.lights.iter().enumerate() {
        let at = format!("scene.lights[{k}]");
        let light = match l {
            LightSpec::Point(p) => {
                bounded(&format!("{at}.position"), &p.position)?;
                bounded(&format!("{at}.intensity"), &p.intensity)?;
                Light::point(vec3(p.position), rgb(p.intensity))
            }
            LightSpec::Directional(d) => {
                bounded(&format!("{at}.toward_light"), &d.toward_light)?;
                bounded(&format!("{at}.intensity"), &d.intensity)?;
                Light::directional(vec3(d.toward_light), rgb(d.intensity))
            }
        };
        lights.push(light.map_err(|e| SpecError::from_quad(&at, e))?);
    }
    let mut objects = Vec::with_capacity(spec.objects.len());
    let mut warnings = Vec::new();
    for (k, o) in spec.objects.iter().enumerate() {
        let at = format!("scene.objects[{k}]");
        let object = object(o, &at)?;
        if let Some(w) = object.material.energy_warning() {
            warnings.push(SpecError::at(format!("{at}.material"), w));
        }
        // An object whose squared size underflows f64 has no area to hit.
        if let Some(size) = object.shape.size()
            && size < SMALLEST_SIZE
        {
            warnings.push(SpecError::at(
                at.clone(),
                format!(
                    "its size is {size:.1e}, below {SMALLEST_SIZE:.0e}: its squared sizes and \
                     distances underflow f64, so its hits are undefined or missed (a failed \
                     job); expected the scene in units that make its sizes nearer 1"
                ),
            ));
        }
        // An object smaller than the rounding of the rays that reach it
        // (about 1e-16 of their length) is met, or missed, by rounding.
        if let Some(ratio) = object.shape.size_over_distance(camera.eye())
            && (0.0..SMALLEST_RESOLVED).contains(&ratio)
        {
            warnings.push(SpecError::at(
                at.clone(),
                format!(
                    "its size is {ratio:.1e} of its distance from the eye, below the {:.0e} that \
                     f64 resolves along a ray: whether a ray meets it, and where, is rounding, \
                     and a ray that meets it can come out undefined (a failed job)",
                    SMALLEST_RESOLVED
                ),
            ));
        }
        // Hit points are rounded to about 1e-16 of their coordinates: an
        // object small beside the coordinates it sits at (or the eye's) is
        // drawn at a rounded size (an eye 5 from a unit sphere, both at x =
        // 1e16, where f64's spacing is 2, rendered 0.4352 for 0.4376).
        let magnitude = object.shape.extent().max(camera.eye().amax());
        if let Some(size) = object.shape.size()
            && size < SMALLEST_RESOLVED * magnitude
        {
            warnings.push(SpecError::at(
                at.clone(),
                format!(
                    "its size is {:.1e} of the coordinates it and the eye sit at ({magnitude:.1e}), \
                     below the {SMALLEST_RESOLVED:.0e} that f64 resolves: its hit points are \
                     rounded by a sizeable part of it; expected the scene moved nearer the \
                     origin",
                    size / magnitude
                ),
            ));
        }
        // An object far larger than the camera's distance to what it
        // looks at (a sphere of radius 1e100 around the eye) puts hit
        // points where the rest of the scene is rounding, and their shadow
        // and reflected rays come out undefined.
        let focus = forward.norm();
        if let Some(size) = object.shape.size()
            && size > focus / SMALLEST_RESOLVED
        {
            warnings.push(SpecError::at(
                at.clone(),
                format!(
                    "its size is {size:.1e}, {:.1e} times the eye's distance from look_at \
                     ({focus:.1e}), above the {:.0e} that f64 resolves along a ray: the scene \
                     around the eye is rounding beside its hit points, and rays from them can \
                     come out undefined (a failed job); expected {RESOLVED_SCENE}",
                    size / focus,
                    1.0 / SMALLEST_RESOLVED
                ),
            ));
        }
        objects.push(object);
    }
    let scene = Scene::new(
        objects,
        lights,
        rgb(spec.ambient),
        rgb(spec.background),
        camera,
        spec.max_depth,
    )
    .map_err(|e| SpecError::from_quad("scene", e))?;
    if let Some([i, j]) = spec.pixel
        && (i >= c.width || j >= c.height)
    {
        return Err(SpecError::at(
            "scene.pixel",
            format!(
                "[{i}, {j}] is outside the {} x {} image: expected [i, j] with i < {} and j < {}",
                c.width, c.height, c.width, c.height
            ),
        ));
    }
    Ok(Built {
        scene,
        pixel: spec.pixel,
        warnings,
    })
}

/// Renders the scene of a `whitted` experiment file's JSON (`json["scene"]`)
/// at `width x height` (default: the file's) with W-SS's `m x m` grid, `m =
/// floor(sqrt(samples))`: the image and the rays by kind. Faults name their
/// JSON path.
pub fn render_spec(
    json: &serde_json::Value,
    width: Option<usize>,
    height: Option<usize>,
    samples: usize,
) -> Result<(super::image::Image, RayCount, Vec<SpecError>), SpecError> {
    if json.get("family").and_then(|f| f.as_str()) != Some(Whitted::NAME) {
        return Err(SpecError::at(
            "family",
            "expected a `whitted` experiment file (\"family\": \"whitted\")",
        ));
    }
    let built = scene_of(json, width, height)?;
    let (spec_width, spec_height) = (built.scene.camera.width(), built.scene.camera.height());
    if samples == 0 {
        return Err(SpecError::at(
            "samples",
            "0 rays a pixel: expected at least 1 (rounded down to a square: 1, 4, 9, ...)",
        ));
    }
    let side = ((samples as f64).sqrt().floor() as usize).max(1);
    // Refuse what would run for hours: the primary rays, each of which may
    // spawn up to `max_depth` generations more.
    let primary = (spec_width as f64) * (spec_height as f64) * (side as f64).powi(2);
    if primary > MAX_RENDER_RAYS {
        return Err(SpecError::at(
            "samples",
            format!(
                "{spec_width} x {spec_height} pixels at {side} x {side} rays a pixel are {primary:.3e} primary rays: expected at most {MAX_RENDER_RAYS:e} (fewer --samples or a smaller --width, --height)"
            ),
        ));
    }
    // And the whole ray tree: each primary ray's shadow rays and secondary
    // generations, each tested against every object, as `run` counts it (12
    // glass spheres at depth 16 passed the primary-ray count, about 5e10
    // rays, hours).
    let work = primary * per_primary(&built.scene);
    if work > crate::experiment::validate::MAX_JOB_EVALUATIONS {
        return Err(SpecError::at(
            "samples",
            format!(
                "{spec_width} x {spec_height} pixels at {side} x {side} rays a pixel, with the rays \
                 each primary ray can spawn in this scene (depth {}, lights: {}, objects: {}), are \
                 about {work:.1e} ray-object tests: expected at most {:.0e} (fewer --samples, a \
                 smaller --width, --height, or a lower max_depth in the file)",
                built.scene.max_depth,
                built.scene.lights.len(),
                built.scene.objects.len(),
                crate::experiment::validate::MAX_JOB_EVALUATIONS
            ),
        ));
    }
    // And what would not fit: the values, their errors, the image and its
    // files hold about RENDER_BYTES_PER_PIXEL a pixel (8192 x 8192 peaked at
    // 3.2 GB; 16384 x 16384 ran out of memory).
    let bytes = (spec_width as f64) * (spec_height as f64) * RENDER_BYTES_PER_PIXEL;
    let limit = crate::experiment::validate::MAX_JOB_BYTES;
    if bytes > limit {
        return Err(SpecError::at(
            "width",
            format!(
                "{spec_width} x {spec_height} pixels hold about {:.1} GB while rendering: expected at most {:.1} GB (a smaller --width, --height)",
                bytes / 1e9,
                limit / 1e9
            ),
        ));
    }
    let out = render::render_parallel(&built.scene, &Render::Grid { n: side }, 0)
        .map_err(|e| SpecError::from_quad("scene", e))?;
    // A pixel that is not a number is a fault of the scene's numbers, never
    // a silent black pixel in the PNG.
    let undefined = out.image.values.iter().filter(|v| !v.all_finite()).count();
    if undefined > 0 {
        return Err(SpecError::at(
            "scene",
            format!(
                "{undefined} of {} pixels came out undefined (NaN or infinite): the scene's coordinates or sizes are beyond what f64 resolves along these rays; expected {RESOLVED_SCENE}",
                out.image.values.len()
            ),
        ));
    }
    let image = super::image::Image::new(spec_width, spec_height, out.image.values)
        .map_err(|e| SpecError::from_quad("scene.camera", e))?;
    Ok((image, out.rays, built.warnings))
}

/// The memory a render holds per pixel, in bytes (values and errors, the
/// image, the PNG and PFM bytes; measured: 8192 x 8192 peaked at 3.2 GB,
/// about 48 a pixel).
pub const RENDER_BYTES_PER_PIXEL: f64 = 64.0;

/// The scene of a `whitted` experiment file's `scene` (its camera at
/// `width x height` where given), built and checked as `check` does; the
/// file's `pixel` is ignored.
pub fn scene_of(
    json: &serde_json::Value,
    width: Option<usize>,
    height: Option<usize>,
) -> Result<Built, SpecError> {
    let scene = json
        .get("scene")
        .cloned()
        .ok_or_else(|| SpecError::at("scene", "the required field `scene` is missing"))?;
    let mut spec: SceneSpec = serde_path_to_error::deserialize(scene).map_err(|e| {
        let (path, message) = tagged::located(&e.path().to_string(), &e.inner().to_string());
        SpecError::at(format!("scene.{path}"), message)
    })?;
    spec.camera.width = width.unwrap_or(spec.camera.width);
    spec.camera.height = height.unwrap_or(spec.camera.height);
    spec.pixel = None;
    build(&spec)
}

/// The most primary rays `lightquad render` traces (about a minute on one
/// core at the bundled test scene's cost per ray).
pub const MAX_RENDER_RAYS: f64 = 1e9;

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
