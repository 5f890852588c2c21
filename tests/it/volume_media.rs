//! The linear-gradient sphere and the voxel grid against independent
//! references: line integrals derived by hand, the medium's closed form,
//! brute-force composite quadrature, and each other (Gauss–Legendre with 2
//! nodes per smooth piece is exact for their piecewise-linear and
//! piecewise-cubic densities along a ray).

use lightquad::domain::{Segment, Vec3};
use lightquad::error::QuadError;
use lightquad::geometry::Ray;
use lightquad::quadrature::GaussLegendre;
use lightquad::volume::{
    ConstantSphere, DepthScheme, LinearGradient, Medium, ShadowMethod, VolumeScene, VoxelGrid,
    evaluate,
};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64;
use std::sync::Arc;

fn rng(seed: u64) -> Pcg64 {
    Pcg64::seed_from_u64(seed)
}

/// Relative difference `|a - b| / |b|` (absolute when b = 0).
fn rel(a: f64, b: f64) -> f64 {
    if b == 0.0 {
        (a - b).abs()
    } else {
        ((a - b) / b).abs()
    }
}

/// Gauss–Legendre without the error estimate, so `n` is exactly the number of
/// nodes per smooth piece.
fn gl() -> GaussLegendre {
    GaussLegendre {
        error_estimate: false,
    }
}

fn ray(origin: [f64; 3], dir: [f64; 3]) -> Ray {
    Ray::new(Vec3::from(origin), Vec3::from(dir)).expect("valid ray")
}

/// The optical depth `int v_r dt` over `[t_min, t_max]` (lambda = 1) by
/// `evaluate` with `n` Gauss–Legendre nodes per smooth piece.
fn depth(medium: Arc<dyn Medium>, ray: Ray, t_min: f64, t_max: f64, n: usize) -> f64 {
    let mut scene = VolumeScene::new(ray);
    scene.medium = Some(medium);
    scene.t_min = t_min;
    scene.t_max = t_max;
    evaluate(
        &scene,
        &gl(),
        n,
        DepthScheme::Cumulative,
        ShadowMethod::ClosedFormWhereAvailable,
        &mut rng(0),
    )
    .expect("finite")
    .optical_depth
    .value
}

/// Brute-force reference: the composite midpoint rule with `m` panels over
/// `[a, b]`, blind to break points and supports (error O(m^-2) at kinks).
fn midpoint(medium: &dyn Medium, ray: &Ray, a: f64, b: f64, m: usize) -> f64 {
    let h = (b - a) / m as f64;
    (0..m)
        .map(|i| medium.density(ray.at(a + (i as f64 + 0.5) * h)))
        .sum::<f64>()
        * h
}

fn random_unit(r: &mut Pcg64) -> Vec3 {
    loop {
        let v = Vec3::new(
            2.0 * r.random::<f64>() - 1.0,
            2.0 * r.random::<f64>() - 1.0,
            2.0 * r.random::<f64>() - 1.0,
        );
        let n = v.norm();
        if n > 0.1 && n <= 1.0 {
            return v / n;
        }
    }
}

fn invalid_name(err: QuadError) -> String {
    match err {
        QuadError::InvalidParameter { name, .. } => name,
        other => panic!("expected InvalidParameter, got {other:?}"),
    }
}

// ---------------------------------------------------------------- linear gradient

#[test]
fn linear_gradient_along_the_ray_through_the_centre_integrates_to_2_r_base() {
    // Gradient k d along the ray: v = b0 + k s on s in [-R, R] (positive since
    // b0 > k R), and the odd part integrates to zero: tau = 2 R b0 = 8.
    let c = Vec3::new(1.0, -2.0, 0.5);
    let d = Vec3::new(1.0, 2.0, 2.0) / 3.0;
    let (r, k, b0) = (2.0, 0.75, 2.0);
    let medium = LinearGradient::new(c, r, b0, d * k).expect("valid");
    let ray = Ray::new(c - d * 5.0, d).expect("valid");
    let want = 2.0 * r * b0;
    let closed = medium
        .density_integral(&ray, 0.0, f64::INFINITY)
        .expect("closed form");
    assert!(rel(closed, want) < 1e-15, "closed form {closed}");
    let quad = depth(Arc::new(medium), ray, 0.0, f64::INFINITY, 2);
    assert!(rel(quad, want) < 1e-14, "GL(2) {quad}");
    assert!(rel(quad, closed) < 1e-14);
}

#[test]
fn linear_gradient_off_centre_with_a_transverse_gradient() {
    // Ray along x at height h = 0.6 through the unit sphere: x in [-0.8, 0.8],
    // v = 1 + 0.5 x + 2 h = 2.2 + 0.5 x > 0, so tau = 1.6 * 2.2 = 3.52.
    let medium =
        LinearGradient::new(Vec3::zeros(), 1.0, 1.0, Vec3::new(0.5, 2.0, -1.0)).expect("valid");
    let ray = ray([-3.0, 0.6, 0.0], [1.0, 0.0, 0.0]);
    let want = 1.6 * 2.2;
    let closed = medium
        .density_integral(&ray, 0.0, f64::INFINITY)
        .expect("closed");
    assert!(rel(closed, want) < 1e-15, "{closed}");
    let quad = depth(Arc::new(medium), ray, 0.0, f64::INFINITY, 2);
    assert!(rel(quad, want) < 1e-14, "{quad}");
    // Over part of the chord, [t = 2.5, 3.5] i.e. x in [-0.5, 0.5]: 1 * 2.2.
    let part = medium.density_integral(&ray, 2.5, 3.5).expect("closed");
    assert!(rel(part, 2.2) < 1e-15);
    assert!(rel(depth(Arc::new(medium), ray, 2.5, 3.5, 2), 2.2) < 1e-14);
}

