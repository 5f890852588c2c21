//! The volume family's scene as an experiment file writes it (`scene`: the
//! ray, the medium, its emission, the light), and its checked construction
//! into the scene the family integrates: every number finite and in range,
//! named by its JSON path, and optical depths that overflow refused with the
//! largest value that does not.

use std::sync::Arc;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::domain::Vec3;
use crate::error::SpecError;
use crate::experiment::tagged;
use crate::geometry::Ray;
use crate::volume::gaussian_blobs::{MAX_WIDTH, MIN_WIDTH};
use crate::volume::printed::{self, Printed};
use crate::volume::{
    ConstantSphere, DirectionalLight, EmissionMap, GaussianBlob, GaussianBlobs, Medium,
    TransferTable, VolumeScene, linear_gradient::LinearGradient, voxel_grid::VoxelGrid,
};

/// The scene along one eye ray.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SceneSpec {
    /// How `tau(t_n, t)` inside V-E and V-L is computed.
    #[serde(default, deserialize_with = "tagged::named")]
    pub depth_scheme: DepthSchemeSpec,
    /// How the shadow ray's optical depth in V-Lp is computed.
    #[serde(default, deserialize_with = "tagged::named")]
    pub shadow: ShadowSpec,
    /// The eye ray.
    #[serde(deserialize_with = "tagged::object")]
    pub ray: RaySpec,
    /// Start of the looked-at part of the ray (default 0).
    #[serde(default)]
    pub t_min: Option<f64>,
    /// End of the looked-at part (default: infinite).
    #[serde(default)]
    pub t_max: Option<f64>,
    /// The medium, if any.
    #[serde(default)]
    pub medium: Option<MediumSpec>,
    /// `lambda` in `sigma = lambda v_r` (default 1).
    #[serde(default)]
    pub lambda: Option<f64>,
    /// The emission map, if the medium emits.
    #[serde(default)]
    pub emission: Option<EmissionSpec>,
    /// Background radiance `I_b`, if any.
    #[serde(default)]
    pub background: Option<f64>,
    /// The directional light, if any.
    #[serde(default, deserialize_with = "tagged::optional_object")]
    pub light: Option<LightSpec>,
    /// Audit points of docs/EQUATIONS.md whose printed forms the report
    /// evaluates in this scene beside the corrected ones (constant sphere
    /// only; `s` and `exponent` need a light, `background` a background).
    #[serde(default, deserialize_with = "tagged::non_empty_names")]
    pub printed: Vec<Printed>,
}

/// A ray `e + t v`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RaySpec {
    /// `e`.
    #[serde(deserialize_with = "tagged::array")]
    pub origin: [f64; 3],
    /// `v` (normalised; t is arc length).
    #[serde(deserialize_with = "tagged::array")]
    pub direction: [f64; 3],
}

/// A medium: `{"type": <name>, <the variant's fields>}`.
#[derive(Debug, Clone, PartialEq, Serialize, JsonSchema)]
#[serde(tag = "type", rename_all = "kebab-case")]
pub enum MediumSpec {
    /// Constant density `kappa` in a sphere.
    ConstantSphere(ConstantSphereSpec),
    /// A sum of Gaussian blobs.
    GaussianBlobs(GaussianBlobsSpec),
    /// `max(0, base + gradient . (x - centre))` inside a sphere.
    LinearGradient(LinearGradientSpec),
    /// A voxel grid (values at voxel centres, trilinear, `[z][y][x]`).
    VoxelGrid(VoxelGridSpec),
}

/// Reads the tag, then the variant's fields, so that a fault inside names
/// its own path (`scene.medium.kappa`; see [`tagged`]).
impl<'de> Deserialize<'de> for MediumSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        const NAMES: [&str; 4] = [
            "constant-sphere",
            "gaussian-blobs",
            "linear-gradient",
            "voxel-grid",
        ];
        let (tag, fields) = tagged::split_tag(serde_json::Value::deserialize(d)?, "type", &NAMES)?;
        match tag.as_str() {
            "constant-sphere" => tagged::variant(fields).map(MediumSpec::ConstantSphere),
            "gaussian-blobs" => tagged::variant(fields).map(MediumSpec::GaussianBlobs),
            "linear-gradient" => tagged::variant(fields).map(MediumSpec::LinearGradient),
            _ => tagged::variant(fields).map(MediumSpec::VoxelGrid),
        }
    }
}

