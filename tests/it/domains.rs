//! Domains against independent references: closed-form areas, solid angles
//! and integrals; the inverse and the Jacobian of every map against the map
//! itself (round trip, central finite differences); and rejection of bad
//! parameters.

use lightquad::QuadError;
use lightquad::domain::{
    Disk, Domain, Frame, Hemisphere, HemisphereMap, Pixel, Rectangle, Segment, SphericalCap,
    Triangle, Vec3, integrate_over,
};
use lightquad::quadrature::{GaussLegendre, Rule};
use proptest::prelude::*;
use rand::SeedableRng;
use std::f64::consts::{E, PI};

/// Gauss–Legendre budget of the closed-form tests: 32 x 32 nodes.
const BUDGET: usize = 32 * 32;

fn rng() -> rand_pcg::Pcg64 {
    rand_pcg::Pcg64::seed_from_u64(7)
}

/// `int_domain g` with the default Gauss–Legendre rule and [`BUDGET`].
fn gl<Dom, G>(domain: &Dom, g: G) -> f64
where
    Dom: Domain<2>,
    G: FnMut(Dom::Point) -> f64,
{
    match integrate_over(&GaussLegendre::default(), domain, BUDGET, &mut rng(), g) {
        Ok(est) => est.value,
        Err(e) => panic!("integration failed: {e}"),
    }
}

#[track_caller]
fn assert_rel(got: f64, want: f64, tol: f64) {
    let rel = (got - want).abs() / want.abs();
    assert!(
        rel <= tol,
        "got {got:e}, want {want:e}: relative error {rel:e} > {tol:e}"
    );
}

fn ok<T>(r: Result<T, QuadError>) -> T {
    match r {
        Ok(t) => t,
        Err(e) => panic!("unexpected error: {e}"),
    }
}

// ---------------------------------------------------------------------------
// Closed forms with Gauss–Legendre
// ---------------------------------------------------------------------------

#[test]
fn disk_area_is_pi_r_squared() {
    let r = 1.7;
    let disk = ok(Disk::new(
        Vec3::new(1.0, -2.0, 3.0),
        Vec3::new(1.0, 1.0, 1.0),
        r,
    ));
    assert_rel(gl(&disk, |_| 1.0), PI * r * r, 1e-12);
}

#[test]
fn disk_gaussian_is_pi_one_minus_exp() {
    // int_{|x| <= R} exp(-|x|^2) dA = pi (1 - exp(-R^2)); pi (1 - 1/e) for R = 1.
    let centre = Vec3::new(0.3, 0.2, -1.0);
    let unit = ok(Disk::new(centre, Vec3::new(0.0, 2.0, -1.0), 1.0));
    assert_rel(
        gl(&unit, |p| (-(p - centre).norm_squared()).exp()),
        PI * (1.0 - 1.0 / E),
        1e-12,
    );
    let r = 1.3;
    let disk = ok(Disk::new(centre, Vec3::new(-1.0, 0.5, 0.25), r));
    assert_rel(
        gl(&disk, |p| (-(p - centre).norm_squared()).exp()),
        PI * (1.0 - (-r * r).exp()),
        1e-12,
    );
}

#[test]
fn disk_second_moment_is_pi_r4_over_4() {
    // int_disk x^2 dA = pi R^4 / 4 in the disk's plane (here z = const, so the
    // world x axis lies in the plane, independently of the disk's frame).
    let (r, centre) = (0.8, Vec3::new(0.5, -0.25, 2.0));
    let disk = ok(Disk::new(centre, Vec3::z(), r));
    assert_rel(
        gl(&disk, |p| (p.x - centre.x).powi(2)),
        PI * r.powi(4) / 4.0,
        1e-12,
    );
}

#[test]
fn rectangle_area_is_cross_product_norm() {
    // e1 x e2 = (2, 0, 1) x (0.5, 3, -1) = (-3, 2.5, 6), |.| = sqrt(51.25).
    let rect = ok(Rectangle::new(
        Vec3::new(1.0, 2.0, 3.0),
        Vec3::new(2.0, 0.0, 1.0),
        Vec3::new(0.5, 3.0, -1.0),
    ));
    assert_rel(gl(&rect, |_| 1.0), 51.25_f64.sqrt(), 1e-12);
    assert_rel(rect.measure(), 51.25_f64.sqrt(), 1e-15);
}

#[test]
fn rectangle_exp_cos_closed_form() {
    // [0, 2] x [0, 3] in the plane z = 1, edges given in the "wrong" order:
    // int_0^2 int_0^3 exp(-x) cos(y) dy dx = (1 - e^-2) sin 3.
    let rect = ok(Rectangle::new(
        Vec3::new(0.0, 3.0, 1.0),
        Vec3::new(0.0, -3.0, 0.0),
        Vec3::new(2.0, 0.0, 0.0),
    ));
    assert_rel(
        gl(&rect, |p| (-p.x).exp() * p.y.cos()),
        (1.0 - (-2.0_f64).exp()) * 3.0_f64.sin(),
        1e-12,
    );
}