#[test]
fn linear_gradient_zero_crossing_cuts_the_support_and_two_nodes_stay_exact() {
    // Unit sphere, v = max(0, 0.5 + 2 x): zero at x = -1/4, so along the
    // x axis tau = int_{-1/4}^{1} (0.5 + 2x) dx = (b0 + kR)^2 / (2k) = 1.5625.
    let medium =
        LinearGradient::new(Vec3::zeros(), 1.0, 0.5, Vec3::new(2.0, 0.0, 0.0)).expect("valid");
    let want = 2.5f64 * 2.5 / 4.0;
    // Forward: the density rises along the ray; support [2.75, 4].
    let fwd = ray([-3.0, 0.0, 0.0], [1.0, 0.0, 0.0]);
    // Backward: it falls along the ray; support [2, 3.25].
    let back = ray([3.0, 0.0, 0.0], [-1.0, 0.0, 0.0]);
    for (r, (a, b)) in [(fwd, (2.75, 4.0)), (back, (2.0, 3.25))] {
        let support = medium.support(&r, 0.0, f64::INFINITY);
        assert_eq!(support.len(), 1);
        assert!((support[0].start() - a).abs() < 1e-15 && (support[0].end() - b).abs() < 1e-15);
        let closed = medium
            .density_integral(&r, 0.0, f64::INFINITY)
            .expect("closed");
        assert!(rel(closed, want) < 1e-15, "{closed}");
        let quad = depth(Arc::new(medium), r, 0.0, f64::INFINITY, 2);
        assert!(rel(quad, want) < 1e-14, "{quad}");
        // The majorant: the value at the chord's high end, 0.5 + 2 = 2.5.
        let bar = medium.max_density(&r, 0.0, f64::INFINITY);
        assert!(bar >= 2.5 && bar - 2.5 < 1e-13, "{bar}");
    }
    // Without the cut the kink would sit inside the piece and GL(2) over the
    // whole chord [2, 4] would be off by far more than rounding.
    let blind = Segment::new(2.0, 4.0)
        .expect("segment")
        .integrate(&gl(), 2, &mut rng(0), |t| medium.density(fwd.at(t)))
        .expect("finite")
        .value;
    assert!(rel(blind, want) > 1e-3, "{blind}");
}

#[test]
fn linear_gradient_oblique_rays_match_closed_form_and_brute_force() {
    let mut r = rng(7);
    let mut crossings = 0;
    for i in 0..200 {
        let c = Vec3::new(r.random::<f64>(), r.random::<f64>(), r.random::<f64>());
        let radius = 0.5 + r.random::<f64>();
        let base = 2.0 * r.random::<f64>() - 1.0; // often negative: a kink inside
        let g = random_unit(&mut r) * (3.0 * r.random::<f64>());
        let medium = LinearGradient::new(c, radius, base, g).expect("valid");
        let origin = c + random_unit(&mut r) * (3.0 * r.random::<f64>());
        let dir = (c + random_unit(&mut r) * (0.9 * radius) - origin).normalize();
        let ray = Ray::new(origin, dir).expect("valid");
        let Some((a, b)) = lightquad::geometry::Sphere::new(c, radius)
            .expect("sphere")
            .clip(&ray, 0.0, f64::INFINITY)
        else {
            continue;
        };
        let (fa, fb) = (medium.linear(ray.at(a)), medium.linear(ray.at(b)));
        if fa * fb < 0.0 {
            crossings += 1;
        }
        let closed = medium
            .density_integral(&ray, 0.0, f64::INFINITY)
            .expect("closed");
        let quad = depth(Arc::new(medium), ray, 0.0, f64::INFINITY, 2);
        let brute = midpoint(&medium, &ray, a, b, 20_000);
        let scale = closed.abs().max(1e-3);
        assert!(
            (quad - closed).abs() < 1e-13 * scale,
            "ray {i}: {quad} vs {closed}"
        );
        // Midpoint panels of ~1.5e-4: O(h^2) at the kink only.
        let brute_tol = 1e-7 * closed.abs().max(1.0);
        assert!(
            (brute - closed).abs() < brute_tol,
            "ray {i}: brute {brute} vs {closed}"
        );
        // The majorant bounds the density all along the chord.
        let bar = medium.max_density(&ray, 0.0, f64::INFINITY);
        for j in 0..=64 {
            let t = a + (b - a) * j as f64 / 64.0;
            assert!(medium.density(ray.at(t)) <= bar, "ray {i}, node {j}");
        }
    }
    assert!(crossings > 20, "only {crossings} rays cross the zero plane");
}

#[test]
fn linear_gradient_misses_and_all_negative_fields_are_empty() {
    let medium =
        LinearGradient::new(Vec3::zeros(), 1.0, -3.0, Vec3::new(1.0, 1.0, 0.0)).expect("valid");
    // The linear function is at most -3 + sqrt(2) < 0 inside the sphere.
    let through = ray([-3.0, 0.1, 0.0], [1.0, 0.0, 0.0]);
    assert!(medium.support(&through, 0.0, f64::INFINITY).is_empty());
    assert_eq!(
        medium.density_integral(&through, 0.0, f64::INFINITY),
        Some(0.0)
    );
    assert_eq!(depth(Arc::new(medium), through, 0.0, f64::INFINITY, 2), 0.0);
    let miss = ray([-3.0, 1.5, 0.0], [1.0, 0.0, 0.0]);
    assert_eq!(medium.max_density(&miss, 0.0, f64::INFINITY), 0.0);
    assert!(medium.support(&miss, 0.0, f64::INFINITY).is_empty());
}

// ---------------------------------------------------------------- voxel grid

