//! Emitters, occluders and visibility (src/rendering/{emitter, occluder,
//! scene, cap}.rs) against independent references:
//!
//! - ray intersections against chords and distances written out by hand,
//!   the parallelogram against its two triangles, watertightness on shared
//!   edges and vertices;
//! - light sampling: the density returned with a sample equals the density
//!   recomputed from its direction; the sampling maps' Jacobians `1 / pdf`
//!   integrate over `[0, 1]^2` to the solid angle of the light (Van
//!   Oosterom–Strackee for triangles and rectangles, `2 pi (1 - cos alpha)`
//!   for spheres and coaxial disks), to 1e-12;
//! - visibility: a receiver lying on an occluder does not shadow itself, a
//!   light hidden behind another adds nothing, the back of a one-sided light
//!   is dark and blocks the environment (`E = pi L (1 - F)`);
//! - small and distant lights: a sphere of `R / d = 1e-4` by both forms to
//!   1e-10 (the cap is stored as `1 - cos theta_max`), cone samples that all
//!   hit it;
//! - round trips `invert(map(u)) = u` of the cap and BRDF-sampled maps.

use crate::common;

use std::f64::consts::PI;

use lightquad::QuadError;
use lightquad::domain::{Domain, HemisphereMap, Vec3};
use lightquad::exact::rendering::disk_coaxial;
use lightquad::quadrature::{GaussLegendre, Rule, Stratified};
use lightquad::rendering::brdf::{Ggx, Lambert, Phong};
use lightquad::rendering::cap::Cap;
use lightquad::rendering::emitter::{
    AnyEmitter, CapLight, DiskLight, Emitter, EnvironmentLight, LightSampling, RectangleLight,
    SphereLight, TriangleLight,
};
use lightquad::rendering::forms::{self, BrdfSampled, Irradiance, Reflected};
use lightquad::rendering::occluder::Occluder;
use lightquad::rendering::receiver::Receiver;
use lightquad::rendering::scene::Scene;
use rand::{RngExt, SeedableRng};

fn v(x: f64, y: f64, z: f64) -> Vec3 {
    Vec3::new(x, y, z)
}

fn rng(seed: u64) -> rand_pcg::Pcg64 {
    rand_pcg::Pcg64::seed_from_u64(seed)
}

fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

/// Solid angle of the triangle `abc` seen from the origin (Van Oosterom and
/// Strackee, IEEE Trans. Biomed. Eng. 30(2), 1983): `tan(Omega / 2) = |a .
/// (b x c)| / (|a||b||c| + (a . b)|c| + (a . c)|b| + (b . c)|a|)`.
fn triangle_solid_angle(a: Vec3, b: Vec3, c: Vec3) -> f64 {
    let (la, lb, lc) = (a.norm(), b.norm(), c.norm());
    let num = a.dot(&b.cross(&c)).abs();
    let den = la * lb * lc + a.dot(&b) * lc + a.dot(&c) * lb + b.dot(&c) * la;
    2.0 * num.atan2(den)
}