#[test]
fn triangle_area_is_half_cross_product_norm() {
    // (b - a) x (c - a) = (3, 1, 0) x (1, 2, 2) = (2, -6, 5), |.| = sqrt(65).
    let a = Vec3::new(1.0, 1.0, 1.0);
    let tri = ok(Triangle::new(
        a,
        a + Vec3::new(3.0, 1.0, 0.0),
        a + Vec3::new(1.0, 2.0, 2.0),
    ));
    assert_rel(gl(&tri, |_| 1.0), 65.0_f64.sqrt() / 2.0, 1e-12);
    assert_rel(tri.measure(), 65.0_f64.sqrt() / 2.0, 1e-15);
}

#[test]
fn triangle_centroid_is_vertex_mean() {
    let (a, b, c) = (
        Vec3::new(1.0, 1.0, 1.0),
        Vec3::new(4.0, 2.0, 1.0),
        Vec3::new(2.0, 3.0, 3.0),
    );
    let tri = ok(Triangle::new(a, b, c));
    let first_moment = match integrate_over(
        &GaussLegendre::default(),
        &tri,
        BUDGET,
        &mut rng(),
        |p: Vec3| p,
    ) {
        Ok(est) => est.value,
        Err(e) => panic!("integration failed: {e}"),
    };
    let area = 65.0_f64.sqrt() / 2.0;
    let centroid = first_moment / area;
    let want = (a + b + c) / 3.0;
    for i in 0..3 {
        assert_rel(centroid[i], want[i], 1e-12);
    }
}

#[test]
fn triangle_exp_closed_form() {
    // The triangle (0,0), (1,0), (0,1) in the plane z = 2, vertices permuted:
    // int_0^1 int_0^{1-x} exp(x + y) dy dx = int_0^1 (e - e^x) dx = 1.
    let tri = ok(Triangle::new(
        Vec3::new(1.0, 0.0, 2.0),
        Vec3::new(0.0, 1.0, 2.0),
        Vec3::new(0.0, 0.0, 2.0),
    ));
    assert_rel(gl(&tri, |p| (p.x + p.y).exp()), 1.0, 1e-12);
}

#[test]
fn sphere_area_and_moments() {
    let (r, centre) = (2.5, Vec3::new(1.0, 2.0, 3.0));
    let sphere = ok(SphericalCap::sphere(centre, r));
    assert!(sphere.is_sphere());
    assert_rel(gl(&sphere, |_| 1.0), 4.0 * PI * r * r, 1e-12);
    assert_rel(sphere.measure(), 4.0 * PI * r * r, 1e-15);
    // int z^2 dA = 4 pi R^4 / 3 (about the centre).
    assert_rel(
        gl(&sphere, |p| (p.z - centre.z).powi(2)),
        4.0 * PI * r.powi(4) / 3.0,
        1e-12,
    );
    // int exp(z) dA = 2 pi R int_{-R}^{R} exp(z) dz = 4 pi R sinh R.
    assert_rel(
        gl(&sphere, |p| (p.z - centre.z).exp()),
        4.0 * PI * r * r.sinh(),
        1e-12,
    );
    // A whole sphere about a tilted axis: int x^2 dA = 4 pi R^4 / 3 as well.
    let tilted = ok(SphericalCap::new(
        centre,
        Vec3::new(1.0, -2.0, 0.5),
        r,
        -1.0,
    ));
    assert_rel(gl(&tilted, |_| 1.0), 4.0 * PI * r * r, 1e-12);
    assert_rel(
        gl(&tilted, |p| (p.x - centre.x).powi(2)),
        4.0 * PI * r.powi(4) / 3.0,
        1e-12,
    );
}

#[test]
fn cap_area_and_exp_closed_form() {
    let (r, cos_max, centre) = (1.5, 0.3, Vec3::new(-1.0, 0.0, 2.0));
    let axis = Vec3::new(0.0, 3.0, 4.0) / 5.0;
    let cap = ok(SphericalCap::new(centre, axis * 5.0, r, cos_max));
    assert_rel(gl(&cap, |_| 1.0), 2.0 * PI * r * r * (1.0 - cos_max), 1e-12);
    // int_cap exp(cos theta) dA = 2 pi R^2 int_{cos_max}^1 e^c dc.
    assert_rel(
        gl(&cap, |p| ((p - centre).dot(&axis) / r).exp()),
        2.0 * PI * r * r * (E - cos_max.exp()),
        1e-12,
    );
    // Every point is on the sphere, inside the cap.
    let mut worst: f64 = 0.0;
    gl(&cap, |p| {
        let d = p - centre;
        worst = worst.max((d.norm() - r).abs());
        assert!(d.dot(&axis) / d.norm() >= cos_max - 1e-12);
        1.0
    });
    assert!(worst < 1e-14, "off the sphere by {worst:e}");
}

