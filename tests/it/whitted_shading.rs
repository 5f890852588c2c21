//! Whitted's illumination model (src/whitted/shade.rs, intersect.rs)
//! against references computed here.
//!
//! Layers: (1) W-6.1 with W-Phong at single hits whose every term is
//! derived in the test from the formula with explicit numbers (ambient,
//! Lambert, the Phong highlight, a shadow, a mirror ray to the background,
//! a transmitted ray); (2) the directions against Snell's law written as
//! sines, and total internal reflection on either side of the critical
//! angle `asin(1 / ior)`; (3) the rays traced by kind, none of a kind the
//! scene does not need; (4) robustness: rays spawned from hits on spheres,
//! planes and triangles at coordinates up to 1e6 and at grazing angles
//! never meet their own surface again, and a ray through the shared edge
//! of two triangles meets one of them.

use lightquad::domain::Vec3;
use lightquad::value::Rgb;
use lightquad::whitted::intersect::{Ray, Shape};
use lightquad::whitted::scene::{Camera, Light, Material, Object, Scene};
use lightquad::whitted::shade::{RayCount, reflect, refract, trace};
use rand::{RngExt, SeedableRng};

fn v3(x: f64, y: f64, z: f64) -> Vec3 {
    Vec3::new(x, y, z)
}

fn white(x: f64) -> Rgb {
    Rgb::new(x, x, x)
}

fn camera() -> Camera {
    Camera::new(v3(0.0, 0.0, 5.0), -Vec3::z(), Vec3::y(), 60.0, 1, 1).expect("camera")
}

fn scene(objects: Vec<Object>, lights: Vec<Light>, ambient: Rgb, depth: usize) -> Scene {
    Scene::new(
        objects,
        lights,
        ambient,
        Rgb::new(0.2, 0.3, 0.4),
        camera(),
        depth,
    )
    .expect("scene")
}

fn floor(m: Material) -> Object {
    Object {
        shape: Shape::plane(Vec3::zeros(), Vec3::z()).expect("plane"),
        material: m,
    }
}

fn close(a: Rgb, b: Rgb, tol: f64) {
    assert!((a - b).amax() <= tol, "{a:?} vs {b:?}");
}

// ------------------------------------------------------- (1) W-6.1 values

/// A floor seen from above at 30 degrees from the normal, a point light at
/// 60 degrees on the far side: every term of W-6.1 and W-Phong by hand.
#[test]
fn w61_with_phong_at_one_hit_is_the_formula_with_its_numbers() {
    let m = Material {
        k_a: 0.1,
        k_d: 0.6,
        k_s: 0.3,
        k_t: 0.0,
        phong: 8.0,
        ior: 1.0,
        colour: Rgb::new(1.0, 0.5, 0.25),
    };
    // The eye ray hits the origin from direction A = (-sin 30, 0, cos 30).
    let (s30, c30) = (0.5_f64, 3f64.sqrt() / 2.0);
    let eye = v3(-2.0 * s30, 0.0, 2.0 * c30);
    // The light at 60 degrees from the normal, on the far side in x.
    let (s60, c60) = (3f64.sqrt() / 2.0, 0.5_f64);
    let light = Light::point(v3(4.0 * s60, 0.0, 4.0 * c60), Rgb::new(2.0, 1.0, 0.5)).expect("l");
    // max_depth 0: no mirror ray, the terms at the hit alone.
    let sc = scene(vec![floor(m)], vec![light], Rgb::new(0.5, 0.5, 0.5), 0);
    let mut rays = RayCount::default();
    let got = trace(&sc, &Ray::new(eye, -eye / eye.norm()), 0, &mut rays);
    // N . L = cos 60 = 0.5. R_q = 2 (N.L) N - L = (-sin 60, 0, cos 60);
    // R_q . A = sin 60 sin 30 + cos 60 cos 30 = cos(30) = 0.8660254...
    let r_dot_a: f64 = s60 * s30 + c60 * c30;
    let want =
        |ia: f64, iq: f64, c: f64| ia * 0.1 * c + iq * (0.6 * c * 0.5 + 0.3 * r_dot_a.powf(8.0));
    let expected = Rgb::new(
        want(0.5, 2.0, 1.0),
        want(0.5, 1.0, 0.5),
        want(0.5, 0.5, 0.25),
    );
    close(got, expected, 1e-14);
    // 0.05 + 2 (0.3 + 0.3 * 0.31640625) = 0.839843...: the numbers spelled out.
    assert!((expected.x - (0.05 + 2.0 * (0.3 + 0.3 * 0.75f64.powi(4)))).abs() < 1e-14);
    assert_eq!((rays.primary, rays.shadow), (1, 1));
}