/// The lights of the sampling tests with the solid angle each subtends
/// from the origin (for the environment: the hemisphere about `+z`).
/// A named light with the solid angle it subtends.
type Light = (&'static str, AnyEmitter<f64>, f64);

/// The sphere light's centre and radius.
const SPHERE: (Vec3, f64) = (Vec3::new(1.0, 0.5, 4.0), 0.7);

fn lights() -> Result<Vec<Light>, QuadError> {
    let (o, e1, e2) = (v(-0.5, 0.2, 1.5), v(0.3, 1.1, 0.4), v(1.2, -0.2, -0.1));
    let rect = RectangleLight::new(o, e1, e2, 1.0)?;
    let rect_omega =
        triangle_solid_angle(o, o + e1, o + e1 + e2) + triangle_solid_angle(o, o + e1 + e2, o + e2);
    let (a, b, c) = (v(-0.4, -0.3, 1.2), v(0.2, 0.9, 1.0), v(1.1, -0.5, 1.4));
    let tri = TriangleLight::new(a, b, c, 1.0)?;
    let (h, r) = (2.0_f64, 1.0_f64);
    let disk = DiskLight::new(v(0.0, 0.0, h), -Vec3::z(), r, 1.0)?;
    let disk_omega = 2.0 * PI * (1.0 - h / h.hypot(r));
    let (sc, sr) = SPHERE;
    let sphere = SphereLight::new(sc, sr, 1.0)?;
    let s = sr / sc.norm();
    let sphere_omega = 2.0 * PI * s * s / (1.0 + (1.0 - s * s).sqrt());
    let alpha: f64 = 0.3;
    let cap = CapLight::new(v(0.5, 0.0, 1.0), alpha, 1.0)?;
    let cap_omega = 2.0 * PI * (1.0 - alpha.cos());
    Ok(vec![
        ("rectangle", rect.into(), rect_omega),
        ("triangle", tri.into(), triangle_solid_angle(a, b, c)),
        ("disk (coaxial)", disk.into(), disk_omega),
        ("sphere", sphere.into(), sphere_omega),
        ("cap light", cap.into(), cap_omega),
        ("environment", EnvironmentLight::new(1.0)?.into(), 2.0 * PI),
    ])
}

/// The density returned with a sample is the density [`Emitter::pdf`]
/// computes from the direction alone, and the sample's point lies on the
/// ray at its distance; for every light and both strategies.
#[test]
fn sample_density_matches_the_density_of_its_direction() -> Result<(), QuadError> {
    let x = Receiver::new(Vec3::zeros(), Vec3::z())?;
    let mut r = rng(1);
    for (name, light, _) in lights()? {
        for how in [LightSampling::Area, LightSampling::Cone] {
            let mut some = 0;
            for _ in 0..2000 {
                let u = [r.random::<f64>(), r.random::<f64>()];
                let Some(s) = light.sample(&x, how, u) else {
                    continue;
                };
                some += 1;
                let p = light.pdf(&x, how, s.wi);
                assert!(
                    rel(p, s.pdf) < 1e-9,
                    "{name} {how:?} u {u:?}: pdf {p} vs sample {}",
                    s.pdf
                );
                assert!((s.wi.norm() - 1.0).abs() < 1e-14);
                if s.distance.is_finite() {
                    assert!((x.point() + s.wi * s.distance - s.point).norm() < 1e-12);
                }
                // pdf_w = pdf_A r^2 / cos theta' for area samples.
                if let Some(pdf_area) = s.pdf_area {
                    let cos_light = -light.normal_at(s.point).dot(&s.wi);
                    let converted = pdf_area * s.distance * s.distance / cos_light;
                    assert!(
                        rel(converted, s.pdf) < 1e-12,
                        "{name}: {converted} vs {}",
                        s.pdf
                    );
                }
            }
            assert!(some > 0, "{name} {how:?}: no sample");
        }
    }
    Ok(())
}

/// `int_[0,1]^2 1 / pdf(w(u)) du` is the solid angle a sampling map covers:
/// for area sampling `|J| cos theta' / r^2`, the light's solid angle; by
/// Gauss–Legendre at 48 x 48 nodes, to 1e-12 of the closed forms.
#[test]
fn sampling_jacobians_integrate_to_the_solid_angle() -> Result<(), QuadError> {
    let x = Receiver::new(Vec3::zeros(), Vec3::z())?;
    let gl = GaussLegendre::default();
    for (name, light, omega) in lights()? {
        let est = gl.integrate(48 * 48, &mut rng(0), |u: [f64; 2]| {
            light
                .sample(&x, LightSampling::Area, u)
                .map_or(0.0, |s| 1.0 / s.pdf)
        })?;
        eprintln!(
            "{name:16} area map: solid angle rel err {:.1e}",
            rel(est.value, omega)
        );
        assert!(
            rel(est.value, omega) < 1e-12,
            "{name}: {} vs {omega}",
            est.value
        );
    }
    // The exact cones: sphere, cap light and coaxial disk.
    for (name, light, omega) in lights()? {
        if !matches!(
            light,
            AnyEmitter::Sphere(_) | AnyEmitter::Cap(_) | AnyEmitter::Disk(_)
        ) {
            continue;
        }
        let cone = light.cone(&x)?;
        assert!(rel(cone.measure(), omega) < 1e-14, "{name} cone");
    }
    Ok(())
}

/// A sphere of radius 1 at distance 1e4 (R/d = 1e-4): both forms reach
/// `E = pi L (R/d)^2 cos omega` to 1e-10 with 16 x 16 nodes, and cone
/// samples all hit it, the ones on the rim included.
#[test]
fn small_distant_sphere_light() -> Result<(), QuadError> {
    let c = v(3e3, 0.0, 4e3) * 2.0;
    let (r, l) = (1.0, 2.0);
    let light = SphereLight::new(c, r, l)?;
    let scene = Scene::new(vec![light.into()], vec![]);
    let x = Receiver::new(Vec3::zeros(), Vec3::z())?;
    let d = c.norm();
    let exact = PI * l * (r / d).powi(2) * c.z / d;
    let gl = GaussLegendre::default();
    let a = forms::area(&gl, &scene, &x, &Irradiance, 256, &mut rng(0))?;
    let h = forms::cone(&gl, &scene, &x, &Irradiance, 256, &mut rng(0))?;
    eprintln!(
        "R/d = 1e-4: R-A rel {:.1e}, R-H cone rel {:.1e}",
        rel(a.value, exact),
        rel(h.value, exact)
    );
    assert!(rel(a.value, exact) < 1e-10, "R-A {} vs {exact}", a.value);
    assert!(rel(h.value, exact) < 1e-10, "R-H {} vs {exact}", h.value);
    for i in 0..=64 {
        for u1 in [0.0, 0.5, 1.0 - 1e-12, 1.0] {
            let u = [u1, i as f64 / 64.0];
            assert!(
                light.sample(&x, LightSampling::Cone, u).is_some(),
                "cone sample {u:?} missed"
            );
        }
    }
    Ok(())
}

/// Sphere intersection from far away and grazing: the chord of a ray at
/// height `h` is `2 sqrt(R^2 - h^2)` and the entry distance `D -
/// sqrt(R^2 - h^2)` from a start at distance `D` along the ray.
#[test]
fn sphere_intersection_far_and_grazing() -> Result<(), QuadError> {
    let s = Occluder::sphere(Vec3::zeros(), 1.0)?;
    for (h, dist) in [(0.6, 1e6), (0.0, 1e3), (1.0 - 1e-8, 10.0), (0.6, 2.0)] {
        let origin = v(-dist, h, 0.0);
        let t = s
            .intersect(origin, Vec3::x(), 0.0, f64::INFINITY)
            .ok_or(QuadError::invalid("h", h, "a hit"))?;
        let half = ((1.0 - h) * (1.0 + h)).sqrt();
        let want = dist - half;
        assert!(
            (t - want).abs() < 4.0 * f64::EPSILON * dist,
            "h {h} D {dist}: {t} vs {want}"
        );
    }
    // Just outside: a miss; from inside: the exit.
    assert!(
        s.intersect(v(-5.0, 1.0 + 1e-12, 0.0), Vec3::x(), 0.0, f64::INFINITY)
            .is_none()
    );
    let t = s.intersect(Vec3::zeros(), Vec3::y(), 0.0, f64::INFINITY);
    assert_eq!(t, Some(1.0));
    // Nothing before t_min or after t_max.
    assert!(
        s.intersect(v(-5.0, 0.0, 0.0), Vec3::x(), 0.0, 3.9)
            .is_none()
    );
    assert_eq!(
        s.intersect(v(-5.0, 0.0, 0.0), Vec3::x(), 4.5, 10.0),
        Some(6.0)
    );
    Ok(())
}

/// Disks and parallelograms: hits inside, misses outside, parallel rays
/// miss; a parallelogram is hit where one of its two triangles is, at the
/// same distance.
#[test]
fn planar_intersections() -> Result<(), QuadError> {
    let disk = Occluder::disk(v(0.0, 0.0, 2.0), v(0.0, 0.0, 1.0), 1.0)?;
    assert_eq!(
        disk.intersect(Vec3::zeros(), Vec3::z(), 0.0, f64::INFINITY),
        Some(2.0)
    );
    let out = v(1.01, 0.0, 2.0).normalize();
    assert!(
        disk.intersect(Vec3::zeros(), out, 0.0, f64::INFINITY)
            .is_none()
    );
    assert!(
        disk.intersect(Vec3::zeros(), Vec3::x(), 0.0, f64::INFINITY)
            .is_none()
    );
    let (o, e1, e2) = (v(-0.7, 0.1, 1.3), v(1.1, 0.3, 0.2), v(-0.2, 0.9, 0.4));
    let rect = Occluder::rectangle(o, e1, e2)?;
    let t1 = Occluder::triangle(o, o + e1, o + e1 + e2)?;
    let t2 = Occluder::triangle(o, o + e1 + e2, o + e2)?;
    let mut r = rng(5);
    let mut hits = 0;
    for _ in 0..20000 {
        let origin = v(
            r.random_range(-2.0..2.0),
            r.random_range(-2.0..2.0),
            r.random_range(-1.0..0.0),
        );
        let target = o + e1 * r.random_range(-0.3..1.3) + e2 * r.random_range(-0.3..1.3);
        let d = (target - origin).normalize();
        let a = rect.intersect(origin, d, 0.0, f64::INFINITY);
        let b = t1.intersect(origin, d, 0.0, f64::INFINITY).or(t2.intersect(
            origin,
            d,
            0.0,
            f64::INFINITY,
        ));
        match (a, b) {
            (Some(ta), Some(tb)) => {
                hits += 1;
                assert!((ta - tb).abs() < 1e-12 * ta, "{ta} vs {tb}");
            }
            (None, None) => {}
            other => panic!("rectangle and triangles disagree: {other:?} at {origin:?} {d:?}"),
        }
    }
    assert!(hits > 5000);
    Ok(())
}

/// Watertightness: rays aimed at points of the shared edge of two triangles
/// from random origins hit at least one of them, and so do rays aimed at
/// the inner vertex of a fan of six triangles; none slips through a crack.
#[test]
fn triangles_sharing_an_edge_are_watertight() -> Result<(), QuadError> {
    let (a, b, c, d) = (
        v(-1.0, -1.0, 2.0),
        v(1.3, -0.8, 2.3),
        v(0.9, 1.1, 1.7),
        v(-1.2, 0.7, 2.1),
    );
    // Same orientation: the shared edge a-c runs a -> c in one, c -> a in the other.
    let t1 = Occluder::triangle(a, b, c)?;
    let t2 = Occluder::triangle(a, c, d)?;
    let mut r = rng(9);
    for i in 0..100_000 {
        let origin = v(
            r.random_range(-3.0..3.0),
            r.random_range(-3.0..3.0),
            r.random_range(-2.0..0.0),
        );
        let s: f64 = if i % 100 == 0 {
            [0.5, 0.25, 0.75][i % 3]
        } else {
            r.random_range(1e-9..1.0 - 1e-9)
        };
        let target = a + (c - a) * s;
        let dir = (target - origin).normalize();
        let hit = t1.intersect(origin, dir, 0.0, f64::INFINITY).is_some()
            || t2.intersect(origin, dir, 0.0, f64::INFINITY).is_some();
        assert!(
            hit,
            "ray {i} from {origin:?} toward {target:?} slipped through"
        );
    }
    // A fan of six triangles about an inner vertex p: rays aimed at p.
    let p = v(0.1, -0.2, 2.0);
    let ring: Vec<Vec3> = (0..6)
        .map(|k| {
            let phi = k as f64 * PI / 3.0 + 0.1;
            p + v(phi.cos(), phi.sin(), 0.2 * (2.0 * phi).sin())
        })
        .collect();
    let fan: Vec<Occluder> = (0..6)
        .map(|k| Occluder::triangle(p, ring[k], ring[(k + 1) % 6]))
        .collect::<Result<_, _>>()?;
    for i in 0..20_000 {
        let origin = v(
            r.random_range(-3.0..3.0),
            r.random_range(-3.0..3.0),
            r.random_range(-2.0..0.0),
        );
        let dir = (p - origin).normalize();
        let hit = fan
            .iter()
            .any(|t| t.intersect(origin, dir, 0.0, f64::INFINITY).is_some());
        assert!(
            hit,
            "ray {i} from {origin:?} toward the fan's vertex slipped through"
        );
    }
    Ok(())
}

/// A receiver lying on a floor that is an occluder sees the light as if the
/// floor were not there (the offsets keep it from shadowing itself): R-A
/// by Gauss–Legendre and R-H by stratified sampling against the closed form.
#[test]
fn receiver_on_an_occluder_does_not_shadow_itself() -> Result<(), QuadError> {
    let light = DiskLight::new(v(0.3, 0.2, 2.0), -Vec3::z(), 1.0, 1.0)?;
    let floor = Occluder::rectangle(v(-5.0, -5.0, 0.0), v(10.0, 0.0, 0.0), v(0.0, 10.0, 0.0))?;
    let scene = Scene::new(vec![light.into()], vec![floor]);
    let x = Receiver::new(v(0.3, 0.2, 0.0), Vec3::z())?;
    let exact = PI * disk_coaxial(2.0, 1.0)?;
    let a = forms::area(
        &GaussLegendre::default(),
        &scene,
        &x,
        &Irradiance,
        1024,
        &mut rng(0),
    )?;
    assert!(rel(a.value, exact) < 1e-12, "R-A {} vs {exact}", a.value);
    let h = forms::hemispherical(
        &Stratified,
        &scene,
        &x,
        &Irradiance,
        HemisphereMap::Projected,
        1 << 16,
        &mut rng(1),
    )?;
    assert!(
        (h.value - exact).abs() < 4.0 * h.error,
        "R-H {} +- {}",
        h.value,
        h.error
    );
    Ok(())
}

/// A disk light hidden behind a larger one adds nothing; the back of a
/// one-sided disk is dark and blocks the environment: `E = pi L_env (1 -
/// F)` with `F` the coaxial form factor. Both forms.
#[test]
fn lights_hide_lights_and_backs_are_dark() -> Result<(), QuadError> {
    let x = Receiver::new(Vec3::zeros(), Vec3::z())?;
    let gl = GaussLegendre::default();
    let near = DiskLight::new(v(0.0, 0.0, 1.0), -Vec3::z(), 1.0, 2.0)?;
    let far = DiskLight::new(v(0.0, 0.0, 3.0), -Vec3::z(), 0.5, 5.0)?;
    let scene = Scene::new(vec![near.into(), far.into()], vec![]);
    let exact = PI * 2.0 * disk_coaxial(1.0, 1.0)?;
    let a = forms::area(&gl, &scene, &x, &Irradiance, 1024, &mut rng(0))?;
    let h = forms::cone(&gl, &scene, &x, &Irradiance, 1024, &mut rng(0))?;
    assert!(rel(a.value, exact) < 1e-12, "R-A {}", a.value);
    assert!(rel(h.value, exact) < 1e-12, "R-H {}", h.value);
    // A disk facing away from the receiver under a uniform sky.
    let (l_env, h_disk, r_disk) = (0.7, 1.5, 1.0);
    let back = DiskLight::new(v(0.0, 0.0, h_disk), Vec3::z(), r_disk, 9.0)?;
    let scene = Scene::new(
        vec![back.into(), EnvironmentLight::new(l_env)?.into()],
        vec![],
    );
    let exact = PI * l_env * (1.0 - disk_coaxial(h_disk, r_disk)?);
    for (label, est) in [
        (
            "R-A",
            forms::area(&gl, &scene, &x, &Irradiance, 4096, &mut rng(0))?,
        ),
        (
            "R-H cone",
            forms::cone(&gl, &scene, &x, &Irradiance, 4096, &mut rng(0))?,
        ),
        (
            "R-H stratified",
            forms::hemispherical(
                &Stratified,
                &scene,
                &x,
                &Irradiance,
                HemisphereMap::Projected,
                1 << 16,
                &mut rng(0),
            )?,
        ),
    ] {
        eprintln!(
            "dark back + sky {label}: rel {:.1e} (est {:.1e})",
            rel(est.value, exact),
            est.error / exact
        );
        // The sky's integrand over the hemisphere is discontinuous at the
        // disk's outline: statistical agreement for all three.
        assert!(
            (est.value - exact).abs() < 4.0 * est.error.max(1e-15 * exact),
            "{label}: {} +- {} vs {exact}",
            est.value,
            est.error
        );
    }
    Ok(())
}

/// `invert(map(u)) = u` for the cap map (a small cone and a large visible
/// cap) and the BRDF-sampled maps of Lambert, Phong and GGX, away from the
/// poles where the azimuth is undefined.
#[test]
fn map_invert_round_trips() -> Result<(), QuadError> {
    let caps = [
        Cap::directions(v(0.3, -0.2, 1.0), 1e-7)?,
        Cap::new(v(1.0, 2.0, 3.0), v(-1.0, 0.0, 0.5), 0.7, 1.3)?,
    ];
    let x = Receiver::new(v(0.1, 0.0, 0.2), v(0.2, 0.3, 1.0))?;
    let (lambert, phong, ggx) = (Lambert::new(0.5)?, Phong::new(0.5, 40.0)?, Ggx::new(0.3)?);
    let wo = v(0.4, 0.1, 0.8);
    let mut r = rng(4);
    for _ in 0..2000 {
        let u = [r.random_range(0.01..0.99), r.random_range(0.01..0.99)];
        for cap in &caps {
            let (p, _) = cap.map(u);
            let back = cap
                .invert(&p)
                .ok_or(QuadError::invalid("u", u[0], "on the cap"))?;
            assert!(
                (back[0] - u[0]).abs() < 1e-8 && (back[1] - u[1]).abs() < 1e-9,
                "{u:?} {back:?}"
            );
        }
        let maps: [(&str, Option<[f64; 2]>, f64); 3] = [
            (
                "lambert",
                round(&BrdfSampled::new(Reflected::new(&lambert, &x, wo)?), u),
                1e-9,
            ),
            (
                "phong",
                round(&BrdfSampled::new(Reflected::new(&phong, &x, wo)?), u),
                1e-7,
            ),
            (
                "ggx",
                round(&BrdfSampled::new(Reflected::new(&ggx, &x, wo)?), u),
                1e-7,
            ),
        ];
        for (name, back, tol) in maps {
            if let Some(back) = back {
                assert!(
                    (back[0] - u[0]).abs() < tol && (back[1] - u[1]).abs() < tol,
                    "{name} {u:?} -> {back:?}"
                );
            }
        }
    }
    Ok(())
}

/// `invert(map(u))` where the map reaches a direction (`None` below the
/// horizon).
fn round<D: Domain<2, Point = Vec3>>(d: &D, u: [f64; 2]) -> Option<[f64; 2]> {
    let (w, jacobian) = d.map(u);
    if jacobian == 0.0 {
        return None;
    }
    d.invert(&w)
}

/// Chi-square goodness of fit of `light`'s sampling `how` from `x` against
/// its own density, as Mitsuba 3's and pbrt-v4's tests do, by
/// `lightquad::testing::ChiSquare`: `n` directions binned in `40 x 80`
/// cells of `(cos theta, phi)` over the whole sphere; each cell's expected
/// count by adaptive Genz–Malik on 4 x 4 boxes of it (to 0.016 samples a
/// cell, so a cell cut by the light's silhouette, where the density jumps,
/// is integrated to a small fraction of a count), one bin for the samples
/// that miss (`None`); bins expecting fewer than 5 pooled; and the
/// density's integral against the fraction of draws that gave a sample.
fn light_chi_square(
    light: &AnyEmitter<f64>,
    how: LightSampling,
    x: &Receiver,
    n: usize,
    seed: u64,
    tests: usize,
) -> Result<lightquad::testing::chi_square::Outcome, QuadError> {
    let sphere = lightquad::domain::SphericalCap::sphere(Vec3::zeros(), 1.0)?;
    lightquad::testing::ChiSquare::new(sphere)
        .cells([40, 80])
        .samples(n)
        .cubature_boxes(4)
        .cubature_tolerance(0.016)
        .tests(tests)
        .run(
            |w: &Vec3| light.pdf(x, how, *w),
            |u| light.sample(x, how, u).map(|s| s.wi),
            seed,
        )
}

/// Chi-square of a sphere light's area sampling, binned on the sphere: its
/// density in solid angle grows like `1 / cos theta'` toward the silhouette,
/// which no cell cubature integrates to a fraction of a count, but in area
/// it is the constant `pdf_area` the samples carry. Cells of `(cos, phi)`
/// about the axis toward the receiver (`40 x 80`); a point is seen from the
/// receiver where `cos > R / d`, and its expected count is `n pdf_area R^2`
/// times the cell's seen part, exactly; the rest of `n` is expected missed.
fn sphere_area_chi_square(
    centre: Vec3,
    radius: f64,
    light: &AnyEmitter<f64>,
    x: &Receiver,
    n: usize,
    seed: u64,
) -> (f64, usize, f64) {
    let (res_c, res_phi) = (40usize, 80usize);
    let to_x = x.point() - centre;
    let axis = to_x / to_x.norm();
    let seen = radius / to_x.norm();
    let t = axis.cross(&Vec3::x()).normalize();
    let b = axis.cross(&t);
    let mut observed = vec![0.0; res_c * res_phi];
    let (mut missed, mut density) = (0.0, None);
    let mut r = rng(seed);
    for _ in 0..n {
        let u = [r.random::<f64>(), r.random::<f64>()];
        let Some(s) = light.sample(x, LightSampling::Area, u) else {
            missed += 1.0;
            continue;
        };
        let pdf_area = s.pdf_area.expect("an area sample");
        assert!(
            density.is_none_or(|d: f64| (d - pdf_area).abs() <= 1e-12 * d),
            "not uniform in area: {pdf_area}"
        );
        density = Some(pdf_area);
        let q = (s.point - centre) / radius;
        let c = q.dot(&axis).clamp(-1.0, 1.0);
        let phi = q.dot(&b).atan2(q.dot(&t)).rem_euclid(2.0 * PI);
        let ic = (((c + 1.0) / 2.0 * res_c as f64) as usize).min(res_c - 1);
        let ip = ((phi / (2.0 * PI) * res_phi as f64) as usize).min(res_phi - 1);
        observed[ic * res_phi + ip] += 1.0;
    }
    let density = density.expect("some samples");
    let mut expected = vec![0.0; res_c * res_phi];
    for ic in 0..res_c {
        let (c0, c1) = (
            -1.0 + 2.0 * ic as f64 / res_c as f64,
            -1.0 + 2.0 * (ic + 1) as f64 / res_c as f64,
        );
        let seen_part = (c1 - c0.max(seen)).max(0.0);
        for ip in 0..res_phi {
            expected[ic * res_phi + ip] =
                n as f64 * density * radius * radius * seen_part * 2.0 * PI / res_phi as f64;
        }
    }
    let total: f64 = expected.iter().sum();
    assert!(
        total <= n as f64 * (1.0 + 1e-12),
        "the cells expect {total} of {n}"
    );
    common::pearson(n as f64 - total, missed, expected.into_iter().zip(observed))
}

/// A light's area and cone sampling against its density: 10^6 samples
/// each, Sidak-corrected significance 0.01 over the twelve tests of the six
/// lights (the sphere's area sampling binned on the sphere). One test per
/// light, so that each finishes in seconds.
fn light_sampling_chi_square_goodness_of_fit(light_name: &str) -> Result<(), QuadError> {
    let x = Receiver::new(Vec3::zeros(), Vec3::z())?;
    let lights = lights()?;
    let tests = 2 * lights.len();
    let threshold = 1.0 - (1.0 - 0.01_f64).powf(1.0 / tests as f64);
    let (i, (name, light, _)) = lights
        .iter()
        .enumerate()
        .find(|(_, (name, _, _))| *name == light_name)
        .expect("a light of lights()");
    for (j, how) in [LightSampling::Area, LightSampling::Cone]
        .into_iter()
        .enumerate()
    {
        let seed = 40 + 2 * i as u64 + j as u64;
        if let (AnyEmitter::Sphere(_), LightSampling::Area) = (light, how) {
            let (stat, dof, p) =
                sphere_area_chi_square(SPHERE.0, SPHERE.1, light, &x, 1_000_000, seed);
            println!("chi2 {name} {how:?}: {stat:.1} on {dof} dof, p = {p:.3}");
            assert!(
                p > threshold,
                "{name} {how:?}: chi2 = {stat} on {dof} dof, p = {p} < {threshold}"
            );
            continue;
        }
        let out = light_chi_square(light, how, &x, 1_000_000, seed, tests)?;
        println!("{name} {how:?}: {out}");
        assert!(out.passed, "{name} {how:?}: {out}");
    }
    Ok(())
}

#[test]
fn rectangle_light_sampling_chi_square_goodness_of_fit() -> Result<(), QuadError> {
    light_sampling_chi_square_goodness_of_fit("rectangle")
}

#[test]
fn triangle_light_sampling_chi_square_goodness_of_fit() -> Result<(), QuadError> {
    light_sampling_chi_square_goodness_of_fit("triangle")
}

#[test]
fn disk_light_sampling_chi_square_goodness_of_fit() -> Result<(), QuadError> {
    light_sampling_chi_square_goodness_of_fit("disk (coaxial)")
}

#[test]
fn sphere_light_sampling_chi_square_goodness_of_fit() -> Result<(), QuadError> {
    light_sampling_chi_square_goodness_of_fit("sphere")
}

#[test]
fn cap_light_sampling_chi_square_goodness_of_fit() -> Result<(), QuadError> {
    light_sampling_chi_square_goodness_of_fit("cap light")
}

#[test]
fn environment_light_sampling_chi_square_goodness_of_fit() -> Result<(), QuadError> {
    light_sampling_chi_square_goodness_of_fit("environment")
}