#[test]
fn hemisphere_uniform_map() {
    let h = Hemisphere::uniform();
    assert_rel(gl(&h, |w| w.z), PI, 1e-12);
    assert_rel(gl(&h, |_| 1.0), 2.0 * PI, 1e-12);
    // int cos^n theta d omega = 2 pi / (n + 1).
    for n in [2, 5, 9] {
        assert_rel(gl(&h, |w| w.z.powi(n)), 2.0 * PI / (n + 1) as f64, 1e-12);
    }
    // int exp(cos theta) d omega = 2 pi (e - 1).
    assert_rel(gl(&h, |w| w.z.exp()), 2.0 * PI * (E - 1.0), 1e-12);
    // int sin^2 theta cos^2 phi d omega = pi int_0^1 (1 - c^2) dc = 2 pi / 3.
    assert_rel(gl(&h, |w| w.x * w.x), 2.0 * PI / 3.0, 1e-12);
}

#[test]
fn hemisphere_cosine_map() {
    let h = Hemisphere::cosine();
    assert_rel(gl(&h, |w| w.z), PI, 1e-12);
    // int cos^3 theta d omega = 2 pi / 4.
    assert_rel(gl(&h, |w| w.z.powi(3)), PI / 2.0, 1e-12);
    assert_eq!(h.measure(), 2.0 * PI);
}

#[test]
fn hemisphere_about_a_tilted_normal() {
    let n = Vec3::new(1.0, 2.0, -2.0) / 3.0;
    for map in [HemisphereMap::Uniform, HemisphereMap::Cosine] {
        let h = Hemisphere {
            frame: ok(Frame::from_normal(n * 3.0)),
            map,
        };
        assert_rel(
            gl(&h, |w| {
                assert!(w.dot(&n) >= 0.0 && (w.norm() - 1.0).abs() < 1e-14);
                w.dot(&n)
            }),
            PI,
            1e-12,
        );
    }
}

#[test]
fn pixel_area_and_trig_closed_form() {
    let (x0, y0, w, h) = (3.0, -2.0, 0.5, 0.25);
    let px = ok(Pixel::new(x0, y0, w, h));
    assert_rel(gl(&px, |_| 1.0), w * h, 1e-12);
    assert_rel(
        gl(&px, |[x, y]| x.sin() * y.cos()),
        (x0.cos() - (x0 + w).cos()) * ((y0 + h).sin() - y0.sin()),
        1e-12,
    );
    assert_eq!(px.centre(), [3.25, -1.875]);
}

// ---------------------------------------------------------------------------
// Inverse maps: points off the domain
// ---------------------------------------------------------------------------

#[test]
fn invert_rejects_points_off_the_domain() {
    let nan = Vec3::new(f64::NAN, 0.0, 0.0);

    let rect = ok(Rectangle::new(Vec3::zeros(), Vec3::x() * 2.0, Vec3::y()));
    assert_eq!(rect.invert(&Vec3::new(1.0, 0.5, 0.0)), Some([0.5, 0.5]));
    assert_eq!(rect.invert(&Vec3::new(2.2, 0.5, 0.0)), None);
    assert_eq!(rect.invert(&Vec3::new(1.0, -0.01, 0.0)), None);
    assert_eq!(rect.invert(&Vec3::new(1.0, 0.5, 1e-3)), None);
    assert_eq!(rect.invert(&nan), None);

    let disk = ok(Disk::new(Vec3::zeros(), Vec3::z(), 2.0));
    assert_eq!(disk.invert(&Vec3::zeros()), Some([0.0, 0.0]));
    assert_eq!(disk.invert(&Vec3::new(0.0, 2.02, 0.0)), None);
    assert_eq!(disk.invert(&Vec3::new(0.0, 1.0, 1e-3)), None);
    assert_eq!(disk.invert(&nan), None);

    let tri = ok(Triangle::new(Vec3::zeros(), Vec3::x(), Vec3::y()));
    assert_eq!(tri.invert(&Vec3::zeros()), Some([0.0, 0.0]));
    assert_eq!(tri.invert(&Vec3::new(0.6, 0.6, 0.0)), None);
    assert_eq!(tri.invert(&Vec3::new(-0.1, 0.5, 0.0)), None);
    assert_eq!(tri.invert(&Vec3::new(0.5, -0.1, 0.0)), None);
    assert_eq!(tri.invert(&Vec3::new(0.2, 0.2, 1e-3)), None);
    assert_eq!(tri.invert(&nan), None);

    let cap = ok(SphericalCap::new(Vec3::zeros(), Vec3::z(), 1.0, 0.5));
    assert!(cap.invert(&Vec3::z()).is_some());
    // cos theta = 0.4 < cos_max.
    assert_eq!(
        cap.invert(&Vec3::new((1.0_f64 - 0.16).sqrt(), 0.0, 0.4)),
        None
    );
    assert_eq!(cap.invert(&(Vec3::z() * 1.01)), None);
    assert_eq!(cap.invert(&nan), None);
    let sphere = ok(SphericalCap::sphere(Vec3::zeros(), 1.0));
    assert_eq!(sphere.invert(&-Vec3::z()), Some([1.0, 0.0]));

    let h = Hemisphere::uniform();
    assert_eq!(h.invert(&Vec3::new(0.0, 0.6, -0.8)), None);
    assert_eq!(h.invert(&(Vec3::z() * 1.01)), None);

    let px = ok(Pixel::new(0.0, 0.0, 1.0, 1.0));
    assert_eq!(px.invert(&[0.5, 0.25]), Some([0.5, 0.25]));
    assert_eq!(px.invert(&[1.01, 0.5]), None);
    assert_eq!(px.invert(&[0.5, f64::NAN]), None);
}