/// Constant density `kappa` in a sphere.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ConstantSphereSpec {
    /// Centre.
    #[serde(deserialize_with = "tagged::array")]
    pub centre: [f64; 3],
    /// Radius.
    pub radius: f64,
    /// Density.
    pub kappa: f64,
}

/// A sum of Gaussian blobs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GaussianBlobsSpec {
    /// The blobs.
    pub blobs: Vec<BlobSpec>,
}

/// `max(0, base + gradient . (x - centre))` inside a sphere.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LinearGradientSpec {
    /// Centre of the bounding sphere.
    #[serde(deserialize_with = "tagged::array")]
    pub centre: [f64; 3],
    /// Its radius.
    pub radius: f64,
    /// Density at the centre.
    pub base: f64,
    /// Gradient.
    #[serde(deserialize_with = "tagged::array")]
    pub gradient: [f64; 3],
}

/// A voxel grid (values at voxel centres, trilinear, `[z][y][x]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct VoxelGridSpec {
    /// Lower corner.
    #[serde(deserialize_with = "tagged::array")]
    pub min: [f64; 3],
    /// Upper corner.
    #[serde(deserialize_with = "tagged::array")]
    pub max: [f64; 3],
    /// Voxels per axis.
    #[serde(deserialize_with = "tagged::counts")]
    pub resolution: [usize; 3],
    /// Densities, x fastest.
    pub data: Vec<f64>,
}

/// One Gaussian blob.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BlobSpec {
    /// Centre.
    #[serde(deserialize_with = "tagged::array")]
    pub centre: [f64; 3],
    /// Peak density.
    pub amplitude: f64,
    /// Width (standard deviation).
    pub width: f64,
}

/// The emission of V-E: a map `c(v)` of the density, or a field of its own;
/// `{"type": <name>, <the variant's fields>}`.
#[derive(Debug, Clone, PartialEq, Serialize, JsonSchema)]
#[serde(tag = "type", rename_all = "kebab-case")]
pub enum EmissionSpec {
    /// `c(v) = c` inside the medium (where the density is positive).
    Constant(ConstantEmissionSpec),
    /// `c(v) = k v`.
    Proportional(ProportionalEmissionSpec),
    /// A transfer function `c(v)`, piecewise linear.
    Table(TableEmissionSpec),
    /// An emission field of its own, `Le(p)`, independent of the density.
    Field(FieldEmissionSpec),
}

/// Reads the tag, then the variant's fields (see [`MediumSpec`]'s reader).
impl<'de> Deserialize<'de> for EmissionSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        const NAMES: [&str; 4] = ["constant", "proportional", "table", "field"];
        let (tag, fields) = tagged::split_tag(serde_json::Value::deserialize(d)?, "type", &NAMES)?;
        match tag.as_str() {
            "constant" => tagged::variant(fields).map(EmissionSpec::Constant),
            "proportional" => tagged::variant(fields).map(EmissionSpec::Proportional),
            "table" => tagged::variant(fields).map(EmissionSpec::Table),
            _ => tagged::variant(fields).map(EmissionSpec::Field),
        }
    }
}

/// `c(v) = c` inside the medium (where the density is positive).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ConstantEmissionSpec {
    /// The constant.
    pub c: f64,
}

/// `c(v) = k v`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ProportionalEmissionSpec {
    /// The factor.
    pub k: f64,
}

/// A transfer function: `c(v)` piecewise linear through `points`
/// `[[v0, c0], [v1, c1], ..]` (at least 2; `v` at least 0 and strictly
/// increasing; `c` finite, at least 0), held at `c0` below `v0` and at the
/// last `c` above the last `v`, and 0 where the density is 0 (a medium
/// emits where its density is positive).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TableEmissionSpec {
    /// The points `[v, c]`.
    #[serde(deserialize_with = "tagged::arrays")]
    pub points: Vec<[f64; 2]>,
}

/// An emission field of its own, `Le(p)`, independent of the density:
/// `I_E = int tau(t_0, t) Le(r(t)) dt`, also where the density is 0.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct FieldEmissionSpec {
    /// The field's shape and values, written as a medium (`Le` is its
    /// density): `constant-sphere`, `gaussian-blobs`, `linear-gradient`
    /// or `voxel-grid`.
    pub field: MediumSpec,
}

