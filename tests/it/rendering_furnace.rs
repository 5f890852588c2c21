//! The full rendering equation in an integrating sphere:
//! the Neumann series bounce by bounce and path tracing with Russian
//! roulette, against the closed form `L = L_e [cap] + rho L_e (1 - cos
//! alpha) / (2 (1 - rho))` and the white furnace `L_e / (1 - rho)`
//! (`exact::rendering::furnace`). The closed form rests on the sphere's
//! constant kernel, checked here by an independent area integral.

use crate::common;
use common::rng;
use lightquad::domain::{SphericalCap, Vec3, integrate_over};
use lightquad::exact::rendering::{furnace, furnace_truncated};
use lightquad::quadrature::{GaussLegendre, GenzMalik};
use lightquad::rendering::furnace::{IntegratingSphere, bounces_for};
use std::f64::consts::PI;

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// The irradiance at a wall point from a Lambertian cap of radiance 1,
/// integrated over the cap's surface (R-A with the explicit cosines at both
/// ends and the distance), equals `A_c / (4 R^2) = pi (1 - cos alpha) / 2`
/// for every wall point: the constant kernel the closed form uses.
#[test]
fn a_cap_lights_every_wall_point_alike() {
    let r = 2.0;
    for alpha in [0.3f64, 1.0, 2.0] {
        let cap = SphericalCap::new(Vec3::zeros(), Vec3::z(), r, alpha.cos()).expect("cap");
        let want = PI * (1.0 - alpha.cos()) / 2.0;
        for d in [
            Vec3::new(1.0, 0.0, -1.0),
            Vec3::new(0.3, -0.8, -0.2),
            Vec3::new(0.0, 0.0, -1.0),
        ] {
            let x = d.normalize() * r;
            // Points of the cap near x's own position are excluded by the
            // choice of x (outside every cap here but the largest).
            let e = integrate_over(
                &GenzMalik::default(),
                &cap,
                200_000,
                &mut rng(0),
                |y: Vec3| {
                    let v = y - x;
                    let dist2 = v.norm_squared();
                    let cos_x = (v / dist2.sqrt()).dot(&(-x / r)).max(0.0);
                    let cos_y = (-v / dist2.sqrt()).dot(&(-y / r)).max(0.0);
                    cos_x * cos_y / dist2
                },
            )
            .expect("finite");
            assert!(
                rel(e.value, want) < 1e-9,
                "alpha {alpha}, x {x:?}: {} vs {want}",
                e.value
            );
        }
    }
}

/// The closed form: the white furnace is `exact::rendering::furnace`; a cap
/// adds its uniform share to every wall point and its emission inside.
#[test]
fn the_closed_form_is_the_furnace_and_the_cap_share() {
    for rho in [0.0, 0.5, 0.9, 0.999] {
        let s = IntegratingSphere::furnace(1.5, rho, 2.0).expect("valid");
        let x = s.wall(Vec3::new(0.2, 0.3, 0.9));
        assert!(rel(s.radiance(&x), furnace(2.0, rho).expect("valid")) < 1e-14);
        for k in [0u32, 1, 5, 100] {
            let (_, tail) = furnace_truncated(2.0, rho, k).expect("valid");
            assert!((s.truncation(k) - tail).abs() <= 1e-14 * tail.max(1e-300) + 1e-300);
        }
    }
    let s = IntegratingSphere::new(1.0, 0.8, 3.0, 0.5, Vec3::x()).expect("valid");
    let share = 0.8 * 3.0 * (1.0 - 0.5f64.cos()) / (2.0 * 0.2);
    assert!(rel(s.radiance(&Vec3::x()), 3.0 + share) < 1e-15);
    assert!(rel(s.radiance(&-Vec3::x()), share) < 1e-15);
}

/// Bounces for a relative truncation error: the smallest `K` with
/// `rho^(K+1) <= tol`, found here by repeated multiplication.
#[test]
fn the_bounces_the_truncation_needs() {
    for (rho, tol) in [(0.5, 1e-3), (0.9, 1e-6), (0.999, 1e-6), (0.999, 1e-10)] {
        let (mut k, mut p) = (0u64, rho);
        while p > tol {
            p *= rho;
            k += 1;
        }
        assert_eq!(
            bounces_for(rho, tol).expect("valid"),
            k,
            "rho {rho}, tol {tol}"
        );
    }
    eprintln!(
        "rho = 0.999: {} bounces for 1e-6",
        bounces_for(0.999, 1e-6).expect("valid")
    );
    assert!(bounces_for(1.0, 1e-6).is_err() && bounces_for(0.5, 0.0).is_err());
}

