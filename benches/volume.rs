//! Time per eye ray for the volume terms at 1e-8 relative accuracy.
//!
//! For each medium (the constant sphere and two Gaussian blobs), each term
//! (V-tau, V-L with single scattering) and each deterministic rule, the setup
//! finds the smallest budget (doubling) whose value is within 1e-8 of the
//! reference (the closed form for the sphere; a 400-node Gauss–Legendre run,
//! itself checked against 800 nodes, for the blobs) and prints it; criterion
//! then times one evaluation at that budget. The tracking estimators cannot
//! reach 1e-8 (it would take ~1e16 walks); they are timed at 10^4 walks with
//! the standard error they achieve printed beside.

use std::hint::black_box;
use std::sync::Arc;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use lightquad::domain::Vec3;
use lightquad::geometry::Ray;
use lightquad::quadrature::{AnyRule, GaussLegendre};
use lightquad::volume::tracking::{Extinction, Tracker, transmittance};
use lightquad::volume::{
    ConstantSphere, DepthScheme, DirectionalLight, GaussianBlob, GaussianBlobs, Medium,
    ShadowMethod, VolumeScene, evaluate,
};
use rand::SeedableRng;

fn scene(medium: Arc<dyn Medium>) -> VolumeScene {
    let mut s = VolumeScene::new(
        Ray::new(Vec3::new(-4.0, 0.2, 0.1), Vec3::new(1.0, 0.05, 0.0))
            .unwrap_or_else(|e| panic!("{e}")),
    );
    s.medium = Some(medium);
    s.lambda = 1.0;
    s.light = Some(
        DirectionalLight::new(Vec3::new(0.3, 1.0, 0.2), 1.0, Some(0.8))
            .unwrap_or_else(|e| panic!("{e}")),
    );
    s
}

/// (V-tau optical depth, V-L) with `rule` at budget n.
fn terms(s: &VolumeScene, rule: &AnyRule, n: usize) -> (f64, f64) {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(1);
    let r = evaluate(
        s,
        rule,
        n,
        DepthScheme::Cumulative,
        ShadowMethod::ClosedFormWhereAvailable,
        &mut rng,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    (r.optical_depth.value, r.light.map_or(0.0, |l| l.value))
}

fn volume(c: &mut Criterion) {
    let sphere: Arc<dyn Medium> =
        Arc::new(ConstantSphere::new(Vec3::zeros(), 1.0, 1.5).unwrap_or_else(|e| panic!("{e}")));
    let blobs: Arc<dyn Medium> = Arc::new(
        GaussianBlobs::new(vec![
            GaussianBlob {
                centre: Vec3::new(0.0, 0.1, 0.0),
                amplitude: 1.2,
                width: 0.4,
            },
            GaussianBlob {
                centre: Vec3::new(0.6, -0.2, 0.1),
                amplitude: 0.8,
                width: 0.25,
            },
        ])
        .unwrap_or_else(|e| panic!("{e}")),
    );
    let reference_rule = AnyRule::Base(lightquad::quadrature::BaseRule::GaussLegendre(
        GaussLegendre {
            error_estimate: false,
        },
    ));
    let mut g = c.benchmark_group("volume_per_ray");
    g.sample_size(20)
        .measurement_time(Duration::from_secs(2))
        .warm_up_time(Duration::from_millis(300));
    for (medium_name, medium) in [("constant-sphere", sphere), ("gaussian-blobs", blobs)] {
        let s = scene(medium.clone());
        let reference = terms(&s, &reference_rule, 400);
        let check = terms(&s, &reference_rule, 800);
        eprintln!(
            "{medium_name}: reference depth {:.15e}, I_L {:.15e} (400 vs 800 nodes: {:.1e}, {:.1e})",
            reference.0,
            reference.1,
            ((reference.0 - check.0) / check.0).abs(),
            ((reference.1 - check.1) / check.1).abs()
        );
        for rule_name in ["trapezoid", "gauss-legendre", "gauss-kronrod"] {
            let Ok(rule) = AnyRule::by_name(rule_name) else {
                continue;
            };
            for (term, pick) in [("tau", 0usize), ("I_L", 1usize)] {
                let want = if pick == 0 { reference.0 } else { reference.1 };
                let mut n = if rule_name == "gauss-kronrod" { 15 } else { 3 };
                let found = loop {
                    let (d, l) = terms(&s, &rule, n);
                    let got = if pick == 0 { d } else { l };
                    if ((got - want) / want).abs() < 1e-8 {
                        break Some(n);
                    }
                    if n > 1 << 16 {
                        break None;
                    }
                    n *= 2;
                };
                let Some(n) = found else {
                    eprintln!("{medium_name} {term} {rule_name}: 1e-8 not reached by n = 65536");
                    continue;
                };
                eprintln!("{medium_name} {term} {rule_name}: 1e-8 reached at n = {n}");
                let id = BenchmarkId::new(format!("{medium_name}/{term}/{rule_name}"), n);
                g.bench_function(id, |b| {
                    b.iter(|| {
                        let mut only = s.clone();
                        if pick == 0 {
                            only.light = None;
                        }
                        terms(black_box(&only), &rule, n)
                    })
                });
            }
        }
        for tracker in [Tracker::Delta, Tracker::Ratio, Tracker::ResidualRatio] {
            let sigma = Extinction {
                medium: medium.as_ref(),
                lambda: 1.0,
            };
            let ray = s.ray;
            let mut rng = rand_pcg::Pcg64::seed_from_u64(3);
            let est = transmittance(tracker, sigma, &ray, 0.0, f64::INFINITY, 10_000, &mut rng)
                .unwrap_or_else(|e| panic!("{e}"));
            eprintln!(
                "{medium_name} tau {}: 1e4 walks give {:.6} +- {:.1e} (true {:.6})",
                tracker.name(),
                est.value,
                est.error,
                (-reference.0).exp()
            );
            g.bench_function(
                BenchmarkId::new(format!("{medium_name}/tau/{}", tracker.name()), 10_000),
                |b| {
                    b.iter(|| {
                        transmittance(tracker, sigma, &ray, 0.0, f64::INFINITY, 10_000, &mut rng)
                    })
                },
            );
        }
    }
    g.finish();
}

criterion_group!(benches, volume);
criterion_main!(benches);