// ---------------------------------------------------------------------------
// Property tests
// ---------------------------------------------------------------------------

/// Interior `u`, away from the edges where a map collapses (the disk's centre,
/// the triangle's vertex `a`, the poles) and the azimuth is ill-conditioned.
fn interior() -> impl Strategy<Value = [f64; 2]> {
    [1e-3..(1.0 - 1e-3), 1e-3..(1.0 - 1e-3)]
}

/// Any `u` in the open unit square.
fn open_square() -> impl Strategy<Value = [f64; 2]> {
    let open = (0.0..1.0_f64).prop_filter("open interval", |&x| x > 0.0);
    [open.clone(), open]
}

fn point() -> impl Strategy<Value = Vec3> {
    [-10.0..10.0_f64, -10.0..10.0_f64, -10.0..10.0_f64].prop_map(Vec3::from)
}

/// A vector of length in `[0.1, 5 sqrt 3]`.
fn vector() -> impl Strategy<Value = Vec3> {
    [-5.0..5.0_f64, -5.0..5.0_f64, -5.0..5.0_f64]
        .prop_map(Vec3::from)
        .prop_filter("not too short", |v| v.norm() > 0.1)
}

/// Two vectors at an angle with `sin >= 0.05`.
fn edges() -> impl Strategy<Value = (Vec3, Vec3)> {
    (vector(), vector()).prop_filter("not nearly parallel", |(a, b)| {
        a.cross(b).norm() >= 0.05 * a.norm() * b.norm()
    })
}

fn rectangles() -> impl Strategy<Value = Rectangle> {
    (point(), edges()).prop_map(|(o, (e1, e2))| ok(Rectangle::new(o, e1, e2)))
}

fn disks() -> impl Strategy<Value = Disk> {
    (point(), vector(), 0.1..10.0_f64).prop_map(|(c, n, r)| ok(Disk::new(c, n, r)))
}

fn triangles() -> impl Strategy<Value = Triangle> {
    (point(), edges()).prop_map(|(a, (e1, e2))| ok(Triangle::new(a, a + e1, a + e1 + e2)))
}

fn caps() -> impl Strategy<Value = SphericalCap> {
    (point(), vector(), 0.1..10.0_f64, -1.0..0.9_f64).prop_map(|(c, n, r, cos_max)| {
        // Exercise the whole sphere too.
        let cos_max = if cos_max < -0.8 { -1.0 } else { cos_max };
        ok(SphericalCap::new(c, n, r, cos_max))
    })
}

fn hemispheres() -> impl Strategy<Value = Hemisphere> {
    (vector(), prop::bool::ANY).prop_map(|(n, cosine)| Hemisphere {
        frame: ok(Frame::from_normal(n)),
        map: if cosine {
            HemisphereMap::Cosine
        } else {
            HemisphereMap::Uniform
        },
    })
}

fn pixels() -> impl Strategy<Value = Pixel> {
    (
        -100.0..100.0_f64,
        -100.0..100.0_f64,
        0.01..10.0_f64,
        0.01..10.0_f64,
    )
        .prop_map(|(x, y, w, h)| ok(Pixel::new(x, y, w, h)))
}