/// A directional light.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LightSpec {
    /// Direction from a point toward the light.
    #[serde(deserialize_with = "tagged::array")]
    pub toward_light: [f64; 3],
    /// Intensity `I_p`.
    pub intensity: f64,
    /// Single-scattering albedo (omit for the document's reduced V-L).
    #[serde(default)]
    pub albedo: Option<f64>,
}

/// How the nested optical depth is computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum DepthSchemeSpec {
    /// Cumulative (cost ~ n).
    #[default]
    Cumulative,
    /// Nested (cost ~ n^2).
    Nested,
}

/// How the shadow ray is integrated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum ShadowSpec {
    /// Closed form where the medium has one.
    #[default]
    ClosedForm,
    /// Always quadrature.
    Quadrature,
}

/// A field of a medium that scales its optical depth bound: its path below
/// `scene.medium`, its value, and how to set it.
type DepthField = (String, f64, Box<dyn Fn(&mut MediumSpec, f64)>);

/// The fields whose size scales a medium's optical depth along a ray: the
/// densities (kappa, amplitudes, base, gradient, the voxel grid's largest
/// value) and the lengths (radius, widths).
fn depth_fields(m: &MediumSpec) -> Vec<DepthField> {
    let mut out: Vec<DepthField> = Vec::new();
    match m {
        MediumSpec::ConstantSphere(s) => {
            out.push((
                "kappa".into(),
                s.kappa,
                Box::new(|m, x| {
                    if let MediumSpec::ConstantSphere(s) = m {
                        s.kappa = x;
                    }
                }),
            ));
            out.push((
                "radius".into(),
                s.radius,
                Box::new(|m, x| {
                    if let MediumSpec::ConstantSphere(s) = m {
                        s.radius = x;
                    }
                }),
            ));
        }
        MediumSpec::GaussianBlobs(b) => {
            for (i, blob) in b.blobs.iter().enumerate() {
                out.push((
                    format!("blobs[{i}].amplitude"),
                    blob.amplitude,
                    Box::new(move |m, x| {
                        if let MediumSpec::GaussianBlobs(b) = m {
                            b.blobs[i].amplitude = x;
                        }
                    }),
                ));
                out.push((
                    format!("blobs[{i}].width"),
                    blob.width,
                    Box::new(move |m, x| {
                        if let MediumSpec::GaussianBlobs(b) = m {
                            b.blobs[i].width = x;
                        }
                    }),
                ));
            }
        }
        MediumSpec::LinearGradient(g) => {
            out.push((
                "radius".into(),
                g.radius,
                Box::new(|m, x| {
                    if let MediumSpec::LinearGradient(g) = m {
                        g.radius = x;
                    }
                }),
            ));
            out.push((
                "base".into(),
                g.base,
                Box::new(|m, x| {
                    if let MediumSpec::LinearGradient(g) = m {
                        g.base = x;
                    }
                }),
            ));
            for k in 0..3 {
                out.push((
                    format!("gradient[{k}]"),
                    g.gradient[k],
                    Box::new(move |m, x| {
                        if let MediumSpec::LinearGradient(g) = m {
                            g.gradient[k] = x;
                        }
                    }),
                ));
            }
        }
        MediumSpec::VoxelGrid(v) => {
            if let Some((i, &x)) = v
                .data
                .iter()
                .enumerate()
                .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
            {
                out.push((
                    format!("data[{i}]"),
                    x,
                    Box::new(move |m, x| {
                        if let MediumSpec::VoxelGrid(v) = m {
                            v.data[i] = x;
                        }
                    }),
                ));
            }
        }
    }
    out
}

/// Whether the scene of `spec` fails to build or its optical depth bound
/// along the ray is not finite.
fn depth_overflows(spec: &SceneSpec) -> bool {
    scene(spec).map_or(true, |s| {
        let (sigma, depth) = s.anchored().0.depth_bound();
        !(sigma.is_finite() && depth.is_finite())
    })
}

