//! Times lightquad's tracking estimators of V-tau and its free-flight
//! estimator of V-L through a voxel grid, for `scripts/tracking_race.py`,
//! which races them against Mitsuba 3.
//!
//! `cargo run --release --example tracking_race -- FILE ESTIMATOR WALKS SEED THREADS`
//!
//! - `FILE`: a volume experiment file whose `scene.medium` is a `voxel-grid`
//!   (its `scene.ray`, `scene.lambda` and `scene.light` are read; nothing
//!   else is);
//! - `ESTIMATOR`: `delta-tracking`, `ratio-tracking` or
//!   `residual-ratio-tracking` for V-tau, or `free-flight-light` for V-L with
//!   single scattering (delta tracking along the eye ray, a ratio-tracking
//!   shadow walk at every tentative collision: [`radiance`]);
//! - `WALKS`: the walks, split evenly over `THREADS` threads, each thread with
//!   its own PCG stream of `SEED`.
//!
//! Prints one JSON object: the estimate, its standard error, the walks, the
//! density look-ups and the seconds the walks took (the grid is built before
//! the clock starts).

use std::sync::Arc;
use std::time::Instant;

use lightquad::QuadError;
use lightquad::domain::Vec3;
use lightquad::geometry::Ray;
use lightquad::volume::tracking::{Extinction, Tracked, Tracker, Wanted, radiance, transmittance};
use lightquad::volume::{DirectionalLight, ShadowMethod, VolumeScene, VoxelGrid};
use rayon::prelude::*;
use serde_json::Value;

/// The three numbers at `path` in `v`, or an error naming the path.
fn vec3(v: &Value, path: &str) -> Result<Vec3, String> {
    let x = v.pointer(path).and_then(Value::as_array);
    match x.map(|a| a.iter().map(Value::as_f64).collect::<Option<Vec<_>>>()) {
        Some(Some(a)) if a.len() == 3 => Ok(Vec3::new(a[0], a[1], a[2])),
        _ => Err(format!("{path}: expected three numbers")),
    }
}

/// The number at `path` in `v`, or an error naming the path.
fn number(v: &Value, path: &str) -> Result<f64, String> {
    v.pointer(path)
        .and_then(Value::as_f64)
        .ok_or(format!("{path}: expected a number"))
}

/// The volume scene of the experiment file `text`: its voxel grid, ray,
/// lambda and, when `light`, its light.
fn scene(text: &str, light: bool) -> Result<VolumeScene, String> {
    let v: Value = serde_json::from_str(text).map_err(|e| e.to_string())?;
    let m = "/scene/medium";
    if v.pointer(&format!("{m}/type")).and_then(Value::as_str) != Some("voxel-grid") {
        return Err(format!("{m}/type: expected \"voxel-grid\""));
    }
    let resolution = v
        .pointer(&format!("{m}/resolution"))
        .and_then(Value::as_array)
        .and_then(|a| a.iter().map(Value::as_u64).collect::<Option<Vec<_>>>())
        .filter(|a| a.len() == 3)
        .ok_or(format!("{m}/resolution: expected three counts"))?;
    let data = v
        .pointer(&format!("{m}/data"))
        .and_then(Value::as_array)
        .and_then(|a| a.iter().map(Value::as_f64).collect::<Option<Vec<_>>>())
        .ok_or(format!("{m}/data: expected numbers"))?;
    let grid = VoxelGrid::new(
        vec3(&v, &format!("{m}/min"))?,
        vec3(&v, &format!("{m}/max"))?,
        [0, 1, 2].map(|k| resolution[k] as usize),
        data,
    )
    .map_err(|e| e.to_string())?;
    let ray = Ray::new(
        vec3(&v, "/scene/ray/origin")?,
        vec3(&v, "/scene/ray/direction")?,
    )
    .map_err(|e| e.to_string())?;
    let mut scene = VolumeScene::new(ray);
    scene.medium = Some(Arc::new(grid));
    scene.lambda = v
        .pointer("/scene/lambda")
        .map_or(Ok(1.0), |_| number(&v, "/scene/lambda"))?;
    if light {
        let albedo = number(&v, "/scene/light/albedo")?;
        scene.light = Some(
            DirectionalLight::new(
                vec3(&v, "/scene/light/toward_light")?,
                number(&v, "/scene/light/intensity")?,
                Some(albedo),
            )
            .map_err(|e| e.to_string())?,
        );
    }
    Ok(scene)
}