/// A Phong exponent of 0 is legal, the constant lobe: `max(0, R . A)^0 =
/// 1`, so the highlight is `k_s I` also where the mirror direction turns
/// away from the viewer (IEEE's `0^0 = 1`), as documented on `Material`.
#[test]
fn a_phong_exponent_of_zero_is_a_constant_lobe() {
    let m = Material {
        k_a: 0.0,
        k_d: 0.6,
        k_s: 0.3,
        k_t: 0.0,
        phong: 0.0,
        ior: 1.0,
        colour: Rgb::new(1.0, 1.0, 1.0),
    };
    // The eye at 30 degrees and the light at 70 degrees on the same side:
    // R_q . A = cos(100 degrees) < 0.
    let (s30, c30) = (0.5_f64, 3f64.sqrt() / 2.0);
    let eye = v3(2.0 * s30, 0.0, 2.0 * c30);
    let (s70, c70) = (70f64.to_radians().sin(), 70f64.to_radians().cos());
    let light = Light::point(v3(4.0 * s70, 0.0, 4.0 * c70), white(1.0)).expect("l");
    let r_dot_a = -s70 * s30 + c70 * c30;
    assert!(r_dot_a < -0.17);
    let sc = scene(vec![floor(m)], vec![light], white(0.0), 0);
    let mut rays = RayCount::default();
    let got = trace(&sc, &Ray::new(eye, -eye / eye.norm()), 0, &mut rays);
    close(got, white(0.6 * c70 + 0.3), 1e-14);
}

/// A sphere between the hit and the light: `S_q = 0`, the ambient term only.
#[test]
fn a_shadowed_hit_keeps_only_the_ambient_term() {
    let m = Material {
        k_a: 0.2,
        k_d: 0.8,
        ..Material::default()
    };
    let blocker = Object {
        shape: Shape::sphere(v3(0.0, 0.0, 2.0), 0.5).expect("sphere"),
        material: m,
    };
    let light = Light::point(v3(0.0, 0.0, 4.0), white(1.0)).expect("light");
    let sc = scene(vec![floor(m), blocker], vec![light], white(1.0), 0);
    let mut rays = RayCount::default();
    // Look at the floor at (0.1, 0, 0) from the side, below the blocker.
    let target = v3(0.1, 0.0, 0.0);
    let eye = v3(3.0, 0.0, 1.0);
    let got = trace(
        &sc,
        &Ray::new(eye, (target - eye).normalize()),
        0,
        &mut rays,
    );
    close(got, white(0.2), 1e-15);
    assert_eq!(rays.shadow, 1);
    // The light moved aside: lit, 0.2 + 0.8 cos(theta) with the new angle.
    let aside = v3(3.0, 0.0, 3.0);
    let light = Light::point(aside, white(1.0)).expect("light");
    let sc = scene(sc.objects.clone(), vec![light], white(1.0), 0);
    let got = trace(
        &sc,
        &Ray::new(eye, (target - eye).normalize()),
        0,
        &mut rays,
    );
    let l = (aside - target).normalize();
    close(got, white(0.2 + 0.8 * l.z), 1e-14);
}