/// A grid whose box and voxel sizes are dyadic, so voxel centres, lattice
/// coordinates and the test's own centre formula are all exact:
/// min (-1, 0.5, 2), voxels (0.5, 0.25, 0.125), resolution 6 x 4 x 5.
const LO: [f64; 3] = [-1.0, 0.5, 2.0];
const CELL: [f64; 3] = [0.5, 0.25, 0.125];
const RES: [usize; 3] = [6, 4, 5];

fn hi() -> [f64; 3] {
    [0, 1, 2].map(|k| LO[k] + CELL[k] * RES[k] as f64)
}

/// The centre of voxel (i, j, k), computed independently of the library.
fn centre(i: usize, j: usize, k: usize) -> Vec3 {
    Vec3::new(
        LO[0] + (i as f64 + 0.5) * CELL[0],
        LO[1] + (j as f64 + 0.5) * CELL[1],
        LO[2] + (k as f64 + 0.5) * CELL[2],
    )
}

/// `f(x) = 0.75 + 0.5 x - 0.25 y + z`, positive over the box.
fn f_lin(p: Vec3) -> f64 {
    0.75 + 0.5 * p.x - 0.25 * p.y + p.z
}

fn grid_from(mut f: impl FnMut(usize, usize, usize) -> f64) -> VoxelGrid {
    let mut data = Vec::new();
    for k in 0..RES[2] {
        for j in 0..RES[1] {
            for i in 0..RES[0] {
                data.push(f(i, j, k));
            }
        }
    }
    VoxelGrid::new(Vec3::from(LO), Vec3::from(hi()), RES, data).expect("valid grid")
}

fn linear_grid() -> VoxelGrid {
    grid_from(|i, j, k| f_lin(centre(i, j, k)))
}

fn random_grid(seed: u64) -> VoxelGrid {
    let mut r = rng(seed);
    grid_from(|_, _, _| 3.0 * r.random::<f64>())
}

#[test]
fn voxel_grid_reproduces_a_linear_field_inside_the_centre_lattice() {
    // The lattice spans x in [-0.75, 1.75], y in [0.625, 1.375],
    // z in [2.0625, 2.5625]. A chord from P0 to P1 inside it: trilinear
    // interpolation of a linear function is that function, so
    // tau = |P1 - P0| f((P0 + P1)/2).
    let grid = linear_grid();
    let p0 = Vec3::new(-0.5, 0.7, 2.1);
    let p1 = Vec3::new(1.5, 1.3, 2.5);
    let len = (p1 - p0).norm();
    let r = Ray::new(p0, p1 - p0).expect("valid");
    let want = len * f_lin((p0 + p1) * 0.5);
    let got = depth(Arc::new(grid.clone()), r, 0.0, len, 2);
    assert!(rel(got, want) < 1e-14, "{got} vs {want}");
    // Pointwise too.
    for s in [0.0, 0.13, 0.5, 0.77, 1.0] {
        let p = p0 + (p1 - p0) * s;
        assert!(rel(grid.density(p), f_lin(p)) < 1e-14, "s = {s}");
    }
}

#[test]
fn voxel_grid_clamped_margins_by_hand_for_axis_aligned_rays() {
    let grid = linear_grid();
    let fx = |x: f64, y: f64, z: f64| f_lin(Vec3::new(x, y, z));
    // Along x through the box x in [-1, 2] at (y, z) inside the lattice: the
    // half-voxel margins [-1, -0.75] and [1.75, 2] hold the edge values, the
    // middle [-0.75, 1.75] is f itself (linear: length times midpoint value).
    // With (y, z) in the margins the edge values in y and z are used instead.
    for (y, z, yc, zc) in [
        (1.0, 2.3, 1.0, 2.3),
        (0.55, 2.6, 0.625, 2.5625), // both in the lower-y, upper-z margins
    ] {
        let want = 0.25 * fx(-0.75, yc, zc) + 2.5 * fx(0.5, yc, zc) + 0.25 * fx(1.75, yc, zc);
        let r = ray([-3.0, y, z], [1.0, 0.0, 0.0]);
        let got = depth(Arc::new(grid.clone()), r, 0.0, f64::INFINITY, 2);
        assert!(
            rel(got, want) < 1e-14,
            "(y, z) = ({y}, {z}): {got} vs {want}"
        );
    }
    // Along -z through z in [2.625, 2] at x = 1.9 (upper x margin), y = 1.0:
    // margins of 0.0625 at each end, lattice [2.0625, 2.5625] in between.
    let want = 0.0625 * fx(1.75, 1.0, 2.5625)
        + 0.5 * fx(1.75, 1.0, 2.3125)
        + 0.0625 * fx(1.75, 1.0, 2.0625);
    let r = ray([1.9, 1.0, 5.0], [0.0, 0.0, -1.0]);
    let got = depth(Arc::new(grid), r, 0.0, f64::INFINITY, 2);
    assert!(rel(got, want) < 1e-14, "{got} vs {want}");
}

