//! Rays per second of the Whitted renderer on the bundled test scene
//! (`experiments/w-grey-test-scene.json`: spheres, a plane, a mirror and a
//! glass sphere, one point light) at 256 x 256 pixels:
//!
//! - `whitted/primary/*`: one ray through each pixel centre, the primary
//!   rays' cost (each with its shadow, reflection and refraction rays);
//! - `whitted/grid3/*`: W-SS's 3 x 3 grid a pixel, the full supersampled
//!   image;
//!
//! each on one thread (`render`) and on all of rayon's (`render_parallel`,
//! bands of rows). The setup prints the rays each image traces by kind, so a
//! median converts to rays per second: `rays / median`.
//!
//! `cargo bench --bench whitted`.

use std::time::Duration;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use lightquad::whitted::experiment::scene_of;
use lightquad::whitted::render::{Scheme, render, render_parallel};
use rand::SeedableRng;

fn whitted(c: &mut Criterion) {
    let text = include_str!("../experiments/w-grey-test-scene.json");
    let Ok(json) = serde_json::from_str::<serde_json::Value>(text) else {
        return;
    };
    let Ok(built) = scene_of(&json, Some(256), Some(256)) else {
        return;
    };
    let scene = built.scene;
    let mut g = c.benchmark_group("whitted");
    g.sample_size(10).measurement_time(Duration::from_secs(8));
    for (name, scheme) in [
        ("primary", Scheme::Centre),
        ("grid3", Scheme::Grid { n: 3 }),
    ] {
        if let Ok(out) = render_parallel(&scene, &scheme, 0) {
            println!(
                "{name}: {} rays ({} primary, {} shadow, {} reflection, {} refraction), {} threads",
                out.rays.total(),
                out.rays.primary,
                out.rays.shadow,
                out.rays.reflection,
                out.rays.refraction,
                rayon::current_num_threads()
            );
        }
        g.bench_function(BenchmarkId::new(name, "1-thread"), |b| {
            b.iter(|| {
                let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
                render(&scene, &scheme, &mut rng)
            })
        });
        g.bench_function(BenchmarkId::new(name, "all-threads"), |b| {
            b.iter(|| render_parallel(&scene, &scheme, 0))
        });
    }
    g.finish();
}

criterion_group!(benches, whitted);
criterion_main!(benches);