/// A perfect mirror floor under a background of (0.2, 0.3, 0.4): the eye
/// sees `k_s I_r` = `k_s` times the background, plus the ambient term; a
/// second bounce is cut at `max_depth`.
#[test]
fn the_mirror_ray_adds_k_s_times_what_it_sees() {
    let m = Material {
        k_a: 0.1,
        k_d: 0.0,
        k_s: 0.7,
        ..Material::default()
    };
    let sc = scene(vec![floor(m)], vec![], white(1.0), 3);
    let mut rays = RayCount::default();
    let d = v3(1.0, 0.0, -1.0).normalize();
    let got = trace(&sc, &Ray::new(v3(0.0, 0.0, 1.0), d), 0, &mut rays);
    close(got, white(0.1) + Rgb::new(0.2, 0.3, 0.4) * 0.7, 1e-15);
    assert_eq!(
        (rays.primary, rays.reflection, rays.shadow, rays.refraction),
        (1, 1, 0, 0)
    );
    // Depth 0: no mirror ray at all.
    let sc0 = scene(sc.objects.clone(), vec![], white(1.0), 0);
    let mut rays = RayCount::default();
    let got = trace(&sc0, &Ray::new(v3(0.0, 0.0, 1.0), d), 0, &mut rays);
    close(got, white(0.1), 1e-15);
    assert_eq!(rays.reflection, 0);
}

/// A glass slab (the half-space below a plane, ior 1.5, k_t = 1) seen at
/// normal incidence: the transmitted ray goes straight down and escapes to
/// the background; nothing else is added.
#[test]
fn the_transmitted_ray_adds_k_t_times_what_it_sees() {
    let glass = Material {
        k_a: 0.0,
        k_d: 0.0,
        k_t: 1.0,
        ior: 1.5,
        ..Material::default()
    };
    let sc = scene(vec![floor(glass)], vec![], white(1.0), 2);
    let mut rays = RayCount::default();
    let got = trace(&sc, &Ray::new(v3(0.0, 0.0, 1.0), -Vec3::z()), 0, &mut rays);
    close(got, Rgb::new(0.2, 0.3, 0.4), 1e-15);
    assert_eq!((rays.refraction, rays.reflection), (1, 0));
}

// ------------------------------------------- (2) Snell's law and TIR

/// For incidence angles across (0, 90) degrees and indices 1.0003 to 2.4,
/// the refracted direction is unit, in the plane of incidence, and obeys
/// `eta_1 sin theta_1 = eta_2 sin theta_2` (sines from cross products);
/// the mirror direction keeps the angle.
#[test]
fn refraction_obeys_snells_law_and_reflection_keeps_the_angle() {
    let n = v3(0.0, 0.0, 1.0);
    for &ior in &[1.0003, 1.33, 1.5, 2.4] {
        for k in 1..90 {
            let theta = (k as f64).to_radians();
            let d = v3(theta.sin(), 0.3 * theta.sin(), -theta.cos()).normalize();
            let sin1 = d.cross(&n).norm();
            let t = refract(d, n, 1.0 / ior).expect("entering never reflects totally");
            assert!((t.norm() - 1.0).abs() < 1e-14);
            let sin2 = t.cross(&n).norm();
            assert!((sin1 - ior * sin2).abs() < 1e-14, "ior {ior}, {k} deg");
            // In the plane of incidence, bent toward the normal, going down.
            assert!(d.cross(&n).normalize().dot(&t).abs() < 1e-14);
            assert!(t.z < 0.0 && sin2 <= sin1);
            let r = reflect(d, n);
            assert!((r.z + d.z).abs() < 1e-15 && (r.x - d.x).abs() < 1e-15);
        }
    }
}