/// `invert(map(u)) = u` to `tol` (interior `u`), and `map(invert(map(u))) =
/// map(u)` to `tol` times `size` for any `u` in the open square (where the
/// azimuth may be undefined but the point is not).
fn check_round_trip<Dom>(
    domain: &Dom,
    u: [f64; 2],
    interior: bool,
    size: f64,
    tol: f64,
) -> Result<(), TestCaseError>
where
    Dom: Domain<2, Point = Vec3>,
{
    let (p, _) = domain.map(u);
    let back = domain.invert(&p);
    prop_assert!(back.is_some(), "invert(map({u:?})) = None, p = {p:?}");
    let back = back.unwrap_or_default();
    if interior {
        for i in 0..2 {
            prop_assert!(
                (back[i] - u[i]).abs() <= tol,
                "invert(map({u:?})) = {back:?}"
            );
        }
    }
    let (q, _) = domain.map(back);
    prop_assert!(
        (q - p).norm() <= tol * size,
        "map(invert(p)) = {q:?} != p = {p:?}"
    );
    Ok(())
}

/// `|dp/du_1 x dp/du_2|` by central differences of step `h`.
fn fd_jacobian<Dom>(domain: &Dom, u: [f64; 2], h: f64) -> f64
where
    Dom: Domain<2, Point = Vec3>,
{
    let at = |a: f64, b: f64| domain.map([a, b]).0;
    let d1 = (at(u[0] + h, u[1]) - at(u[0] - h, u[1])) / (2.0 * h);
    let d2 = (at(u[0], u[1] + h) - at(u[0], u[1] - h)) / (2.0 * h);
    d1.cross(&d2).norm()
}

/// `int_{[0,1]^2} |J(u)| du` with Gauss–Legendre, 16 x 16 nodes.
fn gl_measure<Dom: Domain<2>>(domain: &Dom) -> f64 {
    match GaussLegendre::default().integrate(256, &mut rng(), |u: [f64; 2]| domain.map(u).1) {
        Ok(est) => est.value,
        Err(e) => panic!("integration failed: {e}"),
    }
}

const FD_STEP: f64 = 1e-6;
const FD_TOL: f64 = 1e-6;

fn fd_range() -> impl Strategy<Value = [f64; 2]> {
    [0.05..0.95_f64, 0.05..0.95_f64]
}