#[test]
fn voxel_grid_two_nodes_per_piece_equal_twenty_to_1e_13() {
    let mut r = rng(11);
    let lo = Vec3::from(LO);
    let span = Vec3::from(hi()) - lo;
    let mut with_breaks = 0;
    for seed in 0..4 {
        let grid = Arc::new(random_grid(seed));
        for i in 0..100 {
            // Origins in a box twice the grid's (some inside), aimed at a
            // random point of the grid.
            let o = lo
                + span.component_mul(&Vec3::new(
                    2.0 * r.random::<f64>() - 0.5,
                    2.0 * r.random::<f64>() - 0.5,
                    2.0 * r.random::<f64>() - 0.5,
                ));
            let target = lo
                + span.component_mul(&Vec3::new(
                    r.random::<f64>(),
                    r.random::<f64>(),
                    r.random::<f64>(),
                ));
            let ray = Ray::new(o, target - o).expect("valid");
            let pieces = grid.support(&ray, 0.0, f64::INFINITY);
            with_breaks += usize::from(pieces.iter().any(|p| !p.breaks().is_empty()));
            let two = depth(grid.clone(), ray, 0.0, f64::INFINITY, 2);
            let twenty = depth(grid.clone(), ray, 0.0, f64::INFINITY, 20);
            assert!(
                (two - twenty).abs() <= 1e-13 * twenty.abs().max(1e-3),
                "grid {seed}, ray {i}: {two} vs {twenty}"
            );
            // The break points matter: the brute-force reference agrees only
            // to its own O(h^2) accuracy.
            if let Some((a, b)) = grid.chord(&ray, 0.0, f64::INFINITY) {
                let brute = midpoint(grid.as_ref(), &ray, a, b, 20_000);
                assert!((brute - twenty).abs() < 1e-5 * twenty.max(1e-3));
            }
        }
    }
    assert!(
        with_breaks > 300,
        "{with_breaks} rays crossed centre planes"
    );
}

#[test]
fn voxel_grid_without_break_points_two_nodes_are_not_exact() {
    // Control for the test above: the same integral over the whole chord as
    // one piece is a piecewise cubic with kinks, which GL(2) misses.
    let grid = random_grid(3);
    let ray = ray([-1.5, 0.6, 2.05], [1.0, 0.3, 0.1]);
    let (a, b) = grid.chord(&ray, 0.0, f64::INFINITY).expect("hits");
    let whole = Segment::new(a, b)
        .expect("segment")
        .integrate(&gl(), 2, &mut rng(0), |t| grid.density(ray.at(t)))
        .expect("finite")
        .value;
    let exact = depth(Arc::new(grid), ray, 0.0, f64::INFINITY, 2);
    assert!(rel(whole, exact) > 1e-4, "{whole} vs {exact}");
}

#[test]
fn voxel_grid_with_one_voxel_is_a_constant_box() {
    // Unit cube, v = 2.5: the ray from (-1, 0.5, 0.5) along (1, 0.2, 0) enters
    // at x = 0 (y = 0.7) and leaves at x = 1 (y = 0.9): chord sqrt(1.04).
    let cube = VoxelGrid::new(
        Vec3::zeros(),
        Vec3::new(1.0, 1.0, 1.0),
        [1, 1, 1],
        vec![2.5],
    )
    .expect("valid");
    let r = ray([-1.0, 0.5, 0.5], [1.0, 0.2, 0.0]);
    let support = cube.support(&r, 0.0, f64::INFINITY);
    assert_eq!(support.len(), 1);
    assert!(support[0].breaks().is_empty());
    let want = 2.5 * 1.04f64.sqrt();
    assert!(
        rel(
            depth(Arc::new(cube.clone()), r, 0.0, f64::INFINITY, 1),
            want
        ) < 1e-15
    );
    assert!(cube.density_integral(&r, 0.0, f64::INFINITY).is_none());
    assert_eq!(
        cube.max_density(&r, 0.0, f64::INFINITY),
        2.5 * (1.0 + 8.0 * f64::EPSILON)
    );
    // A box that is not a cube, crossed along y: chord 2.
    let slab = VoxelGrid::new(
        Vec3::new(1.0, 2.0, 3.0),
        Vec3::new(1.5, 4.0, 3.25),
        [1, 1, 1],
        vec![0.75],
    )
    .expect("valid");
    let r = ray([1.2, 0.0, 3.1], [0.0, 1.0, 0.0]);
    assert!(rel(depth(Arc::new(slab), r, 0.0, f64::INFINITY, 1), 1.5) < 1e-15);
}

#[test]
fn voxel_grid_density_at_centres_is_the_data_and_between_them_trilinear() {
    let grid = random_grid(5);
    let data = grid.data();
    for k in 0..RES[2] {
        for j in 0..RES[1] {
            for i in 0..RES[0] {
                let want = data[(k * RES[1] + j) * RES[0] + i];
                assert_eq!(grid.density(centre(i, j, k)), want, "voxel ({i}, {j}, {k})");
            }
        }
    }
    // Midway between eight centres: their mean (weights 1/8, exact in binary).
    let at = |i: usize, j: usize, k: usize| data[(k * RES[1] + j) * RES[0] + i];
    let p = (centre(2, 1, 3) + centre(3, 2, 4)) * 0.5;
    let mean: f64 = [(2, 1, 3), (3, 1, 3), (2, 2, 3), (3, 2, 3)]
        .iter()
        .chain(&[(2, 1, 4), (3, 1, 4), (2, 2, 4), (3, 2, 4)])
        .map(|&(i, j, k)| at(i, j, k))
        .sum::<f64>()
        / 8.0;
    assert!(rel(grid.density(p), mean) < 1e-15);
    // A box corner holds the corner voxel's value; just outside the box, 0.
    assert_eq!(grid.density(Vec3::from(LO)), at(0, 0, 0));
    assert_eq!(grid.density(Vec3::from(hi())), at(5, 3, 4));
    assert_eq!(
        grid.density(Vec3::from(LO) - Vec3::new(1e-12, 0.0, 0.0)),
        0.0
    );

    // A box with non-dyadic sizes: the centres agree to rounding.
    let (lo, hi) = (Vec3::new(0.1, -0.3, 0.7), Vec3::new(1.3, 0.4, 2.9));
    let res = [3, 7, 5];
    let mut r = rng(9);
    let data: Vec<f64> = (0..105).map(|_| r.random::<f64>()).collect();
    let odd = VoxelGrid::new(lo, hi, res, data.clone()).expect("valid");
    let h = (hi - lo).component_div(&Vec3::new(3.0, 7.0, 5.0));
    for k in 0..5 {
        for j in 0..7 {
            for i in 0..3 {
                let p = lo
                    + Vec3::new(i as f64 + 0.5, j as f64 + 0.5, k as f64 + 0.5).component_mul(&h);
                let want = data[(k * 7 + j) * 3 + i];
                assert!((odd.density(p) - want).abs() < 1e-14, "({i}, {j}, {k})");
            }
        }
    }
}