/// `x` (> 0) rounded down to two significant digits, in scientific notation.
fn two_digits_down(x: f64) -> String {
    let e = x.log10().floor();
    let mut m = (x / 10f64.powf(e) * 10.0).floor() / 10.0;
    // The division can round a mantissa of 10 down to 9.99...
    if m >= 10.0 {
        m = 9.9;
    }
    format!("{m:.1}e{e}")
}

/// The error for a medium whose optical depth along the ray overflows f64
/// with lambda = 1 (`sigma` and `depth` its bound as given), at the field
/// that causes it: the one field of [`depth_fields`] that brings the bound
/// below 1.8e308 alone when set to 1 (the most extreme of them, if several
/// do), with the largest value it may take, the others as given, found by
/// bisection. A medium no single field can repair is refused at its largest
/// field, saying so.
pub(super) fn depth_fault(
    spec: &SceneSpec,
    medium: &MediumSpec,
    sigma: f64,
    depth: f64,
) -> SpecError {
    let with = |set: &dyn Fn(&mut MediumSpec, f64), x: f64| {
        let mut s = spec.clone();
        if let Some(m) = s.medium.as_mut() {
            set(m, x);
        }
        s
    };
    let fields: Vec<DepthField> = depth_fields(medium)
        .into_iter()
        .filter(|(_, x, _)| x.abs() > 1.0)
        .collect();
    let culprit = fields
        .iter()
        .filter(|(_, x, set)| !depth_overflows(&with(set.as_ref(), x.signum())))
        .reduce(|a, b| if b.1.abs() > a.1.abs() { b } else { a });
    let overflow = format!(
        "the optical depth along the ray overflows f64 (lambda = {}; the largest extinction \
         lambda v is {sigma:e}, and times the chord it bounds the depth by {depth:e})",
        crate::error::shortened(spec.lambda.unwrap_or(1.0).to_string())
    );
    let Some((field, x, set)) = culprit else {
        let Some((field, x, _)) = fields
            .iter()
            .reduce(|a, b| if b.1.abs() > a.1.abs() { b } else { a })
        else {
            return SpecError::at(
                "scene.medium",
                format!(
                    "{overflow}: expected a medium whose optical depth along the ray stays \
                     below 1.8e308"
                ),
            );
        };
        let others: Vec<String> = fields
            .iter()
            .filter(|(f, y, _)| f != field && y.abs() > 1.0)
            .map(|(f, _, _)| format!("scene.medium.{f}"))
            .collect();
        return SpecError::at(
            format!("scene.medium.{field}"),
            format!(
                "{}: {overflow}, and no value of this field alone brings it below 1.8e308: \
                 expected smaller values here and at {}",
                crate::error::shortened(x.to_string()),
                others.join(", ")
            ),
        );
    };
    // The largest magnitude in [1, |x|] whose bound stays finite, bisected
    // on the exponent.
    let (mut lo, mut hi) = (0.0f64, x.abs().log2());
    for _ in 0..64 {
        let mid = 0.5 * (lo + hi);
        if depth_overflows(&with(set.as_ref(), x.signum() * mid.exp2())) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let largest = two_digits_down(lo.exp2());
    let range = if *x < 0.0 {
        format!("at least -{largest}")
    } else {
        format!("at most {largest}")
    };
    SpecError::at(
        format!("scene.medium.{field}"),
        format!(
            "{}: {overflow}: expected {field} {range} along this ray, with lambda and the \
             medium's other fields as given (the optical depth must stay below 1.8e308)",
            crate::error::shortened(x.to_string())
        ),
    )
}

fn vec3(v: [f64; 3]) -> Vec3 {
    Vec3::new(v[0], v[1], v[2])
}

fn finite(path: &str, x: f64, accepted: &str) -> Result<f64, SpecError> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(SpecError::at(path, format!("{x} is not {accepted}")))
    }
}

/// `x` when finite and `>= 0`, else an error at `path`.
fn non_negative(path: &str, x: f64) -> Result<f64, SpecError> {
    if x.is_finite() && x >= 0.0 {
        Ok(x)
    } else {
        Err(SpecError::at(
            path,
            format!(
                "{x} is not a finite number >= 0 (emitted radiance; absorption belongs to sigma)"
            ),
        ))
    }
}

