//! The exchange family's scene as an experiment file writes it: the
//! receiving surface, the planar emitters and the occluders (the rendering
//! family's formats), checked and built with every error at its JSON path.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::domain::{Disk, Rectangle, Triangle, Vec3};
use crate::error::{QuadError, SpecError};
use crate::experiment::tagged;
use crate::rendering::emitter::{AnyEmitter, Emitter};
use crate::rendering::experiment::{
    DiskSpec, EmitterSpec, OccluderSpec, RectangleSpec, TriangleSpec, bounded, build_emitter,
    build_occluder, emitter_numbers, occluder_numbers, vec3,
};
use crate::rendering::occluder::Occluder;
use crate::rendering::scene::Scene;

use super::Built;
use super::surface::Surface;

/// The scene: the receiving surface, the emitters and the occluders.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SceneSpec {
    /// The surface that receives the light, on the side of its normal.
    pub receiver: SurfaceSpec,
    /// The lights: rectangles, disks, triangles (at least one).
    pub emitters: Vec<EmitterSpec>,
    /// Opaque surfaces between them (default none).
    #[serde(default, deserialize_with = "tagged::non_empty")]
    pub occluders: Vec<OccluderSpec>,
}

/// A receiving patch, `{"type": <name>, <the variant's fields>}`: it
/// receives on the side of `edge_u x edge_v` (a rectangle), `(b - a) x (c -
/// a)` (a triangle), `normal` (a disk).
#[derive(Debug, Clone, PartialEq, Serialize, JsonSchema)]
#[serde(tag = "type", rename_all = "kebab-case")]
pub enum SurfaceSpec {
    /// A parallelogram `origin + a edge_u + b edge_v`.
    Rectangle(RectangleSpec),
    /// A disk.
    Disk(DiskSpec),
    /// A triangle.
    Triangle(TriangleSpec),
}

impl<'de> Deserialize<'de> for SurfaceSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        const NAMES: [&str; 3] = ["rectangle", "disk", "triangle"];
        let (tag, fields) = tagged::split_tag(serde_json::Value::deserialize(d)?, "type", &NAMES)?;
        match tag.as_str() {
            "rectangle" => tagged::variant(fields).map(SurfaceSpec::Rectangle),
            "disk" => tagged::variant(fields).map(SurfaceSpec::Disk),
            _ => tagged::variant(fields).map(SurfaceSpec::Triangle),
        }
    }
}

fn surface(spec: &SurfaceSpec) -> Result<(Surface, Occluder), QuadError> {
    let v = vec3;
    Ok(match spec {
        SurfaceSpec::Rectangle(r) => (
            Surface::Rectangle(Rectangle::new(v(r.origin), v(r.edge_u), v(r.edge_v))?),
            Occluder::rectangle(v(r.origin), v(r.edge_u), v(r.edge_v))?,
        ),
        SurfaceSpec::Disk(d) => (
            Surface::Disk(Disk::new(v(d.centre), v(d.normal), d.radius)?),
            Occluder::disk(v(d.centre), v(d.normal), d.radius)?,
        ),
        SurfaceSpec::Triangle(t) => (
            Surface::Triangle(Triangle::new(v(t.a), v(t.b), v(t.c))?),
            Occluder::triangle(v(t.a), v(t.b), v(t.c))?,
        ),
    })
}

fn surface_numbers(spec: &SurfaceSpec) -> Vec<(&'static str, Vec<f64>)> {
    match spec {
        SurfaceSpec::Rectangle(r) => occluder_numbers(&OccluderSpec::Rectangle(r.clone())),
        SurfaceSpec::Disk(d) => occluder_numbers(&OccluderSpec::Disk(d.clone())),
        SurfaceSpec::Triangle(t) => occluder_numbers(&OccluderSpec::Triangle(t.clone())),
    }
}

/// Checks every number of the scene and builds it; errors name the JSON
/// path from the file's root, doubts come back as warnings.
pub(super) fn build(spec: &SceneSpec) -> Result<Built, SpecError> {
    let at = "scene.receiver";
    let (receiver, body) = surface(&spec.receiver).map_err(|e| SpecError::from_quad(at, e))?;
    bounded(at, &body, &surface_numbers(&spec.receiver))?;
    large_enough(at, &receiver)?;
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
        if matches!(
            e_spec,
            EmitterSpec::Sphere(_) | EmitterSpec::Environment(_) | EmitterSpec::Cap(_)
        ) {
            return Err(SpecError::at(
                format!("{at}.type"),
                "a sphere, environment or cap light: the exchange family's emitters are \
                 surfaces of the scene with an area (expected `rectangle`, `disk` or \
                 `triangle`); the rendering family integrates the others at a point",
            ));
        }
        let e = build_emitter(e_spec).map_err(|err| SpecError::from_quad(&at, err))?;
        if let Some(o) = e.occluder() {
            bounded(&at, &o, &emitter_numbers(e_spec))?;
        }
        if let Some(light) = Surface::of_light(&e) {
            large_enough(&at, &light)?;
        }
        warnings.extend(placement(&at, &receiver, &e));
        emitters.push(e);
    }
    let mut occluders = Vec::with_capacity(spec.occluders.len());
    for (j, o_spec) in spec.occluders.iter().enumerate() {
        let at = format!("scene.occluders[{j}]");
        let o = build_occluder(o_spec).map_err(|err| SpecError::from_quad(&at, err))?;
        bounded(&at, &o, &occluder_numbers(o_spec))?;
        occluders.push(o);
    }
    Ok(Built {
        scene: Scene::new(emitters, occluders),
        receiver,
        warnings,
    })
}

