//! The scene as an experiment file writes it: serde types, each field's
//! default and the JSON forms of lights and objects.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::experiment::tagged;

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
    /// (default 5; the primary ray is depth 0). With both mirrors (`k_s >
    /// 0`) and glass (`k_t > 0`) each primary ray may have `2^(max_depth +
    /// 1) - 1` rays below it (131071 at 16): the cost guards count that
    /// tree (jobs and the converged reference past 1e11 ray-object tests are
    /// refused), and past depth 9 `check` warns.
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