proptest! {
    #[test]
    fn rectangle_properties(rect in rectangles(), u in interior(), v in open_square(), w in fd_range()) {
        let size = rect.edge_u().norm().max(rect.edge_v().norm());
        check_round_trip(&rect, u, true, size, 1e-9)?;
        check_round_trip(&rect, v, false, size, 1e-9)?;
        let (_, jac) = rect.map(w);
        let fd = fd_jacobian(&rect, w, FD_STEP);
        prop_assert!((jac - fd).abs() <= FD_TOL * jac, "|J| = {jac}, finite difference {fd}");
        prop_assert!((gl_measure(&rect) - rect.measure()).abs() <= 1e-12 * rect.measure());
    }

    #[test]
    fn disk_properties(disk in disks(), u in interior(), v in open_square(), w in fd_range()) {
        check_round_trip(&disk, u, true, disk.radius(), 1e-8)?;
        check_round_trip(&disk, v, false, disk.radius(), 1e-8)?;
        let (p, jac) = disk.map(w);
        prop_assert!((p - disk.centre()).dot(&disk.frame().n).abs() <= 1e-12 * (1.0 + disk.centre().norm()));
        let fd = fd_jacobian(&disk, w, FD_STEP);
        prop_assert!((jac - fd).abs() <= FD_TOL * jac, "|J| = {jac}, finite difference {fd}");
        prop_assert!((gl_measure(&disk) - disk.measure()).abs() <= 1e-12 * disk.measure());
        prop_assert!((disk.measure() - PI * disk.radius().powi(2)).abs() <= 1e-14 * disk.measure());
    }

    #[test]
    fn triangle_properties(tri in triangles(), u in interior(), v in open_square(), w in fd_range()) {
        let [a, b, c] = tri.vertices();
        let size = (b - a).norm().max((c - b).norm()).max((a - c).norm());
        check_round_trip(&tri, u, true, size, 1e-8)?;
        check_round_trip(&tri, v, false, size, 1e-8)?;
        let (_, jac) = tri.map(w);
        let fd = fd_jacobian(&tri, w, FD_STEP);
        prop_assert!((jac - fd).abs() <= FD_TOL * jac, "|J| = {jac}, finite difference {fd}");
        let area = 0.5 * (b - a).cross(&(c - a)).norm();
        prop_assert!((gl_measure(&tri) - area).abs() <= 1e-12 * area);
        prop_assert!((tri.measure() - area).abs() <= 1e-12 * area);
    }

    #[test]
    fn cap_properties(cap in caps(), u in interior(), v in open_square(), w in fd_range()) {
        check_round_trip(&cap, u, true, cap.radius(), 1e-8)?;
        check_round_trip(&cap, v, false, cap.radius(), 1e-8)?;
        let (p, jac) = cap.map(w);
        let d = p - cap.centre();
        prop_assert!((d.norm() - cap.radius()).abs() <= 1e-12 * (cap.radius() + cap.centre().norm()));
        let fd = fd_jacobian(&cap, w, FD_STEP);
        prop_assert!((jac - fd).abs() <= FD_TOL * jac, "|J| = {jac}, finite difference {fd}");
        let want = 2.0 * PI * cap.radius().powi(2) * (1.0 - cap.cos_max());
        prop_assert!((gl_measure(&cap) - want).abs() <= 1e-12 * want);
        prop_assert!((cap.measure() - want).abs() <= 1e-14 * want);
    }

    #[test]
    fn hemisphere_properties(h in hemispheres(), u in interior(), v in open_square(), w in fd_range()) {
        check_round_trip(&h, u, true, 1.0, 1e-8)?;
        check_round_trip(&h, v, false, 1.0, 1e-8)?;
        let (dir, jac) = h.map(w);
        prop_assert!((dir.norm() - 1.0).abs() <= 1e-14);
        prop_assert!(dir.dot(&h.frame.n) >= 0.0);
        let fd = fd_jacobian(&h, w, FD_STEP);
        prop_assert!((jac - fd).abs() <= FD_TOL * jac, "|J| = {jac}, finite difference {fd}");
        // The cosine map's Jacobian pi / cos theta is singular at the rim, where
        // Gauss–Legendre converges only algebraically: check it on the uniform map.
        if h.map == HemisphereMap::Uniform {
            prop_assert!((gl_measure(&h) - 2.0 * PI).abs() <= 1e-12 * 2.0 * PI);
        }
        prop_assert_eq!(h.measure(), 2.0 * PI);
    }

    #[test]
    fn pixel_properties(px in pixels(), u in open_square(), w in fd_range()) {
        let (p, jac) = px.map(u);
        let back = px.invert(&p);
        prop_assert!(back.is_some());
        let back = back.unwrap_or_default();
        let [x0, y0] = px.corner();
        // Rounding of x0 + w u: a few ulps of |x0| relative to the width.
        for (i, (lo, size)) in [(x0, px.width()), (y0, px.height())].into_iter().enumerate() {
            let tol = 1e-12 + 4.0 * f64::EPSILON * (lo.abs() + size) / size;
            prop_assert!((back[i] - u[i]).abs() <= tol, "invert(map({u:?})) = {back:?}");
        }
        // The 2-D Jacobian det(dp/du) by central differences.
        let at = |a: f64, b: f64| px.map([a, b]).0;
        let h = FD_STEP;
        let (xp, xm) = (at(w[0] + h, w[1]), at(w[0] - h, w[1]));
        let (yp, ym) = (at(w[0], w[1] + h), at(w[0], w[1] - h));
        let d1 = [(xp[0] - xm[0]) / (2.0 * h), (xp[1] - xm[1]) / (2.0 * h)];
        let d2 = [(yp[0] - ym[0]) / (2.0 * h), (yp[1] - ym[1]) / (2.0 * h)];
        let fd = (d1[0] * d2[1] - d1[1] * d2[0]).abs();
        prop_assert!((jac - fd).abs() <= FD_TOL * jac, "|J| = {jac}, finite difference {fd}");
        let want = px.width() * px.height();
        prop_assert!((gl_measure(&px) - want).abs() <= 1e-12 * want);
        prop_assert!((px.measure() - want).abs() <= 1e-15 * want);
    }

    #[test]
    fn segment_properties(a in -100.0..100.0_f64, len in 0.01..100.0_f64, u in 0.0..=1.0_f64) {
        let seg = ok(Segment::new(a, a + len));
        let (t, jac) = seg.map([u]);
        let back = seg.invert(&t);
        prop_assert!(back.is_some());
        let back = back.unwrap_or_default();
        let tol = 1e-12 + 4.0 * f64::EPSILON * (a.abs() + len) / len;
        prop_assert!((back[0] - u).abs() <= tol, "invert(map({u})) = {back:?}");
        prop_assert!((jac - len).abs() <= 1e-12 * len);
        prop_assert!((seg.measure() - (seg.end() - seg.start())).abs() == 0.0);
    }
}

// ---------------------------------------------------------------------------
// Bad input
// ---------------------------------------------------------------------------

