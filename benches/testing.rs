//! `lightquad::testing`'s chi-square test at the size a renderer's test
//! suite runs it: 10^6 samples of cosine-weighted hemisphere sampling over
//! `40 x 80` cells of the uniform hemisphere map, on one core.
//!
//! - `chi_square/whole`: the expected counts (Genz–Malik on `2 x 2` boxes
//!   of each cell) and the test, as `ChiSquare::run` does them;
//! - `chi_square/expected_counts`: the cubature alone;
//! - `chi_square/samples`: drawing, binning and judging the samples
//!   against counts computed once.

use std::f64::consts::PI;
use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use lightquad::domain::{Hemisphere, Vec3};
use lightquad::testing::ChiSquare;

/// Malley's method.
fn cosine(u: [f64; 2]) -> Option<Vec3> {
    let (r, phi) = (u[0].sqrt(), 2.0 * PI * u[1]);
    Some(Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u[0]).sqrt()))
}

fn pdf(w: &Vec3) -> f64 {
    w.z / PI
}

fn chi_square(c: &mut Criterion) {
    let test = ChiSquare::new(Hemisphere::uniform())
        .cells([40, 80])
        .samples(1_000_000);
    let mut group = c.benchmark_group("chi_square");
    group.sample_size(10);
    group.bench_function("whole", |b| {
        b.iter(|| {
            let out = test.run(pdf, cosine, black_box(1));
            assert!(out.is_ok_and(|o| o.passed));
        })
    });
    group.bench_function("expected_counts", |b| {
        b.iter(|| black_box(test.clone().expect(pdf).map(|e| e.total())))
    });
    let Ok(expected) = test.clone().expect(pdf) else {
        panic!("the expected counts of a finite density")
    };
    group.bench_function("samples", |b| {
        b.iter(|| black_box(expected.test(cosine, black_box(1)).map(|o| o.statistic)))
    });
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().measurement_time(Duration::from_secs(5)).warm_up_time(Duration::from_secs(1));
    targets = chi_square
}
criterion_main!(benches);