/// Leaving glass of index 1.5: the critical angle is `asin(1/1.5)`; a ray
/// a hair inside it refracts (grazing, `sin theta_2 ~ 1`), one a hair
/// beyond it is totally reflected, and the tracer then sends `k_t` along
/// the mirror direction.
#[test]
fn total_internal_reflection_starts_at_the_critical_angle() {
    let ior = 1.5_f64;
    let critical = (1.0 / ior).asin();
    let n = Vec3::z(); // turned toward the incoming ray (inside the glass, below)
    let at = |theta: f64| v3(theta.sin(), 0.0, -theta.cos());
    let below = refract(at(critical - 1e-9), n, ior).expect("refracts");
    assert!(below.cross(&n).norm() > 1.0 - 1e-7, "grazing: {below:?}");
    assert!(refract(at(critical + 1e-9), n, ior).is_none());
    // Through the tracer: glass below z = 0, a ray from inside at 60
    // degrees (beyond the critical 41.8) reflects totally: it goes down
    // again and escapes to the background as a reflection ray.
    let glass = Material {
        k_a: 0.0,
        k_d: 0.0,
        k_t: 0.9,
        ior,
        ..Material::default()
    };
    let sc = scene(vec![floor(glass)], vec![], white(1.0), 2);
    let mut rays = RayCount::default();
    let steep = 60f64.to_radians();
    let d = v3(steep.sin(), 0.0, steep.cos());
    let got = trace(&sc, &Ray::new(v3(0.0, 0.0, -1.0), d), 0, &mut rays);
    close(got, Rgb::new(0.2, 0.3, 0.4) * 0.9, 1e-15);
    assert_eq!((rays.reflection, rays.refraction), (1, 0));
    // At 30 degrees (inside the critical angle) it refracts out instead.
    let mut rays = RayCount::default();
    let mild = 30f64.to_radians();
    let d = v3(mild.sin(), 0.0, mild.cos());
    trace(&sc, &Ray::new(v3(0.0, 0.0, -1.0), d), 0, &mut rays);
    assert_eq!((rays.reflection, rays.refraction), (0, 1));
}

// ------------------------------------------------ (3) rays left out

/// Rays a scene does not need are not traced: no lights, no shadow rays;
/// k_s = 0, no reflection rays; k_t = 0, no refraction rays. A glass sphere
/// in front of a mirror under a light traces all four kinds.
#[test]
fn only_the_rays_a_scene_needs_are_traced() {
    let d = v3(0.0, 0.0, -1.0);
    let from = v3(0.0, 0.0, 5.0);
    let ball = |m: Material| Object {
        shape: Shape::sphere(Vec3::zeros(), 1.0).expect("sphere"),
        material: m,
    };
    let diffuse = Material::default();
    let light = Light::directional(v3(0.0, 0.0, 1.0), white(1.0)).expect("light");
    let count = |sc: &Scene| {
        let mut r = RayCount::default();
        trace(sc, &Ray::new(from, d), 0, &mut r);
        r
    };
    let unlit = scene(vec![ball(diffuse)], vec![], white(1.0), 5);
    assert_eq!(
        count(&unlit),
        RayCount {
            primary: 1,
            ..RayCount::default()
        }
    );
    let lit = scene(vec![ball(diffuse)], vec![light], white(1.0), 5);
    assert_eq!(
        count(&lit),
        RayCount {
            primary: 1,
            shadow: 1,
            ..RayCount::default()
        }
    );
    let glass = Material {
        k_s: 0.1,
        k_t: 0.8,
        ior: 1.5,
        ..Material::default()
    };
    let mirror = Object {
        shape: Shape::plane(v3(0.0, 0.0, -3.0), Vec3::z()).expect("plane"),
        material: Material {
            k_s: 0.9,
            k_d: 0.0,
            ..Material::default()
        },
    };
    let full = scene(vec![ball(glass), mirror], vec![light], white(1.0), 3);
    let r = count(&full);
    assert!(
        r.shadow > 0 && r.reflection > 0 && r.refraction > 0,
        "{r:?}"
    );
}

// --------------------------------------------------- (4) robustness