/// The error names `name` (in the variant and in the message).
#[track_caller]
fn assert_names<T: std::fmt::Debug>(r: Result<T, QuadError>, name: &str) {
    match r {
        Err(e @ QuadError::InvalidParameter { .. }) => {
            let QuadError::InvalidParameter { name: got, .. } = &e else {
                unreachable!()
            };
            assert_eq!(got, name, "error {e} names the wrong parameter");
            assert!(
                e.to_string().contains(&format!("invalid {name} =")),
                "message does not name {name}: {e}"
            );
        }
        other => panic!("expected an invalid {name}, got {other:?}"),
    }
}

#[test]
fn rectangle_rejects_bad_input() {
    let (o, x, y) = (Vec3::zeros(), Vec3::x(), Vec3::y());
    let nan = Vec3::new(0.0, f64::NAN, 0.0);
    let inf = Vec3::new(f64::INFINITY, 0.0, 0.0);
    assert_names(Rectangle::new(nan, x, y), "origin");
    assert_names(Rectangle::new(o, inf, y), "edge_u");
    assert_names(Rectangle::new(o, x, nan), "edge_v");
    assert_names(Rectangle::new(o, Vec3::zeros(), y), "edge_u");
    assert_names(Rectangle::new(o, x, Vec3::zeros()), "edge_v");
    assert_names(Rectangle::new(o, x, x * -3.0), "edge_v");
    // Finite components and a finite area: built (the length is taken
    // scaled); an area beyond f64 is refused.
    assert!(Rectangle::new(o, x * 1e200, y).is_ok());
    assert_names(Rectangle::new(o, x * 1e150, y * 1e160), "edge_v");
    assert_names(Rectangle::new(o, x * f64::MAX, y * 2.0), "edge_v");
    assert!(Rectangle::new(o, x, x + y * 1e-6).is_ok());
}

#[test]
fn disk_rejects_bad_input() {
    let c = Vec3::zeros();
    assert_names(
        Disk::new(Vec3::new(f64::NAN, 0.0, 0.0), Vec3::z(), 1.0),
        "centre",
    );
    assert_names(Disk::new(c, Vec3::zeros(), 1.0), "normal");
    assert_names(
        Disk::new(c, Vec3::new(0.0, f64::INFINITY, 1.0), 1.0),
        "normal",
    );
    for r in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert_names(Disk::new(c, Vec3::z(), r), "radius");
    }
    // Huge and tiny normals are fine: only the direction counts.
    for s in [1e-300, 1e300] {
        let disk = ok(Disk::new(c, Vec3::new(1.0, 1.0, 0.0) * s, 1.0));
        let n = disk.frame().n;
        assert!((n - Vec3::new(1.0, 1.0, 0.0) / 2.0_f64.sqrt()).norm() < 1e-15);
    }
}

#[test]
fn triangle_rejects_bad_input() {
    let (a, b, c) = (Vec3::zeros(), Vec3::x(), Vec3::y());
    assert_names(Triangle::new(Vec3::new(f64::NAN, 0.0, 0.0), b, c), "a");
    assert_names(Triangle::new(a, Vec3::new(0.0, 0.0, f64::INFINITY), c), "b");
    assert_names(
        Triangle::new(a, b, Vec3::new(0.0, f64::NEG_INFINITY, 0.0)),
        "c",
    );
    assert_names(Triangle::new(a, a, c), "b");
    assert_names(Triangle::new(a, b, b), "c");
    assert_names(Triangle::new(a, b, a), "c");
    assert_names(Triangle::new(a, b, b * 2.5), "c");
}

#[test]
fn cap_rejects_bad_input() {
    let c = Vec3::zeros();
    assert_names(
        SphericalCap::new(Vec3::new(0.0, 0.0, f64::NAN), Vec3::z(), 1.0, 0.0),
        "centre",
    );
    assert_names(SphericalCap::new(c, Vec3::zeros(), 1.0, 0.0), "axis");
    for r in [0.0, -2.0, f64::NAN] {
        assert_names(SphericalCap::new(c, Vec3::z(), r, 0.0), "radius");
        assert_names(SphericalCap::sphere(c, r), "radius");
    }
    for cos_max in [1.0, 1.5, -1.0 - 1e-12, f64::NAN, f64::INFINITY] {
        assert_names(SphericalCap::new(c, Vec3::z(), 1.0, cos_max), "cos_max");
    }
    assert!(SphericalCap::new(c, Vec3::z(), 1.0, -1.0).is_ok());
    assert!(SphericalCap::new(c, Vec3::z(), 1.0, 1.0 - 1e-9).is_ok());
}

#[test]
fn pixel_rejects_bad_input() {
    assert_names(Pixel::new(f64::NAN, 0.0, 1.0, 1.0), "x0");
    assert_names(Pixel::new(0.0, f64::INFINITY, 1.0, 1.0), "y0");
    for s in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert_names(Pixel::new(0.0, 0.0, s, 1.0), "width");
        assert_names(Pixel::new(0.0, 0.0, 1.0, s), "height");
    }
    assert_names(Pixel::new(f64::MAX, 0.0, f64::MAX, 1.0), "width");
}