/// The medium (or emission field) of `spec`, errors anchored at `at`.
fn medium(spec: &MediumSpec, at: &str) -> Result<Arc<dyn Medium>, SpecError> {
    Ok(match spec {
        MediumSpec::ConstantSphere(ConstantSphereSpec {
            centre,
            radius,
            kappa,
        }) => Arc::new(
            ConstantSphere::new(vec3(*centre), *radius, *kappa)
                .map_err(|e| SpecError::from_quad(at, e))?,
        ),
        MediumSpec::GaussianBlobs(GaussianBlobsSpec { blobs }) => Arc::new(
            GaussianBlobs::new(
                blobs
                    .iter()
                    .map(|b| GaussianBlob {
                        centre: vec3(b.centre),
                        amplitude: b.amplitude,
                        width: b.width,
                    })
                    .collect(),
            )
            .map_err(|e| SpecError::from_quad(at, e))?,
        ),
        MediumSpec::LinearGradient(LinearGradientSpec {
            centre,
            radius,
            base,
            gradient,
        }) => Arc::new(
            LinearGradient::new(vec3(*centre), *radius, *base, vec3(*gradient))
                .map_err(|e| SpecError::from_quad(at, e))?,
        ),
        MediumSpec::VoxelGrid(VoxelGridSpec {
            min,
            max,
            resolution,
            data,
        }) => Arc::new(
            VoxelGrid::new(vec3(*min), vec3(*max), *resolution, data.clone())
                .map_err(|e| SpecError::from_quad(at, e))?,
        ),
    })
}

/// Builds the scene, naming the path of any bad number.
/// The printed forms an experiment asks for, checked against its scene.
pub(super) fn printed_forms(
    spec: &SceneSpec,
) -> Result<Option<(printed::Sphere, Vec<Printed>)>, SpecError> {
    if spec.printed.is_empty() {
        return Ok(None);
    }
    let Some(MediumSpec::ConstantSphere(ConstantSphereSpec {
        centre,
        radius,
        kappa,
    })) = spec.medium
    else {
        return Err(SpecError::at(
            "scene.printed",
            "the printed formulas are written for a constant-density sphere: give a \
             constant-sphere medium, or leave printed out"
                .to_string(),
        ));
    };
    for (i, p) in spec.printed.iter().enumerate() {
        let name = serde_json::to_string(p).unwrap_or_default();
        if spec.printed[..i].contains(p) {
            return Err(SpecError::at(
                format!("scene.printed[{i}]"),
                format!("{name} is named twice: name each audit point once"),
            ));
        }
        let missing = match p {
            Printed::S | Printed::Exponent if spec.light.is_none() => Some("a light"),
            Printed::Background if spec.background.is_none() => Some("a background"),
            _ => None,
        };
        if let Some(what) = missing {
            return Err(SpecError::at(
                format!("scene.printed[{i}]"),
                format!(
                    "{name} is a printed form of a term the scene does not have: give it {what}"
                ),
            ));
        }
    }
    // The printed light formulas square the radius unscaled, as the
    // document writes them: outside [1e-150, 1e150] R^2 leaves the normal
    // numbers (radius 1e308 made their evaluation NaN; 1e-200 made the
    // printed root real where it is not), as for a blob's width.
    let light_forms = spec
        .printed
        .iter()
        .any(|p| matches!(p, Printed::S | Printed::Exponent));
    if light_forms && !(MIN_WIDTH..=MAX_WIDTH).contains(&radius) {
        return Err(SpecError::at(
            "scene.medium.radius",
            format!(
                "{}: expected a radius in [{MIN_WIDTH:e}, {MAX_WIDTH:e}] where the printed light \
                 formulas (scene.printed \"s\" or \"exponent\") are evaluated: they square it, \
                 and its square must be a normal number",
                crate::error::shortened(radius.to_string())
            ),
        ));
    }
    Ok(Some((
        printed::Sphere {
            centre: Vec3::new(centre[0], centre[1], centre[2]),
            radius,
            kappa,
        },
        spec.printed.clone(),
    )))
}

/// The largest distance from the ray's origin to a sphere's centre that is
/// accepted: the chord is found from `c - o` and its square, which
/// overflows f64 beyond about 1.34e154 (an origin at -1e155 before a sphere
/// at 1e154 was read as a miss, and every term as 0, with no fault).
pub const MAX_REACH: f64 = 1e154;

