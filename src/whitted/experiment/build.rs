//! A file's scene checked and built: a value out of bounds is refused, named
//! by its JSON path; an object f64 may not resolve (too small beside its
//! distance from the eye, or too large) or a material that sends back more
//! than it receives is built, with a warning naming it.

use super::Built;
use super::spec::{LightSpec, MAX_COORDINATE, MaterialSpec, ObjectSpec, SceneSpec};
use crate::domain::Vec3;
use crate::error::SpecError;
use crate::value::Rgb;
use crate::whitted::intersect::Shape;
use crate::whitted::scene::{Camera, Light, Material, Object, Scene};

/// The least size of an object beside its distance from the eye that f64
/// resolves along the rays meeting it: their rounding is about 1e-16 of
/// their length, so below 1e-12 a hit point is uncertain by more than
/// 1e-4 of the object.
pub const SMALLEST_RESOLVED: f64 = 1e-12;

/// The relative accuracy a closed-form coverage must keep: its film lines'
/// rounding over the size of the object's image (both in pixels) above this
/// is warned at the object.
pub const FILM_RESOLVED: f64 = 1e-13;

/// The least size of an object whose squared sizes stay normal f64
/// numbers (1e-150 squared is 1e-300).
pub const SMALLEST_SIZE: f64 = 1e-150;

/// The most rays below one primary ray before `check` warns at
/// `scene.max_depth`: 1023, a tree of both mirror and glass rays to depth 9
/// (the bundled scenes go to depth 4, 31 rays).
pub const BUSHY_TREE: f64 = 1023.0;

/// What a scene must be for its rays to be defined: said when a pixel comes
/// out not a number (`render`) or a pixel's integrand does (a job).
pub const RESOLVED_SCENE: &str = "a scene whose coordinates and sizes f64 resolves along its \
     rays: extents and distances within about 1e12 of each other (an object of size 1e30 \
     around the camera, a sphere of radius 1e-20 seen from 1e19 or an eye 1e16 from the scene \
     are not)";

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
pub(super) fn build(spec: &SceneSpec) -> Result<Built, SpecError> {
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
        // Film coordinates, up to the image's size in pixels, are rounded
        // to about 2.2e-16 of it: an object whose image is a small part of
        // a pixel has a closed-form coverage (a region bounded by film
        // lines) exact only to that rounding over its size (an eye 1e15
        // from a unit triangle: 2.4e-30 for 8.9e-31).
        if let Some(ratio) = object.shape.size_over_distance(camera.eye()) {
            let tan_half = (0.5 * c.fov_y.to_radians()).tan();
            let across = ratio * c.height as f64 / (2.0 * tan_half);
            let film = f64::EPSILON * c.width.max(c.height) as f64;
            if across > 0.0 && film / across > FILM_RESOLVED {
                warnings.push(SpecError::at(
                    at.clone(),
                    format!(
                        "its image is about {across:.1e} pixels across, and film coordinates \
                         are rounded to about {film:.0e} of a pixel: its closed-form coverage \
                         is exact only to about {:.0e} relative (above the {FILM_RESOLVED:.0e} a \
                         reference claims); expected the eye nearer the object",
                        film / across
                    ),
                ));
            }
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
    // A bushy ray tree multiplies every job's and the reference's rays.
    let tree = super::tree_rays(&scene);
    if tree > BUSHY_TREE {
        warnings.push(SpecError::at(
            "scene.max_depth",
            format!(
                "max_depth {} with mirrors and glass: up to {tree:.0} rays below each primary ray, each \
                 tested against {} object(s); jobs are refused past 1e11 ray-object tests by \
                 this count, and so is the converged reference when it runs (each doubling of \
                 its n doubles it); expected a max_depth of {} or less unless the scene's rays \
                 escape early",
                spec.max_depth,
                scene.objects.len(),
                (BUSHY_TREE + 1.0).log2() as usize - 1
            ),
        ));
    }
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