#[test]
fn voxel_grid_density_is_the_clamped_trilinear_sum_anywhere_in_the_box() {
    // An independent form of the field: the lattice coordinate clamped to
    // the outer voxel centres, then the sum over the eight corners of the
    // data times the product of the hat weights. Points all over the box,
    // between the outer centres (density's short path) and in the margins
    // (its path near the faces), and on the faces themselves.
    let grid = random_grid(11);
    let data = grid.data();
    let (lo, hi) = (Vec3::from(LO), Vec3::from(hi()));
    let n = RES.map(|r| r as f64);
    let mut r = rng(12);
    for i in 0..20_000 {
        let mut p = Vec3::from_fn(|k, _| lo[k] + (hi[k] - lo[k]) * r.random::<f64>());
        if i % 10 == 0 {
            p[i % 3] = if i % 20 == 0 { lo[i % 3] } else { hi[i % 3] };
        }
        let u: [f64; 3] = std::array::from_fn(|k| {
            ((p[k] - lo[k]) / (hi[k] - lo[k]) * n[k] - 0.5).clamp(0.0, n[k] - 1.0)
        });
        let want: f64 = (0..8)
            .map(|c: usize| {
                let (mut weight, mut index, mut stride) = (1.0, 0, 1);
                for (k, &u) in u.iter().enumerate() {
                    // The lower corner stays below the last centre, so
                    // that u = n - 1 is the upper corner at weight 1.
                    let i = (u.floor() as usize).min(RES[k] - 2) + (c >> k & 1);
                    weight *= 1.0 - (u - i as f64).abs();
                    index += i * stride;
                    stride *= RES[k];
                }
                weight * data[index]
            })
            .sum();
        let got = grid.density(p);
        assert!(
            (got - want).abs() <= 1e-13 * want.abs().max(1.0),
            "{p:?}: {got} vs {want}"
        );
    }
}

#[test]
fn voxel_grid_rays_parallel_to_faces_inside_on_and_outside_the_slab() {
    let grid = linear_grid();
    let m: Arc<dyn Medium> = Arc::new(grid.clone());
    let fx = |x: f64, y: f64, z: f64| f_lin(Vec3::new(x, y, z));

    // Starting inside at x = 0.25, along +x (parallel to the y and z faces):
    // chord [0, 1.75], lattice part x in [0.25, 1.75] then the margin.
    let r = ray([0.25, 1.0, 2.3], [1.0, 0.0, 0.0]);
    assert_eq!(grid.chord(&r, 0.0, f64::INFINITY), Some((0.0, 1.75)));
    let want = 1.5 * fx(1.0, 1.0, 2.3) + 0.25 * fx(1.75, 1.0, 2.3);
    assert!(rel(depth(m.clone(), r, 0.0, f64::INFINITY, 2), want) < 1e-14);

    // Starting inside, along -y: y from 1.0 down to 0.5; lattice to 0.625.
    let r = ray([0.5, 1.0, 2.3], [0.0, -1.0, 0.0]);
    let want = 0.375 * fx(0.5, 0.8125, 2.3) + 0.125 * fx(0.5, 0.625, 2.3);
    assert!(rel(depth(m.clone(), r, 0.0, f64::INFINITY, 2), want) < 1e-14);

    // Starting inside, along (1, 0, 1)/sqrt 2 (parallel to the y faces only),
    // within the lattice until z = 2.5625 at s = 0.2625 * sqrt 2 (x = 0.5125),
    // then in the upper-z margin until z = 2.625 (x = 0.575).
    let r = ray([0.25, 1.0, 2.3], [1.0, 0.0, 1.0]);
    let s2 = std::f64::consts::SQRT_2;
    let want = 0.2625 * s2 * fx(0.38125, 1.0, 2.43125) + 0.0625 * s2 * fx(0.54375, 1.0, 2.5625);
    assert!(rel(depth(m.clone(), r, 0.0, f64::INFINITY, 2), want) < 1e-14);

    // Lying in the face y = min.y: faces belong to the box, the edge values
    // in y are used.
    let r = ray([-3.0, 0.5, 2.3], [1.0, 0.0, 0.0]);
    let want =
        0.25 * fx(-0.75, 0.625, 2.3) + 2.5 * fx(0.5, 0.625, 2.3) + 0.25 * fx(1.75, 0.625, 2.3);
    assert!(rel(depth(m.clone(), r, 0.0, f64::INFINITY, 2), want) < 1e-14);

    // Parallel to a face but outside its slab (y = 1.6 > max.y = 1.5), and
    // pointing away from the box: no chord, no work, depth 0.
    for r in [
        ray([-3.0, 1.6, 2.3], [1.0, 0.0, 0.0]),
        ray([0.0, 1.0, 1.99], [1.0, 1.0, 0.0]),
        ray([3.0, 1.0, 2.3], [1.0, 0.0, 0.0]),
        ray([0.0, 1.0, 3.0], [0.3, -0.2, 1.0]),
    ] {
        assert!(grid.chord(&r, 0.0, f64::INFINITY).is_none(), "{r:?}");
        assert!(grid.support(&r, 0.0, f64::INFINITY).is_empty());
        assert_eq!(grid.max_density(&r, 0.0, f64::INFINITY), 0.0);
        let mut scene = VolumeScene::new(r);
        scene.medium = Some(m.clone());
        let res = evaluate(
            &scene,
            &gl(),
            2,
            DepthScheme::Cumulative,
            ShadowMethod::Quadrature,
            &mut rng(0),
        )
        .expect("finite");
        assert!(res.chord.is_none() && res.optical_depth.value == 0.0);
        assert_eq!(res.optical_depth.evaluations, 0);
    }
}

