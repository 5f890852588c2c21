//! Volume estimators on budget sweeps: quadrature orders (trapezoid 2 on smooth
//! pieces, Gauss–Legendre exponential), the tracking estimators' N^-1/2 rate
//! and the coverage of their standard errors (a binomial test, statrs, with
//! the significance stated), and property tests of the transmittance laws.

use crate::common;
use common::*;
use lightquad::domain::Vec3;
use lightquad::geometry::Ray;
use lightquad::quadrature::{GaussLegendre, Trapezoid};
use lightquad::volume::tracking::{Extinction, Tracker, transmittance};
use lightquad::volume::{
    ConstantSphere, DepthScheme, EmissionMap, GaussianBlob, GaussianBlobs, Medium, ShadowMethod,
    VolumeScene, evaluate,
};
use proptest::prelude::*;
use statrs::distribution::{Binomial, DiscreteCDF};
use std::sync::Arc;

/// Two overlapping blobs; the ray passes between their centres.
fn blobs(scale: f64) -> GaussianBlobs {
    GaussianBlobs::new(vec![
        GaussianBlob {
            centre: Vec3::new(0.0, 0.1, 0.0) * scale,
            amplitude: 1.2 / scale,
            width: 0.4 * scale,
        },
        GaussianBlob {
            centre: Vec3::new(0.6, -0.2, 0.1) * scale,
            amplitude: 0.8 / scale,
            width: 0.25 * scale,
        },
    ])
    .expect("valid")
}

fn blob_ray(scale: f64) -> Ray {
    Ray::new(
        Vec3::new(-6.0, 0.0, 0.05) * scale,
        Vec3::new(1.0, 0.02, 0.0),
    )
    .expect("ray")
}

fn depth(scene: &VolumeScene, n: usize, trapezoid: bool) -> f64 {
    let res = if trapezoid {
        evaluate(
            scene,
            &Trapezoid,
            n,
            DepthScheme::Cumulative,
            ShadowMethod::Quadrature,
            &mut rng(0),
        )
    } else {
        let rule = GaussLegendre {
            error_estimate: false,
        };
        evaluate(
            scene,
            &rule,
            n,
            DepthScheme::Cumulative,
            ShadowMethod::Quadrature,
            &mut rng(0),
        )
    };
    res.expect("finite").optical_depth.value
}

fn blob_scene(scale: f64) -> VolumeScene {
    let mut scene = VolumeScene::new(blob_ray(scale));
    scene.medium = Some(Arc::new(blobs(scale)));
    scene
}

#[test]
fn trapezoid_is_second_order_and_gauss_legendre_exponential_on_a_smooth_medium() {
    // The looked-at part of the ray ends inside the blobs, so the integrand
    // does not vanish smoothly at the ends (where the trapezoid rule would be
    // spectrally accurate, by Euler–Maclaurin).
    let mut scene = blob_scene(1.0);
    (scene.t_min, scene.t_max) = (5.5, 6.7);
    let exact = blobs(1.0)
        .density_integral(&blob_ray(1.0), 5.5, 6.7)
        .expect("closed form");
    let pts: Vec<(f64, f64)> = (5..=10)
        .map(|j| {
            let n = (1usize << j) + 1;
            ((n - 1) as f64, (depth(&scene, n, true) - exact).abs())
        })
        .collect();
    let order = fitted_order(&pts);
    eprintln!("trapezoid order on the blob medium {order:.3}");
    assert!((order + 2.0).abs() < 0.1, "trapezoid order {order}");
    // Gauss–Legendre: the error falls by orders of magnitude per few nodes
    // until it reaches rounding.
    let errs: Vec<f64> = [10usize, 20, 40, 80]
        .iter()
        .map(|&n| (depth(&scene, n, false) - exact).abs())
        .collect();
    eprintln!("Gauss–Legendre errors at n = 10, 20, 40, 80: {errs:?}");
    assert!(
        errs[1] < 1e-3 * errs[0] && errs[3] < 1e-13 * exact,
        "{errs:?}"
    );
}

#[test]
fn tracking_estimators_converge_at_n_to_minus_one_half_and_their_errors_cover() {
    let medium = blobs(1.0);
    let ray = blob_ray(1.0);
    let tau = (-medium
        .density_integral(&ray, 0.0, f64::INFINITY)
        .expect("closed"))
    .exp();
    let sigma = Extinction {
        medium: &medium,
        lambda: 1.0,
    };
    for tracker in [Tracker::Delta, Tracker::Ratio, Tracker::ResidualRatio] {
        // Root-mean-square error over 24 seeds per budget.
        let pts: Vec<(f64, f64)> = (6..=12)
            .step_by(2)
            .map(|j| {
                let n = 1usize << j;
                let ms = (0..24)
                    .map(|s| {
                        let est =
                            transmittance(tracker, sigma, &ray, 0.0, f64::INFINITY, n, &mut rng(s))
                                .expect("finite");
                        (est.value - tau).powi(2)
                    })
                    .sum::<f64>()
                    / 24.0;
                (n as f64, ms.sqrt())
            })
            .collect();
        let order = fitted_order(&pts);
        eprintln!("{}: order {order:.3}", tracker.name());
        assert!(
            (order + 0.5).abs() < 0.12,
            "{}: order {order}",
            tracker.name()
        );

        // Coverage of 1.96 standard errors over 300 seeds: binomial test of
        // p = 0.95 at alpha = 0.001 (two-sided).
        let runs = 300u64;
        let covered = (0..runs)
            .filter(|&s| {
                let est = transmittance(
                    tracker,
                    sigma,
                    &ray,
                    0.0,
                    f64::INFINITY,
                    2000,
                    &mut rng(10_000 + s),
                )
                .expect("finite");
                (est.value - tau).abs() <= 1.96 * est.error
            })
            .count() as u64;
        let binom = Binomial::new(0.95, runs).expect("valid");
        let low = binom.cdf(covered);
        let high = 1.0 - binom.cdf(covered.saturating_sub(1));
        eprintln!("{}: coverage {covered}/{runs}", tracker.name());
        assert!(
            low > 0.0005 && high > 0.0005,
            "{}: {covered}/{runs} covered",
            tracker.name()
        );
    }
}