/// The doubts about an emitter's place relative to the receiver: it faces
/// away from every receiver point, or the receiver faces away from every
/// point of it (every quantity gets 0 from it), or the two lie in one plane,
/// or they cross (the kernel `1/r^2` is singular along their common line
/// inside both, and the rules converge slowly there). "In a plane" is to
/// the rounding of the coordinates.
fn placement(at: &str, receiver: &Surface, e: &AnyEmitter<f64>) -> Option<SpecError> {
    let light = Surface::of_light(e)?;
    let (p, n) = (receiver.centre(), receiver.normal());
    let (q, m) = (light.centre(), light.normal());
    let (hi_r, lo_r) = receiver.span_along(q, m);
    let (hi_k, lo_k) = light.span_along(p, n);
    let tol = 64.0 * f64::EPSILON * (p.norm() + q.norm() + (p - q).norm());
    let why = if hi_r <= tol && lo_r >= -tol && hi_k <= tol && lo_k >= -tol {
        "lies in the receiver's plane: no light passes between them (every quantity gets 0 \
         from it)"
    } else if hi_r <= tol {
        "faces away from the whole receiver (it emits on the side of its normal: edge_u x \
         edge_v, (b - a) x (c - a), or `normal`): every quantity gets 0 from it"
    } else if hi_k <= tol {
        "is wholly behind the receiver's receiving side (the side of its normal): every \
         quantity gets 0 from it"
    } else if lo_r < -tol && lo_k < -tol && crosses(receiver, &light) {
        "crosses the receiver: the kernel cos cos / r^2 is singular along their common line \
         inside both, so every form converges slowly there; split them at the line for \
         accuracy"
    } else {
        return None;
    };
    Some(SpecError::at(at, why))
}

/// The smallest patch accepted, as the square root of its area.
pub const MIN_SIZE: f64 = 1e-100;

/// Refuses a patch smaller than [`MIN_SIZE`]: the area form's `1 / r^2`
/// between its points underflows f64 beyond it.
fn large_enough(at: &str, surface: &Surface) -> Result<(), SpecError> {
    let size = surface.area().sqrt();
    if size >= MIN_SIZE {
        return Ok(());
    }
    Err(SpecError::at(
        at,
        format!(
            "a patch of size {size:e} (the square root of its area): expected at least \
             {MIN_SIZE:e} (squared distances between the points of smaller ones underflow f64)"
        ),
    ))
}

/// Whether the receiver and the light meet inside both: the chord the
/// light's plane cuts from the receiver, tested at 1025 points for lying on
/// the light (a meeting shorter than 1/1024 of the chord can be missed).
fn crosses(receiver: &Surface, light: &Surface) -> bool {
    use crate::domain::Domain;
    let Some((a, b)) = chord(receiver, light.centre(), light.normal()) else {
        return false;
    };
    let m = light.normal();
    (0..=1024).any(|i| {
        let x = a + (b - a) * (i as f64 / 1024.0);
        let x = x - m * m.dot(&(x - light.centre()));
        light.invert(&x).is_some()
    })
}

/// The chord that the plane through `q` with unit normal `m` cuts from the
/// surface, if it cuts one.
fn chord(surface: &Surface, q: Vec3, m: Vec3) -> Option<(Vec3, Vec3)> {
    let side = |x: Vec3| m.dot(&(x - q));
    let points: Vec<Vec3> = match surface.corners() {
        Some(cs) => (0..cs.len())
            .filter_map(|i| {
                let (a, b) = (cs[i], cs[(i + 1) % cs.len()]);
                let (sa, sb) = (side(a), side(b));
                ((sa <= 0.0) != (sb <= 0.0)).then(|| a + (b - a) * (sa / (sa - sb)))
            })
            .collect(),
        None => {
            let Surface::Disk(d) = surface else {
                return None;
            };
            let n = d.frame().n;
            let u = m - n * n.dot(&m);
            let (len, c) = (u.norm(), d.centre());
            if len <= 1e-12 {
                return None;
            }
            let u = u / len;
            let s = -side(c) / m.dot(&u);
            let half2 = d.radius() * d.radius() - s * s;
            if half2.is_nan() || half2 < 0.0 {
                return None;
            }
            let t = n.cross(&u) * half2.sqrt();
            let mid = c + u * s;
            vec![mid - t, mid + t]
        }
    };
    (points.len() >= 2).then(|| (points[0], points[points.len() - 1]))
}