#[test]
fn voxel_grid_majorant_bounds_the_density_and_is_local() {
    // A spike in the far corner voxel (5, 3, 4) and small values elsewhere.
    let grid = grid_from(|i, j, k| if (i, j, k) == (5, 3, 4) { 100.0 } else { 1.0 });
    // A ray in the opposite corner never reaches the spike's stencil.
    let near = ray([-3.0, 0.55, 2.05], [1.0, 0.0, 0.0]);
    assert!(grid.max_density(&near, 0.0, 3.5) < 1.0 + 1e-14); // x up to 0.5
    assert!(grid.max_density(&near, 0.0, f64::INFINITY) < 1.0 + 1e-14);
    // One through the spike's corner does.
    let far = ray([-3.0, 1.45, 2.6], [1.0, 0.0, 0.0]);
    assert!(grid.max_density(&far, 0.0, f64::INFINITY) >= 100.0);
    // Random rays and sub-intervals of a random grid: density <= majorant.
    let grid = random_grid(21);
    let mut r = rng(4);
    let lo = Vec3::from(LO);
    let span = Vec3::from(hi()) - lo;
    for _ in 0..300 {
        let o = lo + span.component_mul(&Vec3::new(r.random(), r.random(), r.random()));
        let ray = Ray::new(o, random_unit(&mut r)).expect("valid");
        let (a, b) = grid.chord(&ray, 0.0, f64::INFINITY).expect("inside");
        let (s, e) = {
            let (u, v) = (r.random::<f64>(), r.random::<f64>());
            (a + (b - a) * u.min(v), a + (b - a) * u.max(v))
        };
        let bar = grid.max_density(&ray, s, e);
        assert!(bar <= 3.0 * (1.0 + 1e-15));
        for j in 0..=50 {
            let t = s + (e - s) * j as f64 / 50.0;
            assert!(grid.density(ray.at(t)) <= bar);
        }
    }
}

#[test]
fn voxel_grid_block_bounds_bound_the_density_and_extent_is_the_support() {
    // 33 x 30 x 17 voxels, sides not multiples of the 4-voxel blocks, with
    // sparse spikes: long sub-chords (index boxes of more than 64 voxels)
    // take the blocks' maxima, short ones the voxels'. The bound must hold
    // at every sampled point, stay below the global peak, and be local (a
    // short sub-chord far from every spike gets less than the peak); the
    // lower bound (blocks' minima likewise) too.
    let res = [33usize, 30, 17];
    let (lo, hi) = (Vec3::new(-1.0, -2.0, 0.5), Vec3::new(2.3, 1.0, 2.2));
    let mut r = rng(9);
    let data: Vec<f64> = (0..res.iter().product::<usize>())
        .map(|i| {
            if i % 997 == 3 {
                50.0
            } else {
                r.random::<f64>()
            }
        })
        .collect();
    let grid = VoxelGrid::new(lo, hi, res, data).expect("valid grid");
    let span = hi - lo;
    let (mut long, mut short, mut below_peak, mut positive_low) = (0, 0, 0, 0);
    for _ in 0..400 {
        let o = lo + span.component_mul(&Vec3::new(r.random(), r.random(), r.random()));
        let ray = Ray::new(o, random_unit(&mut r)).expect("valid");
        let (a, b) = grid.chord(&ray, 0.0, f64::INFINITY).expect("inside");
        // extent: the chord, the ends of the support's one piece.
        let support = grid.support(&ray, 0.0, f64::INFINITY);
        let ends: Vec<(f64, f64)> = support.iter().map(|p| (p.start(), p.end())).collect();
        assert_eq!(grid.extent(&ray, 0.0, f64::INFINITY), ends);
        let frac = if r.random::<bool>() { 1.0 } else { 0.05 };
        let s = a + (b - a) * (1.0 - frac) * r.random::<f64>();
        let e = s + (b - a) * frac;
        let bar = grid.max_density(&ray, s, e);
        // The lower bound (for cost estimates): 0 for a stretch that leaves
        // the box, and below every sampled density.
        let low = grid.min_density(&ray, s, e);
        assert_eq!(grid.min_density(&ray, s, b + 1.0), 0.0);
        positive_low += usize::from(low > 0.0);
        if frac == 1.0 {
            long += 1
        } else {
            short += 1
        }
        below_peak += usize::from(bar < 50.0);
        assert!(bar <= 50.0 * (1.0 + 1e-14));
        for j in 0..=400 {
            let t = s + (e - s) * j as f64 / 400.0;
            let v = grid.density(ray.at(t));
            assert!(v <= bar, "density {v} above the bound {bar} at t = {t}");
            // Not at the ends, where the chord meets the faces and rounding
            // may put the point outside (density 0).
            if 0 < j && j < 400 {
                assert!(
                    v >= low,
                    "density {v} below the lower bound {low} at t = {t}"
                );
            }
        }
    }
    assert!(long > 150 && short > 150);
    assert!(positive_low > 50, "{positive_low} positive lower bounds");
    assert!(
        below_peak > 50,
        "{below_peak} sub-chords got less than the peak"
    );
}

// ---------------------------------------------------------------- bad input

