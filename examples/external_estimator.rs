//! An external estimator for lightquad in Rust (protocol
//! lightquad-estimator/1, docs/external-estimators.md): irradiance at a
//! receiver point from rectangle lights, each sampled uniformly by area
//! with [`REPLICATES`] independent stratified (jittered) grids of `m x m`
//! points, `8 m^2 <= n`:
//!
//! `E = sum over lights of A L_e (1/m^2) sum_ij cos(theta_r) cos(theta_e) / r^2` (R-A)
//!
//! per grid, averaged over the grids. Each grid is an unbiased estimate of
//! the whole, so the spread of the grids gives the standard error (one
//! stratified grid has no unbiased variance estimate of its own). A scene
//! this example cannot express gets an `error` answer.
//!
//! ```text
//! cargo build --release --example external_estimator
//! lightquad run experiments/x-external-examples.json
//! ```

use std::io::{BufRead, Write};
use std::time::Instant;

use rand::{RngExt, SeedableRng};
use serde_json::{Value, json};

type V3 = [f64; 3];

fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Three numbers at `v[key]`.
fn vec3(v: &Value, key: &str) -> Result<V3, String> {
    let xs: Vec<f64> = v[key]
        .as_array()
        .map(|a| a.iter().filter_map(Value::as_f64).collect())
        .unwrap_or_default();
    <V3>::try_from(xs.as_slice()).map_err(|_| format!("`{key}` is not three numbers"))
}

/// A rectangle light: origin, edges, radiance.
struct Rectangle {
    origin: V3,
    u: V3,
    v: V3,
    radiance: f64,
}

fn rectangles(scene: &Value) -> Result<Vec<Rectangle>, String> {
    if scene["occluders"].as_array().is_some_and(|o| !o.is_empty()) {
        return Err("occluders: this example has no visibility test".into());
    }
    let none = Vec::new();
    let emitters = scene["emitters"].as_array().unwrap_or(&none);
    emitters
        .iter()
        .enumerate()
        .map(|(k, e)| {
            if e["type"] != "rectangle" {
                return Err(format!("emitters[{k}] is a {}: only rectangles", e["type"]));
            }
            Ok(Rectangle {
                origin: vec3(e, "origin")?,
                u: vec3(e, "edge_u")?,
                v: vec3(e, "edge_v")?,
                radiance: e["radiance"]
                    .as_f64()
                    .ok_or(format!("emitters[{k}]: only a scalar radiance"))?,
            })
        })
        .collect()
}

/// Independent stratified grids per estimate.
const REPLICATES: u64 = 8;

/// The irradiance and its standard error from about `n` samples per light.
fn irradiance(scene: &Value, n: u64, seed: u64) -> Result<(f64, f64), String> {
    let x = vec3(&scene["receiver"], "point")?;
    let normal = vec3(&scene["receiver"], "normal")?;
    let normal_len = dot(normal, normal).sqrt();
    let lights = rectangles(scene)?;
    let m = (((n / REPLICATES) as f64).sqrt().floor() as u64).max(1);
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let estimates: Vec<f64> = (0..REPLICATES)
        .map(|_| {
            let mut sum = 0.0;
            for i in 0..m {
                for j in 0..m {
                    let u = (i as f64 + rng.random::<f64>()) / m as f64;
                    let v = (j as f64 + rng.random::<f64>()) / m as f64;
                    for light in &lights {
                        let facing = cross(light.u, light.v);
                        let area = dot(facing, facing).sqrt();
                        let y: V3 = std::array::from_fn(|k| {
                            light.origin[k] + u * light.u[k] + v * light.v[k]
                        });
                        let d = sub(y, x);
                        let r2 = dot(d, d);
                        let cos_r = dot(normal, d) / (normal_len * r2.sqrt());
                        let cos_e = -dot(facing, d) / (area * r2.sqrt());
                        if cos_r > 0.0 && cos_e > 0.0 {
                            sum += light.radiance * area * cos_r * cos_e / r2;
                        }
                    }
                }
            }
            sum / (m * m) as f64
        })
        .collect();
    let k = REPLICATES as f64;
    let mean = estimates.iter().sum::<f64>() / k;
    let variance = estimates.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (k - 1.0);
    Ok((mean, (variance / k).sqrt()))
}

fn answer(request: &Value) -> Value {
    let id = request["id"].clone();
    let quantity = request["quantity"].as_str().unwrap_or("");
    if request["family"] != "rendering" || !quantity.starts_with("E_") {
        return json!({"id": id, "error": format!("{quantity}: only the rendering family's irradiance E_*")});
    }
    let (Some(n), Some(seed)) = (request["budget"].as_u64(), request["seed"].as_u64()) else {
        return json!({"id": id, "error": "no budget or seed"});
    };
    let start = Instant::now();
    match irradiance(&request["scene"], n, seed) {
        Ok((value, se)) => json!({
            "id": id, "value": [value], "std_error": [se],
            "evaluations": REPLICATES * (((n / REPLICATES) as f64).sqrt().floor() as u64).max(1).pow(2),
            "seconds": start.elapsed().as_secs_f64(),
        }),
        Err(e) => json!({"id": id, "error": e}),
    }
}

fn main() -> std::io::Result<()> {
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    // Ready: the protocol it speaks.
    writeln!(
        out,
        "{}",
        json!({"protocol": "lightquad-estimator", "version": 1})
    )?;
    out.flush()?;
    for line in std::io::stdin().lock().lines() {
        let request: Value = serde_json::from_str(&line?).unwrap_or(Value::Null);
        writeln!(out, "{}", answer(&request))?;
        out.flush()?;
    }
    Ok(())
}