/// What is raced: a tracker of V-tau, or the free-flight estimator of V-L.
#[derive(Clone, Copy)]
enum Estimator {
    Tau(Tracker),
    Light,
}

/// `n` walks of `estimator` with the PCG stream `stream` of `seed`.
fn walks(
    estimator: Estimator,
    scene: &VolumeScene,
    n: usize,
    seed: u64,
    stream: u128,
) -> Result<Tracked, QuadError> {
    let mut rng = rand_pcg::Pcg64::new(seed as u128, stream);
    match (estimator, scene.medium.as_deref()) {
        (Estimator::Tau(tracker), Some(medium)) => {
            let sigma = Extinction {
                medium,
                lambda: scene.lambda,
            };
            transmittance(tracker, sigma, &scene.ray, 0.0, f64::INFINITY, n, &mut rng)
        }
        _ => {
            let wanted = Wanted {
                emission: false,
                light: true,
            };
            let shadow = ShadowMethod::ClosedFormWhereAvailable;
            Ok(radiance(scene, shadow, wanted, n, &mut rng)?.light)
        }
    }
}

/// `n` walks on `threads` threads, each with its own stream; the per-thread
/// estimates combined into one mean with its standard error.
fn race(
    estimator: Estimator,
    scene: &VolumeScene,
    n: usize,
    seed: u64,
    threads: usize,
) -> Result<Tracked, QuadError> {
    let parts: Vec<Tracked> = (0..threads)
        .into_par_iter()
        .map(|i| {
            let share = n / threads + usize::from(i < n % threads);
            walks(estimator, scene, share, seed, i as u128)
        })
        .collect::<Result<_, _>>()?;
    let total: u64 = parts.iter().map(|p| p.walks).sum();
    let weight = |p: &Tracked| p.walks as f64 / total as f64;
    // The parts' means weighted by their walks; the variances of the means
    // add with the squared weights.
    let variance: f64 = parts.iter().map(|p| (weight(p) * p.error).powi(2)).sum();
    Ok(Tracked {
        value: parts.iter().map(|p| weight(p) * p.value).sum(),
        error: variance.sqrt(),
        evaluations: parts.iter().map(|p| p.evaluations).sum(),
        walks: total,
        all_alike: parts.iter().all(|p| p.all_alike),
        heavy: parts.iter().any(|p| p.heavy),
        underflows: parts.iter().any(|p| p.underflows),
    })
}

/// The estimators this example races.
const ESTIMATORS: &str =
    "delta-tracking, ratio-tracking, residual-ratio-tracking or free-flight-light";

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [file, estimator, n, seed, threads] = args.as_slice() else {
        return Err("usage: tracking_race FILE ESTIMATOR WALKS SEED THREADS".into());
    };
    let text = std::fs::read_to_string(file).map_err(|e| format!("{file}: {e}"))?;
    let light = estimator == "free-flight-light";
    let scene = scene(&text, light).map_err(|e| format!("{file}: {e}"))?;
    let estimator = if light {
        Estimator::Light
    } else {
        Estimator::Tau(
            serde_json::from_value(serde_json::json!({ "rule": estimator }))
                .map_err(|_| format!("ESTIMATOR {estimator:?}: expected {ESTIMATORS}"))?,
        )
    };
    let parse = |s: &str, what: &str| s.parse::<usize>().map_err(|e| format!("{what}: {e}"));
    let (n, seed, threads) = (
        parse(n, "WALKS")?,
        parse(seed, "SEED")? as u64,
        parse(threads, "THREADS")?,
    );
    if !(1..=MAX_THREADS).contains(&threads) {
        return Err(format!("THREADS = {threads}: expected 1 to {MAX_THREADS}"));
    }
    // Every thread's share needs two walks for a standard error.
    if n < 2 * threads {
        return Err(format!(
            "WALKS = {n}: expected at least 2 a thread, {} for THREADS = {threads}",
            2 * threads
        ));
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| e.to_string())?;
    let start = Instant::now();
    let est = pool
        .install(|| race(estimator, &scene, n, seed, threads))
        .map_err(|e| e.to_string())?;
    let seconds = start.elapsed().as_secs_f64();
    println!(
        "{}",
        serde_json::json!({
            "value": est.value, "std_error": est.error, "walks": est.walks,
            "lookups": est.evaluations, "seconds": seconds, "threads": threads,
        })
    );
    Ok(())
}

/// More threads than this machine kind ever has only adds start-up time.
const MAX_THREADS: usize = 256;