#[test]
fn ratio_tracking_has_lower_variance_than_delta_tracking() {
    let medium = blobs(1.0);
    let ray = blob_ray(1.0);
    let sigma = Extinction {
        medium: &medium,
        lambda: 1.0,
    };
    let se = |t| {
        transmittance(t, sigma, &ray, 0.0, f64::INFINITY, 20_000, &mut rng(7))
            .expect("finite")
            .error
    };
    let (delta, ratio) = (se(Tracker::Delta), se(Tracker::Ratio));
    assert!(ratio < delta, "ratio {ratio} vs delta {delta}");
}

#[test]
fn ratio_tracking_variance_is_campbells_at_its_rate() {
    // A constant sigma = 1 over the diameter L = 2 of a unit sphere: one
    // span's bound is sigma (1 + 8 eps), D = 2, so ratio tracking draws at
    // mu = k sigma with k = min(2 D, 256 / D) = 4. A walk's weight
    // (1 - 1/k)^K, K ~ Poisson(k D), has the relative variance
    // exp(sigma^2 L / mu) - 1 = exp(1/2) - 1 = 0.6487 (Campbell; at the
    // bound itself, k = 1, it would be e^2 - 1 = 6.39), and the mean e^-2.
    let sphere = ConstantSphere::new(Vec3::zeros(), 1.0, 1.0).expect("valid");
    let sigma = Extinction {
        medium: &sphere,
        lambda: 1.0,
    };
    let ray = Ray::new(Vec3::new(-3.0, 0.0, 0.0), Vec3::x()).expect("valid");
    let n = 200_000;
    let t = transmittance(Tracker::Ratio, sigma, &ray, 0.0, 10.0, n, &mut rng(11)).expect("finite");
    let tau = (-2.0f64).exp();
    let relative_variance = (t.error / t.value).powi(2) * n as f64;
    let exact = 0.5f64.exp() - 1.0;
    assert!(
        (relative_variance / exact - 1.0).abs() < 0.05,
        "relative variance {relative_variance} vs {exact}"
    );
    assert!(
        (t.value - tau).abs() < 4.0 * t.error,
        "{} vs {tau}",
        t.value
    );
    // About k D = 8 look-ups a walk (Poisson mean).
    let per_walk = t.evaluations as f64 / n as f64;
    assert!((per_walk - 8.0).abs() < 0.05, "{per_walk} look-ups a walk");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn transmittance_is_multiplicative_and_in_zero_one(
        a in -6.0f64..-1.0, b in -1.0f64..1.0, c in 1.0f64..6.0,
    ) {
        let base = blob_scene(1.0);
        let log_tau = |t0: f64, t1: f64| {
            let mut s = base.clone();
            (s.t_min, s.t_max) = (t0 + 6.0, t1 + 6.0);
            let rule = GaussLegendre { error_estimate: false };
            let res = evaluate(&s, &rule, 200, DepthScheme::Cumulative, ShadowMethod::Quadrature, &mut rng(0))
                .expect("finite");
            prop_assert!(res.transmittance > 0.0 && res.transmittance <= 1.0);
            Ok(res.log_transmittance)
        };
        let (ab, bc, ac) = (log_tau(a, b)?, log_tau(b, c)?, log_tau(a, c)?);
        prop_assert!((ac - (ab + bc)).abs() <= 1e-12 * ac.abs().max(1e-300), "{ac} vs {ab} + {bc}");
    }

    #[test]
    fn radiance_is_monotone_in_the_background(i_b in 0.0f64..10.0, extra in 0.0f64..10.0) {
        let mut s = blob_scene(1.0);
        s.emission = Some(EmissionMap::Proportional(0.5));
        let total = |b: f64| {
            let mut s = s.clone();
            s.background = Some(b);
            evaluate(&s, &GaussLegendre::default(), 30, DepthScheme::Cumulative, ShadowMethod::Quadrature, &mut rng(0))
                .expect("finite")
                .total
        };
        prop_assert!(total(i_b + extra) >= total(i_b));
    }

    #[test]
    fn scaling_geometry_by_s_and_density_by_one_over_s_keeps_tau(log_s in -6.0f64..6.0) {
        let s = 10f64.powf(log_s);
        let reference = depth(&blob_scene(1.0), 60, false);
        let scaled = depth(&blob_scene(s), 60, false);
        prop_assert!(rel(scaled, reference) < 1e-12, "s = {s}: {scaled} vs {reference}");
    }
}