/// The Neumann series at a wall point: every bounce's value plus its
/// closed-form truncation is the exact radiance (to the quadrature error,
/// here Gauss–Legendre on the projected hemisphere: exact for the white
/// furnace's constant integrand), and the truncation falls as `rho^(K+1)`.
/// With a cap the hemisphere integral has a jump at the cap's edge, which
/// the albedo's series multiplies by `1/(1 - rho)` = 20: adaptive cubature
/// converges like a jump does (measured: 8.7e-3 at 4096 evaluations,
/// 6.0e-5 at 1e5), and its estimate stays above the error.
#[test]
fn the_neumann_series_converges_bounce_by_bounce() {
    let s = IntegratingSphere::furnace(1.0, 0.9, 1.0).expect("valid");
    let x = s.wall(Vec3::new(0.1, -0.4, 0.7));
    let series = s
        .neumann(&x, &GaussLegendre::default(), 64, 200, &mut rng(0))
        .expect("finite");
    let exact = s.radiance(&x);
    for b in &series {
        let (kept, tail) = furnace_truncated(1.0, 0.9, b.bounce).expect("valid");
        assert!(
            rel(b.value, kept) < 1e-13,
            "bounce {}: {} vs {kept}",
            b.bounce,
            b.value
        );
        assert!((b.truncation - tail).abs() <= 1e-13 * tail + 1e-300);
        assert!(rel(b.value + b.truncation, exact) < 1e-13);
    }
    // A cap of half-angle 0.7 about +z, seen from a wall point off it.
    let s = IntegratingSphere::new(1.0, 0.95, 1.0, 0.7, Vec3::z()).expect("valid");
    let x = s.wall(Vec3::new(1.0, 0.2, -0.5));
    let exact = s.radiance(&x);
    for (n, tol) in [(4096usize, 2e-2), (100_000, 2e-4)] {
        let series = s
            .neumann(&x, &GenzMalik::default(), n, 2000, &mut rng(0))
            .expect("finite");
        let last = series.last().expect("bounces");
        let truth = (last.value + last.truncation - exact).abs();
        eprintln!(
            "cap, genz-malik n = {n}: L_2000 = {}, exact {exact}, error {truth:.2e}, estimate {:.2e}",
            last.value, last.error
        );
        assert!(truth < tol * exact, "{truth}");
        assert!(last.error >= truth, "estimate {} below {truth}", last.error);
    }
}

/// Path tracing with Russian roulette is unbiased: the mean over paths is
/// within 4 standard errors of the closed form for the white furnace at
/// albedo 0.5, 0.9 and 0.999 (about 1000 bounces a path) and for a cap, and
/// over 200 seeds the interval of 1.96 standard errors covers the truth
/// about 95% of the time.
#[test]
fn path_tracing_with_russian_roulette_is_unbiased_and_its_error_honest() {
    for (rho, paths) in [(0.5, 20_000usize), (0.9, 20_000), (0.999, 400)] {
        let s = IntegratingSphere::furnace(1.0, rho, 1.0).expect("valid");
        let x = s.wall(Vec3::new(0.0, 0.6, 0.8));
        let e = s.path_trace(&x, paths, &mut rng(5)).expect("finite");
        let exact = s.radiance(&x);
        eprintln!(
            "furnace rho {rho}: {} +- {} (exact {exact}), {} bounces",
            e.value, e.error, e.evaluations
        );
        assert!((e.value - exact).abs() < 4.0 * e.error);
    }
    let s = IntegratingSphere::new(1.0, 0.7, 2.0, 0.6, Vec3::z()).expect("valid");
    let x = s.wall(Vec3::new(0.3, 0.0, -1.0));
    let exact = s.radiance(&x);
    let mut covered = 0;
    for seed in 0..200 {
        let e = s.path_trace(&x, 2000, &mut rng(seed)).expect("finite");
        covered += ((e.value - exact).abs() <= 1.96 * e.error) as u32;
    }
    eprintln!("cap: {covered}/200 covered");
    // Binomial(200, 0.95): 5th to 99.9th percentiles about 184 to 197.
    assert!((180..=199).contains(&covered), "{covered}/200");
}

/// Bad parameters are errors naming the parameter.
#[test]
fn bad_parameters_are_named() {
    for (e, name) in [
        (
            IntegratingSphere::new(-1.0, 0.5, 1.0, 1.0, Vec3::z()),
            "radius",
        ),
        (
            IntegratingSphere::new(1.0, 1.0, 1.0, 1.0, Vec3::z()),
            "albedo",
        ),
        (
            IntegratingSphere::new(1.0, 0.5, f64::NAN, 1.0, Vec3::z()),
            "emission",
        ),
        (
            IntegratingSphere::new(1.0, 0.5, 1.0, 4.0, Vec3::z()),
            "alpha",
        ),
        (
            IntegratingSphere::new(1.0, 0.5, 1.0, 1.0, Vec3::zeros()),
            "axis",
        ),
    ] {
        let e = e.expect_err("refused");
        assert!(e.to_string().contains(name), "{e}");
    }
    let s = IntegratingSphere::furnace(1.0, 0.5, 1.0).expect("valid");
    assert!(s.path_trace(&Vec3::x(), 1, &mut rng(0)).is_err());
}
