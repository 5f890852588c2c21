//! The rendering family's scene as an experiment file writes it
//! (`scene` in the JSON: the receiver, emitters, occluders and the BRDF),
//! and its checked construction into the scene the family integrates: every
//! number bounded and named by its JSON path.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::domain::Vec3;
use crate::error::{QuadError, SpecError};
use crate::experiment::tagged;
use crate::rendering::brdf::{Ggx, Lambert, NormalizedPhong, Phong};
use crate::rendering::emitter::{
    AnyEmitter, CapLight, DiskLight, Emitter, EnvironmentLight, RectangleLight, SphereLight,
    TriangleLight,
};
use crate::rendering::occluder::Occluder;
use crate::rendering::receiver::Receiver;
use crate::rendering::scene::Scene;

use super::{AnyBrdf, Built};

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

/// Coordinates and sizes beyond this are refused: squared distances of
/// larger ones overflow f64.
pub const MAX_COORDINATE: f64 = 1e100;

/// `[x, y, z]` as a vector.
pub(crate) fn vec3(v: [f64; 3]) -> Vec3 {
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
pub(crate) fn emitter_numbers(spec: &EmitterSpec) -> Vec<(&'static str, Vec<f64>)> {
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
pub(crate) fn occluder_numbers(spec: &OccluderSpec) -> Vec<(&'static str, Vec<f64>)> {
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
pub(crate) fn bounded(
    path: &str,
    o: &Occluder,
    fields: &[(&str, Vec<f64>)],
) -> Result<(), SpecError> {
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

pub(crate) fn emitter(spec: &EmitterSpec) -> Result<AnyEmitter<f64>, QuadError> {
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

pub(crate) fn occluder(spec: &OccluderSpec) -> Result<Occluder, QuadError> {
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
pub(super) fn build(spec: &SceneSpec) -> Result<Built, SpecError> {
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
    let mut warnings = Vec::new();
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
        if let Some(w) = facing_away(&at, &e, &receiver) {
            warnings.push(w);
        }
        warnings.extend(super::doubts::emitter_doubt(i, &e, receiver.point()));
        emitters.push(e);
    }
    let mut occluders = Vec::with_capacity(spec.occluders.len());
    for (j, o_spec) in spec.occluders.iter().enumerate() {
        let at = format!("scene.occluders[{j}]");
        let o = occluder(o_spec).map_err(|err| SpecError::from_quad(&at, err))?;
        bounded(&at, &o, &occluder_numbers(o_spec))?;
        warnings.extend(super::doubts::occluder_doubts(
            j,
            &o,
            &emitters,
            receiver.point(),
        ));
        occluders.push(o);
    }
    Ok(Built {
        scene: Scene::new(emitters, occluders),
        receiver,
        brdf,
        toward_viewer,
        warnings,
    })
}

/// The warning at `at` for a finite emitter whose emitting side faces away
/// from the receiver (the receiver behind it or in its plane): it sends the
/// receiver no light. A one-sided emitter emits on the side of its normal:
/// `edge_u x edge_v` for a rectangle, `(b - a) x (c - a)` for a triangle,
/// `normal` for a disk, outward for a sphere.
fn facing_away(at: &str, e: &AnyEmitter<f64>, receiver: &Receiver) -> Option<SpecError> {
    if e.at_infinity() {
        return None;
    }
    let (y, _) = crate::domain::Domain::map(&e.surface(receiver).ok()?, [0.5, 0.5]);
    let n = e.normal_at(y);
    let x = receiver.point();
    ((x - y).dot(&n) <= 0.0).then(|| {
        SpecError::at(
            at,
            format!(
                "faces away from the receiver: it emits on the side of its normal {:?} \
                 (edge_u x edge_v for a rectangle, (b - a) x (c - a) for a triangle, `normal` \
                 for a disk), and the receiver at {:?} is behind it or in its plane, so every \
                 quantity gets 0 from it (reverse the normal, or swap edge_u and edge_v, or b \
                 and c, to light the receiver)",
                n.as_slice(),
                x.as_slice()
            ),
        )
    })
}

/// True when R-A needs visibility for some emitter of `spec`: an occluder,
/// or a finite emitter that can shadow another emitter.
pub(super) fn needs_visibility(spec: &SceneSpec) -> bool {
    let finite = spec
        .emitters
        .iter()
        .filter(|e| !matches!(e, EmitterSpec::Environment(_) | EmitterSpec::Cap(_)))
        .count();
    !spec.occluders.is_empty() || (finite >= 1 && spec.emitters.len() >= 2)
}