/// Rays spawned from hits on spheres, planes and triangles, at scales from
/// 1e-3 to 1e6 from the origin, toward random directions on either side
/// (grazing ones included: `w . n` down to 1e-12), and along the mirror
/// direction, never meet the surface they start on (each shape is convex
/// seen from the side they leave to); 20000 spawns per shape and scale.
#[test]
fn spawned_rays_never_meet_their_own_surface() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
    let mut spurious = 0;
    let mut checked = 0;
    for &scale in &[1e-3, 1.0, 1e3, 1e6] {
        let c = v3(scale, -0.7 * scale, 0.3 * scale);
        let shapes = [
            Shape::sphere(c, 0.01 * scale.max(1.0)).expect("sphere"),
            Shape::plane(c, v3(0.3, -1.0, 0.2)).expect("plane"),
            Shape::triangle(c, c + v3(1.0, 0.2, 0.0), c + v3(0.1, 0.9, 0.4)).expect("tri"),
        ];
        for shape in shapes {
            for _ in 0..20000 {
                // A ray from outside toward a random point near the shape.
                let target = match shape {
                    Shape::Triangle { vertices, .. } => {
                        let (a, b) = (rng.random::<f64>(), rng.random::<f64>());
                        let (a, b) = if a + b > 1.0 {
                            (1.0 - a, 1.0 - b)
                        } else {
                            (a, b)
                        };
                        vertices[0]
                            + (vertices[1] - vertices[0]) * a
                            + (vertices[2] - vertices[0]) * b
                    }
                    Shape::Sphere { centre, radius } => {
                        centre
                            + v3(rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5, 1.0)
                                * radius
                                * 0.9
                    }
                    Shape::Plane { point, .. } => {
                        point
                            + v3(
                                rng.random::<f64>(),
                                rng.random::<f64>(),
                                rng.random::<f64>(),
                            )
                    }
                };
                let from = target
                    + v3(rng.random::<f64>() - 0.5, 2.0, rng.random::<f64>() - 0.5)
                        * scale.max(1.0);
                let Some(hit) = shape.intersect(&Ray::new(from, target - from)) else {
                    continue;
                };
                // Leaving: a direction on the ray's side, often grazing.
                let n = if (from - hit.point).dot(&hit.normal) > 0.0 {
                    hit.normal
                } else {
                    -hit.normal
                };
                let tangent = n.cross(&v3(0.37, 0.55, -0.2)).normalize();
                let lift = 10f64.powf(-12.0 * rng.random::<f64>());
                let out = (tangent + n * lift).normalize();
                checked += 1;
                if shape.intersect(&hit.spawn(out)).is_some() {
                    spurious += 1;
                }
                // The mirror direction leaves too.
                let r = reflect((target - from).normalize(), n);
                if shape.intersect(&hit.spawn(r)).is_some() {
                    spurious += 1;
                }
            }
        }
    }
    assert!(checked > 150_000, "{checked}");
    assert_eq!(spurious, 0, "self-intersections out of {checked}");
}

/// A ray through the shared edge of two triangles (or a shared vertex)
/// meets at least one of them: the watertight test leaves no crack.
#[test]
fn a_ray_through_a_shared_edge_meets_one_of_the_triangles() {
    let a = v3(-1.0, -1.0, 0.0);
    let b = v3(1.0, 1.0, 0.0);
    let t1 = Shape::triangle(a, v3(1.0, -1.0, 0.0), b).expect("t1");
    let t2 = Shape::triangle(a, b, v3(-1.0, 1.0, 0.0)).expect("t2");
    let mut rng = rand_pcg::Pcg64::seed_from_u64(3);
    for _ in 0..100_000 {
        let s: f64 = rng.random();
        let on_edge = a + (b - a) * s;
        let from = v3(
            rng.random::<f64>() * 4.0 - 2.0,
            rng.random::<f64>() * 4.0 - 2.0,
            3.0,
        );
        let ray = Ray::new(from, on_edge - from);
        assert!(
            t1.intersect(&ray).is_some() || t2.intersect(&ray).is_some(),
            "a crack at {on_edge:?} from {from:?}"
        );
    }
}

/// A ray tangent to a sphere (grazing it at one point) and rays a hair
/// inside and outside: the discriminant's form keeps them apart where the
/// difference of squares would not (a sphere of radius 1 at 1e6).
#[test]
fn grazing_rays_meet_a_distant_sphere_where_they_should() {
    let sphere = Shape::sphere(v3(0.0, 0.0, 0.0), 1.0).expect("sphere");
    let from = v3(-1e6, 0.0, 0.0);
    for (y, hits) in [(1.0 - 1e-6, true), (1.0 + 1e-6, false), (0.999, true)] {
        let ray = Ray::new(from + v3(0.0, y, 0.0), Vec3::x());
        assert_eq!(sphere.intersect(&ray).is_some(), hits, "height {y}");
        if let Some(h) = sphere.intersect(&ray) {
            // The hit at x = -sqrt(1 - y^2).
            let want = -(1.0 - y * y).sqrt();
            assert!((h.point.x - want).abs() < 1e-9, "{} vs {want}", h.point.x);
        }
    }
}