/// Refuses a sphere (of a constant or linear-gradient medium, or such an
/// emission field) whose centre's distance from the ray's origin, or its
/// square, overflows f64, at the centre's path. (Gaussian blobs and voxel
/// grids meet the ray without that square.)
pub(super) fn within_reach(spec: &SceneSpec) -> Result<(), SpecError> {
    let origin = vec3(spec.ray.origin);
    let centre = |m: &MediumSpec| match m {
        MediumSpec::ConstantSphere(s) => Some(s.centre),
        MediumSpec::LinearGradient(g) => Some(g.centre),
        _ => None,
    };
    let field = match &spec.emission {
        Some(EmissionSpec::Field(FieldEmissionSpec { field })) => Some(field),
        _ => None,
    };
    let spheres = [
        ("scene.medium", spec.medium.as_ref()),
        ("scene.emission.field", field),
    ];
    for (at, m) in spheres {
        let Some(c) = m.and_then(centre) else {
            continue;
        };
        let d = vec3(c) - origin;
        let scale = d.amax();
        let distance = match scale {
            0.0 => 0.0,
            s if s.is_finite() => s * (d / s).norm(),
            _ => f64::INFINITY,
        };
        if distance.is_nan() || distance > MAX_REACH {
            return Err(SpecError::at(
                format!("{at}.centre"),
                format!(
                    "{c:?} is {distance:.2e} from the ray's origin {:?}: expected a centre within \
                     {MAX_REACH:e} of scene.ray.origin (the chord is found from the square of \
                     that distance, which overflows f64 beyond 1.3e154)",
                    spec.ray.origin
                ),
            ));
        }
    }
    Ok(())
}

pub(super) fn scene(s: &SceneSpec) -> Result<VolumeScene, SpecError> {
    let ray = Ray::new(vec3(s.ray.origin), vec3(s.ray.direction))
        .map_err(|e| SpecError::from_quad("scene.ray", e))?;
    let mut scene = VolumeScene::new(ray);
    if let Some(t) = s.t_min {
        scene.t_min = finite("scene.t_min", t, "a finite number")?;
    }
    if let Some(t) = s.t_max {
        if t.is_nan() || t < scene.t_min {
            return Err(SpecError::at(
                "scene.t_max",
                format!("{t} must be >= t_min = {} (t_f >= t_n)", scene.t_min),
            ));
        }
        scene.t_max = t;
    }
    if let Some(l) = s.lambda {
        if !(l.is_finite() && l >= 0.0) {
            return Err(SpecError::at(
                "scene.lambda",
                format!("{l} is not a finite number >= 0"),
            ));
        }
        scene.lambda = l;
    }
    scene.medium = s
        .medium
        .as_ref()
        .map(|m| medium(m, "scene.medium"))
        .transpose()?;
    scene.emission = match &s.emission {
        None => None,
        // Emitted radiance is not negative (absorption belongs to sigma), as
        // for a table's values.
        Some(EmissionSpec::Constant(ConstantEmissionSpec { c })) => {
            Some(EmissionMap::Constant(non_negative("scene.emission.c", *c)?))
        }
        Some(EmissionSpec::Proportional(ProportionalEmissionSpec { k })) => Some(
            EmissionMap::Proportional(non_negative("scene.emission.k", *k)?),
        ),
        Some(EmissionSpec::Table(TableEmissionSpec { points })) => Some(EmissionMap::Table(
            TransferTable::new(points.iter().map(|p| (p[0], p[1])).collect())
                .map_err(|e| SpecError::from_quad("scene.emission", e))?,
        )),
        Some(EmissionSpec::Field(FieldEmissionSpec { field })) => {
            Some(EmissionMap::Field(medium(field, "scene.emission.field")?))
        }
    };
    if let Some(b) = s.background {
        if !(b.is_finite() && b >= 0.0) {
            return Err(SpecError::at(
                "scene.background",
                format!("{b} is not a finite radiance >= 0"),
            ));
        }
        scene.background = Some(b);
    }
    if let Some(l) = &s.light {
        scene.light = Some(
            DirectionalLight::new(vec3(l.toward_light), l.intensity, l.albedo)
                .map_err(|e| SpecError::from_quad("scene.light", e))?,
        );
    }
    Ok(scene)
}