#[test]
fn bad_linear_gradient_input_names_the_field() {
    let g = Vec3::new(1.0, 0.0, 0.0);
    let cases = [
        (
            LinearGradient::new(Vec3::new(f64::NAN, 0.0, 0.0), 1.0, 1.0, g),
            "centre",
        ),
        (LinearGradient::new(Vec3::zeros(), 0.0, 1.0, g), "radius"),
        (
            LinearGradient::new(Vec3::zeros(), f64::INFINITY, 1.0, g),
            "radius",
        ),
        (LinearGradient::new(Vec3::zeros(), 1.0, f64::NAN, g), "base"),
        (
            LinearGradient::new(Vec3::zeros(), 1.0, 1.0, Vec3::new(0.0, f64::INFINITY, 0.0)),
            "gradient",
        ),
    ];
    for (result, name) in cases {
        assert_eq!(invalid_name(result.expect_err(name)), name);
    }
    // A negative base is a valid field (positive only where the gradient lifts it).
    assert!(LinearGradient::new(Vec3::zeros(), 1.0, -0.5, g).is_ok());
}

#[test]
fn bad_voxel_grid_input_names_the_field() {
    let (lo, hi) = (Vec3::zeros(), Vec3::new(1.0, 2.0, 3.0));
    let ok = |n: usize| vec![1.0; n];
    let mut negative = ok(24);
    negative[12] = -0.5;
    let mut nan = ok(24);
    nan[3] = f64::NAN;
    let mut inf = ok(24);
    inf[23] = f64::INFINITY;
    let cases = [
        (VoxelGrid::new(lo, hi, [2, 3, 4], negative), "data[12]"),
        (VoxelGrid::new(lo, hi, [2, 3, 4], nan), "data[3]"),
        (VoxelGrid::new(lo, hi, [2, 3, 4], inf), "data[23]"),
        (VoxelGrid::new(lo, hi, [2, 0, 4], ok(0)), "resolution[1]"),
        (VoxelGrid::new(lo, hi, [0, 3, 4], ok(0)), "resolution[0]"),
        (VoxelGrid::new(lo, hi, [2, 3, 4], ok(23)), "data"),
        (VoxelGrid::new(lo, hi, [usize::MAX, 3, 4], ok(24)), "data"),
        (
            VoxelGrid::new(lo, Vec3::new(1.0, 0.0, 3.0), [2, 3, 4], ok(24)),
            "max[1]",
        ),
        (
            VoxelGrid::new(lo, Vec3::new(1.0, 2.0, -3.0), [2, 3, 4], ok(24)),
            "max[2]",
        ),
        (
            VoxelGrid::new(
                Vec3::new(-f64::MAX, 0.0, 0.0),
                Vec3::new(f64::MAX, 2.0, 3.0),
                [2, 3, 4],
                ok(24),
            ),
            "max[0]",
        ),
        (
            VoxelGrid::new(Vec3::new(0.0, f64::NAN, 0.0), hi, [2, 3, 4], ok(24)),
            "min",
        ),
        (
            VoxelGrid::new(lo, Vec3::new(f64::INFINITY, 2.0, 3.0), [2, 3, 4], ok(24)),
            "max",
        ),
    ];
    for (result, name) in cases {
        assert_eq!(invalid_name(result.expect_err(name)), name);
    }
    assert!(VoxelGrid::new(lo, hi, [2, 3, 4], ok(24)).is_ok());
}

/// The optical depth by the trapezoid rule with `n` points per smooth piece.
fn trapezoid_depth(medium: Arc<dyn Medium>, ray: Ray, n: usize) -> f64 {
    let mut scene = VolumeScene::new(ray);
    scene.medium = Some(medium);
    evaluate(
        &scene,
        &lightquad::quadrature::Trapezoid,
        n,
        DepthScheme::Cumulative,
        ShadowMethod::ClosedFormWhereAvailable,
        &mut rng(0),
    )
    .expect("finite")
    .optical_depth
    .value
}

/// Regression: a piece's end nodes read the piece's own
/// field. Chord ends from the ray–sphere roots round a hair outside the
/// sphere about half the time; read as outside, the trapezoid rule lost half
/// a panel there (tau at n = 1023 off by ~1e-3 for 18 of 40 random rays).
/// The trapezoid rule is exact for a constant and for a linear density: on
/// 40 random unit-scale rays through a constant sphere, a linear gradient and
/// a constant voxel grid, it must match the closed forms (`kappa L`; the
/// midpoint value times L; the constant times the chord in the box) to 1e-13.
#[test]
fn end_nodes_read_the_pieces_own_field_so_the_trapezoid_is_exact_on_linear_media() {
    let mut r = rng(9);
    let sphere = Arc::new(ConstantSphere::new(Vec3::zeros(), 1.0, 2.5).expect("valid"));
    let gradient = Arc::new(
        LinearGradient::new(Vec3::zeros(), 1.0, 2.0, Vec3::new(0.3, -0.2, 0.4)).expect("valid"),
    );
    let grid = Arc::new(grid_from(|_, _, _| 1.5));
    let (mut worst_sphere, mut worst_gradient, mut worst_grid) = (0.0f64, 0.0f64, 0.0f64);
    for _ in 0..40 {
        let dir = random_unit(&mut r);
        // An origin 3 units back along -dir, offset across it within the sphere.
        let across = random_unit(&mut r);
        let offset = (across - dir * across.dot(&dir)) * (0.9 * r.random::<f64>());
        let origin = offset - dir * 3.0;
        let ray = Ray::new(origin, dir).expect("valid");
        // The chord, computed here: |o + t d|^2 = 1.
        let b = origin.dot(&dir);
        let h2 = (origin - dir * b).norm_squared();
        let half = (1.0 - h2).sqrt();
        let (t0, t1) = (-b - half, -b + half);
        let want = 2.5 * (t1 - t0);
        let got = trapezoid_depth(sphere.clone(), ray, 1023);
        worst_sphere = worst_sphere.max(rel(got, want));
        // Linear field: its integral is the value at the chord's midpoint times L.
        let mid = ray.at(0.5 * (t0 + t1));
        let lin = 2.0 + Vec3::new(0.3, -0.2, 0.4).dot(&mid);
        if lin > 1e-3 {
            let got = trapezoid_depth(gradient.clone(), ray, 3);
            worst_gradient = worst_gradient.max(rel(got, lin * (t1 - t0)));
        }
        // Constant grid: 1.5 times the chord inside the box, by the slab method.
        let (lo, top) = (Vec3::from(LO), Vec3::from(hi()));
        let grid_ray = Ray::new(lo + (top - lo) * 0.5 - dir * 10.0, dir).expect("valid");
        let (mut a, mut c) = (f64::NEG_INFINITY, f64::INFINITY);
        for k in 0..3 {
            let (s, e) = (
                (lo[k] - grid_ray.origin[k]) / dir[k],
                (top[k] - grid_ray.origin[k]) / dir[k],
            );
            a = a.max(s.min(e));
            c = c.min(s.max(e));
        }
        let got = trapezoid_depth(grid.clone(), grid_ray, 3);
        worst_grid = worst_grid.max(rel(got, 1.5 * (c - a)));
    }
    eprintln!(
        "trapezoid worst relative error: sphere (n = 1023) {worst_sphere:.1e}, \
         gradient (n = 3) {worst_gradient:.1e}, grid (n = 3) {worst_grid:.1e}"
    );
    assert!(worst_sphere < 1e-13, "sphere {worst_sphere:e}");
    assert!(worst_gradient < 1e-13, "gradient {worst_gradient:e}");
    assert!(worst_grid < 1e-13, "grid {worst_grid:e}");
}