#[test]
fn segment_break_points_make_a_kink_exact_and_bad_segments_are_named() {
    use lightquad::domain::Segment;
    // int_0^2 |t - 1| dt = 1: exact with 2 Gauss nodes per smooth piece when
    // the kink is a break point, not without it.
    let rule = GaussLegendre::default();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
    let f = |t: f64| (t - 1.0).abs();
    let with = Segment::with_breaks(0.0, 2.0, vec![1.0])
        .expect("valid")
        .integrate(&rule, 2, &mut rng, f)
        .expect("finite");
    assert!((with.value - 1.0).abs() < 1e-15, "{}", with.value);
    let without = Segment::new(0.0, 2.0)
        .expect("valid")
        .integrate(&rule, 2, &mut rng, f)
        .expect("finite");
    assert!((without.value - 1.0).abs() > 1e-3);

    let e = Segment::new(1.0, 0.0).expect_err("reversed");
    assert!(
        e.to_string().contains("invalid b = 0") && e.to_string().contains("b >= a"),
        "{e}"
    );
    let e = Segment::new(f64::NAN, 1.0).expect_err("NaN");
    assert!(e.to_string().contains("invalid a = NaN"), "{e}");
    let e = Segment::new(0.0, f64::INFINITY).expect_err("infinite");
    assert!(e.to_string().contains("invalid b = inf"), "{e}");
    let e = Segment::with_breaks(0.0, 1.0, vec![0.5, 2.0]).expect_err("outside");
    assert!(e.to_string().contains("breaks[1] = 2"), "{e}");
}

#[test]
fn projected_hemisphere_lets_every_rule_integrate_cosine_weighted_integrands() {
    use lightquad::domain::Hemisphere;
    use lightquad::quadrature::AnyRule;
    // int cos(theta) d omega = pi as int 1 in projected solid angle; the
    // trapezoid rule has nodes on the rim, where the Cosine map's Jacobian is
    // infinite.
    let h = Hemisphere::projected();
    assert!((h.measure() - PI).abs() < 1e-15);
    for name in [
        "trapezoid",
        "gauss-legendre",
        "product(gauss-legendre,trapezoid)",
    ] {
        let rule = AnyRule::by_name(name).expect("known");
        let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
        let one = integrate_over(&rule, &h, 33 * 33, &mut rng, |_| 1.0).expect("finite");
        assert!((one.value - PI).abs() < 1e-12, "{name}: {}", one.value);
        // int sin^2(theta) cos(theta) d omega = pi / 2: g = 1 - z^2 = u_1 is
        // linear in the map's coordinate, so every rule here is exact.
        let s2 = integrate_over(&rule, &h, 33 * 33, &mut rng, |w: Vec3| 1.0 - w.z * w.z)
            .expect("finite");
        assert!((s2.value - PI / 2.0).abs() < 1e-12, "{name}: {}", s2.value);
    }
}

/// A domain whose measure overflows f64 is refused by its constructor, with
/// the reason: a disk of radius 1e200 and the segment [-f64::MAX, f64::MAX]
/// were built, and every integral over them then blamed an integrand that
/// returned 1.0; a rectangle of edges 1e200
/// was called "not of finite length", a triangle with a vertex at f64::MAX
/// "not distinct from a".
#[test]
fn domains_whose_measure_overflows_are_refused_with_the_reason() {
    let says = |r: Result<(), QuadError>, field: &str, what: &str| {
        let e = r.expect_err("refused").to_string();
        assert!(e.contains(field) && e.contains(what), "{e}");
    };
    says(
        Disk::new(Vec3::zeros(), Vec3::z(), 1e200).map(|_| ()),
        "radius",
        "area pi R^2 is finite",
    );
    says(
        Segment::new(-f64::MAX, f64::MAX).map(|_| ()),
        "b",
        "length b - a is finite",
    );
    says(
        Rectangle::new(
            Vec3::zeros(),
            Vec3::new(1e200, 0.0, 0.0),
            Vec3::new(0.0, 1e200, 0.0),
        )
        .map(|_| ()),
        "edge_v",
        "area |edge_u x edge_v| is finite",
    );
    says(
        Triangle::new(
            Vec3::zeros(),
            Vec3::new(f64::MAX, 0.0, 0.0),
            Vec3::new(0.0, 4.0, 0.0),
        )
        .map(|_| ()),
        "c",
        "edges and area are finite",
    );
    // Large but representable domains are still built.
    assert!(Disk::new(Vec3::zeros(), Vec3::z(), 1e150).is_ok());
    assert!(Segment::new(-1e307, 1e307).is_ok());
}
