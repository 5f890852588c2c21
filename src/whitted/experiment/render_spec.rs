//! The `render` command's side of the family: a file's scene rendered with
//! W-SS's grid, within a memory and ray budget.

use super::build::{RESOLVED_SCENE, build};
use super::spec::SceneSpec;
use super::{Built, Whitted, per_primary};
use crate::error::SpecError;
use crate::experiment::tagged;
use crate::family::Family;
use crate::value::Value;
use crate::whitted::render::{self, Scheme as Render};
use crate::whitted::shade::RayCount;

/// Renders the scene of a `whitted` experiment file's JSON (`json["scene"]`)
/// at `width x height` (default: the file's) with W-SS's `m x m` grid, `m =
/// floor(sqrt(samples))`: the image and the rays by kind. Faults name their
/// JSON path.
pub fn render_spec(
    json: &serde_json::Value,
    width: Option<usize>,
    height: Option<usize>,
    samples: usize,
) -> Result<(crate::whitted::image::Image, RayCount, Vec<SpecError>), SpecError> {
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
    // The size first, named by its flags, and what the memory allows.
    fits(spec_width, spec_height)?;
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
    let image = crate::whitted::image::Image::new(spec_width, spec_height, out.image.values)
        .map_err(|e| SpecError::from_quad("scene.camera", e))?;
    Ok((image, out.rays, built.warnings))
}

/// The most pixels `lightquad render` renders (`width x height`):
/// [`MAX_JOB_BYTES`](crate::experiment::validate::MAX_JOB_BYTES) at
/// [`RENDER_BYTES_PER_PIXEL`], 67 108 864 (8192 x 8192).
pub const MAX_RENDER_PIXELS: f64 =
    crate::experiment::validate::MAX_JOB_BYTES / RENDER_BYTES_PER_PIXEL;

/// The address space a render holds beside its pixels and its threads:
/// the program, its libraries and the scene (`VmSize` at the start, about
/// 10 MB, is already out of the room under a cap; this is the rest, with
/// a margin).
pub const RENDER_RESERVE: f64 = 32e6;

/// Refuses a `width x height` render of more than [`MAX_RENDER_PIXELS`],
/// or one whose memory, `width x height x` [`RENDER_BYTES_PER_PIXEL`] plus
/// its worker threads' stacks and allocator arenas
/// ([`thread_reserve`](crate::experiment::memory::thread_reserve)) plus
/// [`RENDER_RESERVE`], exceeds the room under a hard cap on this process
/// (`prlimit --as`, a cgroup): past it an allocation fails and aborts the
/// process (2048 x 2048 under `prlimit --as=300000000`).
fn fits(width: usize, height: usize) -> Result<(), SpecError> {
    use crate::experiment::memory;
    let pixels = (width as f64) * (height as f64);
    let bytes = pixels * RENDER_BYTES_PER_PIXEL;
    if pixels > MAX_RENDER_PIXELS {
        return Err(SpecError::at(
            "width",
            format!(
                "--width x --height = {width} x {height} pixels ({pixels:.0}) hold about {} \
                 while rendering: expected at most {MAX_RENDER_PIXELS:.0} pixels (8192 x 8192; \
                 a smaller --width, --height)",
                memory::bytes(bytes)
            ),
        ));
    }
    let Some(cap) = memory::hard_cap() else {
        return Ok(());
    };
    let threads = rayon::current_num_threads();
    let workers = memory::thread_reserve(threads);
    if bytes + workers + RENDER_RESERVE > cap.room {
        return Err(SpecError::at(
            "width",
            format!(
                "--width x --height = {width} x {height} pixels hold about {} while rendering, \
                 its {threads} worker thread(s) reserve about {} (stacks and allocator arenas) \
                 and the rest about {}, and {} leaves {}: expected a smaller --width, --height \
                 (or a larger limit)",
                memory::bytes(bytes),
                memory::bytes(workers),
                memory::bytes(RENDER_RESERVE),
                cap.what,
                memory::bytes(cap.room)
            ),
        ));
    }
    Ok(())
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