/// A subnormal density is refused, naming `kappa` and the range: 1e-320
/// keeps a few bits, and the closed form of I_E built from it was off by
/// 1.2e-4 against `c L`, which every rule got exactly. Zero and the smallest
/// normal density are accepted.
#[test]
fn a_subnormal_density_is_refused() {
    use lightquad::volume::constant_sphere::ConstantSphere;
    let e = ConstantSphere::new(Vec3::zeros(), 1.0, 1e-320).expect_err("subnormal");
    assert!(
        e.to_string().contains("kappa") && e.to_string().contains("normal f64"),
        "{e}"
    );
    assert!(ConstantSphere::new(Vec3::zeros(), 1.0, 0.0).is_ok());
    assert!(ConstantSphere::new(Vec3::zeros(), 1.0, f64::MIN_POSITIVE).is_ok());
}

/// A gradient of 1e300 (its square overflows): the density bounds stay
/// finite and bound the density, which is at most `b + |g| R` = 2e300 in the
/// unit sphere; the bound's rounding margin is a few ulps of that, not the
/// infinity of `sqrt(1e600)` that made the depth bound at lambda = 0 NaN
/// (hostile probe, session 30).
#[test]
fn linear_gradient_bounds_stay_finite_for_a_gradient_whose_square_overflows() {
    let g = LinearGradient::new(Vec3::zeros(), 1.0, 1e300, Vec3::new(1e300, 0.0, 0.0))
        .expect("valid medium");
    let r = ray([-3.0, 0.2, 0.0], [1.0, 0.0, 0.0]);
    // The chord: x from -sqrt(0.96) to +sqrt(0.96), t = x + 3.
    let h = 0.96f64.sqrt();
    let (a, b) = (3.0 - h, 3.0 + h);
    let exact_max = 1e300 * (1.0 + h);
    let exact_min = 1e300 * (1.0 - h);
    let max = g.max_density(&r, a, b);
    let min = g.min_density(&r, a, b);
    assert!(max.is_finite() && min.is_finite(), "max {max}, min {min}");
    assert!(
        max >= exact_max && max <= exact_max * (1.0 + 1e-13),
        "max {max} against {exact_max}"
    );
    assert!(
        min <= exact_min && min >= exact_min * (1.0 - 1e-12),
        "min {min} against {exact_min}"
    );
    // lambda = 0: no extinction at all, so the depth bound is 0, not NaN.
    let mut scene = VolumeScene::new(r);
    scene.medium = Some(Arc::new(g));
    scene.lambda = 0.0;
    assert_eq!(scene.depth_bound(), (0.0, 0.0));
    // |g| (|c| + 2 R) past f64 while the density stays finite: a gradient of
    // 1e308 in the unit sphere, and 1e300 in a sphere 1e10 from the origin.
    for (c, grad) in [(0.0, 1e308), (1e10, 1e300)] {
        let g = LinearGradient::new(Vec3::new(c, 0.0, 0.0), 1.0, 1.0, Vec3::new(grad, 0.0, 0.0))
            .expect("valid medium");
        let r = ray([c - 3.0, 0.2, 0.0], [1.0, 0.0, 0.0]);
        let exact_max = 1.0 + grad * h;
        // The rounding margin, 16 eps (|b| + |g| (|c| + 2 R)): points 1e10
        // from the origin carry an absolute rounding of about eps 1e10.
        let margin = 16.0 * f64::EPSILON * (1.0 + grad * (c + 2.0));
        let max = g.max_density(&r, a, b);
        assert!(
            max >= exact_max && max <= (exact_max + margin) * (1.0 + 1e-13),
            "centre {c}, gradient {grad}: max {max} against {exact_max}"
        );
        let mut scene = VolumeScene::new(r);
        scene.medium = Some(Arc::new(g));
        scene.lambda = 1e-300;
        let (sigma, depth) = scene.depth_bound();
        assert!(sigma.is_finite() && depth.is_finite(), "{sigma} {depth}");
    }
}
