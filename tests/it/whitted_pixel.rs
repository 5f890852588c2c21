//! The pixel as an integral over its square (src/whitted/pixel.rs,
//! coverage.rs, render.rs) against independent references.
//!
//! Layers: (1) the exact coverage of a half-plane by clipping, against
//! areas written here from elementary geometry (the diagonal, slivers, a
//! corner triangle of area 1e-12) and against the piecewise-linear integral
//! `int_0^1 clamp((c - a x) / b, 0, 1) dx` split at its kinks, for random
//! lines; (2) W-Corner traces `(s + 1)(z + 1)` primary rays for an `s x z`
//! image, and adaptive subdivision shares its points; (3) convergence
//! orders fitted by least squares on a sweep of budgets: on an edge pixel
//! (RMS over random edges, error against the exact fraction) the grid goes
//! as `N^-1/2` with the edge along an axis (its worst orientation),
//! jittered sampling as `N^-3/4`, scrambled Sobol' points as `N^-3/4`; on a
//! smooth pixel (`e^(x/2) cos y`, integral `2 (e^(1/2) - 1) sin 1`) the
//! grid and jittered sampling go as `N^-1`, scrambled Sobol' as `N^-3/2`.
//! Each test prints its fitted orders.

use crate::common;
use common::fitted_order;

use lightquad::domain::{Pixel, Vec3};
use lightquad::value::Rgb;
use lightquad::whitted::coverage::{HalfPlane, half_plane_fraction, polygon_fraction};
use lightquad::whitted::intersect::Shape;
use lightquad::whitted::pixel::{adaptive_image, corner_image, grid, jittered, low_discrepancy};
use lightquad::whitted::render::{Scheme, render};
use lightquad::whitted::scene::{Camera, Material, Object, Scene};
use rand::{RngExt, SeedableRng};

fn unit() -> Pixel {
    Pixel::new(0.0, 0.0, 1.0, 1.0).expect("pixel")
}

fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

/// `int_0^1 clamp((c - a x) / b, 0, 1) dx` (`b > 0`): the area of the unit
/// square below the line `a x + b y = c`, integrated exactly by the
/// trapezoid rule on the pieces between the kinks (where the clamped value
/// is linear).
fn area_below(a: f64, b: f64, c: f64) -> f64 {
    let g = |x: f64| ((c - a * x) / b).clamp(0.0, 1.0);
    let mut cuts = vec![0.0, 1.0];
    if a != 0.0 {
        for y in [0.0, 1.0] {
            let x = (c - b * y) / a;
            if x > 0.0 && x < 1.0 {
                cuts.push(x);
            }
        }
    }
    cuts.sort_by(f64::total_cmp);
    cuts.windows(2)
        .map(|w| 0.5 * (w[1] - w[0]) * (g(w[0]) + g(w[1])))
        .sum()
}

// ------------------------------------------------------- (1) coverage

#[test]
fn coverage_of_the_diagonal_slivers_and_a_tiny_corner_is_exact() {
    let p = unit();
    // The two diagonals through two corners each: exactly half.
    let diagonal = HalfPlane {
        a: 1.0,
        b: 1.0,
        c: 1.0,
    };
    assert_eq!(half_plane_fraction(&p, diagonal), 0.5);
    let anti = HalfPlane {
        a: 1.0,
        b: -1.0,
        c: 0.0,
    };
    assert_eq!(half_plane_fraction(&p, anti), 0.5);
    // A vertical sliver of width 1e-9, and an oblique one: the strip under
    // y = 1e-8 + 1e-9 x, a trapezoid of area 1e-8 + 0.5e-9.
    assert!(
        rel(
            half_plane_fraction(
                &p,
                HalfPlane {
                    a: 1.0,
                    b: 0.0,
                    c: 1e-9
                }
            ),
            1e-9
        ) < 1e-12
    );
    let oblique = HalfPlane {
        a: -1e-9,
        b: 1.0,
        c: 1e-8,
    };
    assert!(rel(half_plane_fraction(&p, oblique), 1.05e-8) < 1e-12);
    // Its complement, 1 - 1.05e-8.
    let rest = half_plane_fraction(&p, oblique.complement());
    assert!((rest - (1.0 - 1.05e-8)).abs() < 1e-16);
    // The corner triangle x / 1e-6 + y / 2e-6 <= 1: legs 1e-6 and 2e-6, area 1e-12.
    let corner = HalfPlane {
        a: 1e6,
        b: 0.5e6,
        c: 1.0,
    };
    let f = half_plane_fraction(&p, corner);
    assert!(rel(f, 1e-12) < 1e-12, "{f:e}");
    // The same triangle as a polygon, at a far pixel (coordinates 1e3).
    let far = Pixel::new(1000.0, 2000.0, 1.0, 1.0).expect("pixel");
    let tri = [
        [1000.0, 2000.0],
        [1000.0 + 1e-6, 2000.0],
        [1000.0, 2000.0 + 2e-6],
    ];
    let f = polygon_fraction(&far, &tri);
    // Against the legs as stored (1000 + 1e-6 is 1e-6 to 6e-8 relative;
    // the differences are exact by Sterbenz's lemma).
    let legs = (tri[1][0] - 1000.0) * (tri[2][1] - 2000.0);
    assert!(rel(f, 0.5 * legs) < 1e-12, "{f:e} vs {:e}", 0.5 * legs);
    // Nothing and everything.
    assert_eq!(
        half_plane_fraction(
            &p,
            HalfPlane {
                a: 1.0,
                b: 1.0,
                c: -0.1
            }
        ),
        0.0
    );
    assert_eq!(
        half_plane_fraction(
            &p,
            HalfPlane {
                a: 1.0,
                b: 1.0,
                c: 2.1
            }
        ),
        1.0
    );
}

/// 10000 random lines (every orientation, through or near the pixel): the
/// clipped area against the kink-split integral, to 1e-14.
#[test]
fn coverage_of_random_edges_is_the_integral_below_the_line() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
    let p = unit();
    for _ in 0..10_000 {
        let angle = rng.random::<f64>() * std::f64::consts::PI;
        let (a, b) = (angle.cos(), angle.sin().max(1e-3));
        let c = (rng.random::<f64>() * 2.0 - 0.5) * (a.abs() + b);
        let want = area_below(a, b, c);
        let got = half_plane_fraction(&p, HalfPlane { a, b, c });
        assert!(
            (got - want).abs() < 1e-14,
            "a {a} b {b} c {c}: {got} vs {want}"
        );
        // A triangle's coverage: the pixel cut by three lines, against the
        // half-plane when two of its edges lie far outside the pixel.
        let tri_far = [
            [-100.0, (c + 100.0 * a) / b],
            [100.0, (c - 100.0 * a) / b],
            [0.0, -1e4],
        ];
        let poly = polygon_fraction(&p, &tri_far);
        assert!((poly - want).abs() < 1e-11, "{poly} vs {want}");
    }
}

// ---------------------------------------------------- (2) ray counts

fn ball_scene(width: usize, height: usize) -> Scene {
    let ball = Object {
        shape: Shape::sphere(Vec3::new(0.0, 0.0, -3.0), 1.0).expect("sphere"),
        material: Material::default(),
    };
    let cam = Camera::new(Vec3::zeros(), -Vec3::z(), Vec3::y(), 60.0, width, height).expect("cam");
    Scene::new(
        vec![ball],
        vec![],
        Rgb::new(1.0, 1.0, 1.0),
        Rgb::zeros(),
        cam,
        2,
    )
    .expect("scene")
}

/// W-Corner on s x z images traces (s + 1)(z + 1) primary rays, s + z + 1
/// more than one ray per pixel.
#[test]
fn the_corner_scheme_traces_s_plus_1_times_z_plus_1_primary_rays() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
    for (s, z) in [(1, 1), (4, 3), (16, 9), (37, 23)] {
        let scene = ball_scene(s, z);
        let corner = render(&scene, &Scheme::Corner { m: 1 }, &mut rng).expect("render");
        let centre = render(&scene, &Scheme::Centre, &mut rng).expect("render");
        assert_eq!(corner.rays.primary as usize, (s + 1) * (z + 1), "{s} x {z}");
        assert_eq!(
            corner.rays.primary - centre.rays.primary,
            (s + z + 1) as u64
        );
        // The 3 x 3 grid: 9 per pixel.
        let ss = render(&scene, &Scheme::Grid { n: 3 }, &mut rng).expect("render");
        assert_eq!(ss.rays.primary as usize, 9 * s * z);
    }
    // With m x m cells per pixel: (s m + 1)(z m + 1).
    let scene = ball_scene(5, 4);
    let out = render(&scene, &Scheme::Corner { m: 3 }, &mut rng).expect("render");
    assert_eq!(out.rays.primary, 16 * 13);
}

/// Adaptive subdivision traces each lattice point once: on a smooth image
/// (nothing to split) it is W-Corner's count; at an edge it adds points
/// along the edge only, far fewer than the uniform lattice of its depth;
/// its pixels approach the exact coverage as the depth grows.
#[test]
fn adaptive_subdivision_shares_its_points_and_refines_only_at_edges() {
    let mut rays = 0;
    let flat = adaptive_image([0.0, 0.0], 6, 4, 0.1, 5, |p: [f64; 2]| {
        rays += 1;
        0.01 * (p[0] + p[1])
    });
    assert_eq!((rays, flat.len()), (7 * 5, 24));
    // An oblique edge across a 4 x 4 image: 0 below, 1 above.
    let edge = HalfPlane {
        a: 0.37,
        b: 1.0,
        c: 2.3,
    };
    let exact: Vec<f64> = (0..16)
        .map(|k| {
            let p = Pixel::new((k % 4) as f64, (k / 4) as f64, 1.0, 1.0).expect("pixel");
            half_plane_fraction(&p, edge)
        })
        .collect();
    let mut previous = f64::INFINITY;
    for level in [2, 4, 6, 8] {
        let mut rays = 0;
        let img = adaptive_image([0.0, 0.0], 4, 4, 0.5, level, |p: [f64; 2]| {
            rays += 1;
            if edge.side(p) <= 0.0 { 1.0 } else { 0.0 }
        });
        let err = img
            .iter()
            .zip(&exact)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        let uniform = (4 * (1 << level) + 1usize).pow(2);
        println!(
            "adaptive level {level}: {rays} rays (uniform lattice {uniform}), max error {err:.2e}"
        );
        assert!(rays < uniform / 4 || level == 2, "{rays} vs {uniform}");
        assert!(err < previous, "{err} after {previous}");
        previous = err;
    }
    assert!(previous < 2e-3, "{previous}");
}

/// W-Corner's m x m lattice is the composite trapezoid rule: a bilinear L
/// is integrated exactly, and a smooth L converges as m^-2.
#[test]
fn the_corner_scheme_is_the_trapezoid_rule() {
    let bilinear = corner_image([0.0, 0.0], 3, 2, 1, |p: [f64; 2]| 2.0 + p[0] * p[1]);
    for (k, v) in bilinear.iter().enumerate() {
        let (i, j) = ((k % 3) as f64, (k / 3) as f64);
        assert!((v - (2.0 + (i + 0.5) * (j + 0.5))).abs() < 1e-14);
    }
    let f = |p: [f64; 2]| (0.5 * p[0]).exp() * p[1].cos();
    let exact = 2.0 * (0.5f64.exp() - 1.0) * 1f64.sin();
    let points: Vec<(f64, f64)> = [2, 4, 8, 16, 32]
        .iter()
        .map(|&m| {
            let v = corner_image([0.0, 0.0], 1, 1, m, f)[0];
            (m as f64, (v - exact).abs())
        })
        .collect();
    let order = fitted_order(&points);
    println!("corner (trapezoid) on the smooth pixel: order {order:.3} in m");
    assert!((order + 2.0).abs() < 0.05, "{order}");
}

// ------------------------------------------------ (3) convergence orders

/// RMS over `edges` of the error of `scheme` on the indicator of each edge.
fn rms_on_edges(
    edges: &[HalfPlane],
    mut scheme: impl FnMut(&mut dyn FnMut([f64; 2]) -> f64) -> f64,
) -> f64 {
    let p = unit();
    let sum: f64 = edges
        .iter()
        .map(|&h| {
            let exact = half_plane_fraction(&p, h);
            let mut f = |q: [f64; 2]| if h.side(q) <= 0.0 { 1.0 } else { 0.0 };
            (scheme(&mut f) - exact).powi(2)
        })
        .sum();
    (sum / edges.len() as f64).sqrt()
}

/// Edges through the pixel at uniform random offsets; `axis` keeps them
/// vertical (the grid's worst orientation), else any angle.
fn edges(count: usize, axis: bool, seed: u64) -> Vec<HalfPlane> {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    (0..count)
        .map(|_| {
            let angle: f64 = if axis {
                0.0
            } else {
                rng.random::<f64>() * std::f64::consts::PI
            };
            let (a, b) = (angle.cos(), angle.sin());
            // Through a uniform point of the pixel.
            let (x, y) = (rng.random::<f64>(), rng.random::<f64>());
            HalfPlane {
                a,
                b,
                c: a * x + b * y,
            }
        })
        .collect()
}

const SIDES: [usize; 6] = [4, 8, 16, 32, 64, 128];

#[test]
fn on_an_edge_pixel_the_grid_goes_as_n_to_the_minus_half_along_an_axis() {
    let vertical = edges(400, true, 1);
    let points: Vec<(f64, f64)> = SIDES
        .iter()
        .map(|&m| {
            let e = rms_on_edges(&vertical, |f| grid(&unit(), m, f));
            ((m * m) as f64, e)
        })
        .collect();
    let order = fitted_order(&points);
    println!("grid, axis-aligned edge: order {order:.3} in N; {points:?}");
    assert!((order + 0.5).abs() < 0.05, "{order}");
}

#[test]
fn on_an_edge_pixel_jittered_and_sobol_sampling_go_as_n_to_the_minus_three_quarters() {
    let oblique = edges(400, false, 2);
    let mut rng = rand_pcg::Pcg64::seed_from_u64(5);
    let jitter: Vec<(f64, f64)> = SIDES
        .iter()
        .map(|&m| {
            let e = rms_on_edges(&oblique, |f| {
                jittered(&unit(), m, &mut rng, f).expect("rule").value
            });
            ((m * m) as f64, e)
        })
        .collect();
    let sobol: Vec<(f64, f64)> = [64, 256, 1024, 4096, 16384]
        .iter()
        .map(|&n| {
            let e = rms_on_edges(&oblique, |f| {
                low_discrepancy(&unit(), n, &mut rng, f)
                    .expect("rule")
                    .value
            });
            (n as f64, e)
        })
        .collect();
    let (oj, os) = (fitted_order(&jitter), fitted_order(&sobol));
    println!("edge pixel: jittered order {oj:.3}, sobol order {os:.3}");
    println!("jittered {jitter:?}\nsobol {sobol:?}");
    assert!((oj + 0.75).abs() < 0.08, "jittered {oj}");
    assert!((os + 0.75).abs() < 0.12, "sobol {os}");
    // The grid on oblique edges is no worse than along an axis.
    let g = rms_on_edges(&oblique, |f| grid(&unit(), 64, f));
    let ga = rms_on_edges(&edges(400, true, 1), |f| grid(&unit(), 64, f));
    assert!(g < ga, "{g} vs {ga}");
}

#[test]
fn on_a_smooth_pixel_the_grid_and_jittered_go_as_n_to_the_minus_one_sobol_faster() {
    let f = |p: [f64; 2]| (0.5 * p[0]).exp() * p[1].cos();
    let exact = 2.0 * (0.5f64.exp() - 1.0) * 1f64.sin();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(9);
    let grid_points: Vec<(f64, f64)> = SIDES
        .iter()
        .map(|&m| ((m * m) as f64, (grid(&unit(), m, f) - exact).abs()))
        .collect();
    let repeats = 200;
    let rms = |rng: &mut rand_pcg::Pcg64, run: &dyn Fn(&mut rand_pcg::Pcg64) -> f64| {
        ((0..repeats)
            .map(|_| (run(rng) - exact).powi(2))
            .sum::<f64>()
            / repeats as f64)
            .sqrt()
    };
    let jitter: Vec<(f64, f64)> = [4usize, 8, 16, 32, 64]
        .iter()
        .map(|&m| {
            let e = rms(&mut rng, &|r| {
                jittered(&unit(), m, r, f).expect("rule").value
            });
            ((m * m) as f64, e)
        })
        .collect();
    let sobol: Vec<(f64, f64)> = [64usize, 256, 1024, 4096]
        .iter()
        .map(|&n| {
            let e = rms(&mut rng, &|r| {
                low_discrepancy(&unit(), n, r, f).expect("rule").value
            });
            (n as f64, e)
        })
        .collect();
    let (og, oj, os) = (
        fitted_order(&grid_points),
        fitted_order(&jitter),
        fitted_order(&sobol),
    );
    println!("smooth pixel: grid {og:.3}, jittered {oj:.3}, sobol {os:.3}");
    assert!((og + 1.0).abs() < 0.02, "grid {og}");
    assert!((oj + 1.0).abs() < 0.1, "jittered {oj}");
    assert!((os + 1.5).abs() < 0.2, "sobol {os}");
}

/// The parallel render (bands of rows on rayon's threads) is the serial
/// render: the bundled test scene at 40 x 30 by W-SS's 3 x 3 grid gives the
/// same pixels, bit for bit, and the same rays by kind as `render`; a random
/// rule's image is the same on one thread and on three (each band draws from
/// its own seeded generator).
#[test]
fn the_parallel_render_is_the_serial_render() {
    use lightquad::quadrature::AnyRule;
    use lightquad::whitted::experiment::scene_of;
    use lightquad::whitted::render::render_parallel;
    let text = std::fs::read_to_string(common::root().join("experiments/w-grey-test-scene.json"))
        .expect("bundled scene");
    let json: serde_json::Value = serde_json::from_str(&text).expect("json");
    let scene = scene_of(&json, Some(40), Some(30)).expect("scene").scene;
    let grid = Scheme::Grid { n: 3 };
    let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
    let serial = render(&scene, &grid, &mut rng).expect("serial");
    let parallel = render_parallel(&scene, &grid, 0).expect("parallel");
    assert_eq!(serial.rays, parallel.rays);
    assert!(serial.rays.shadow > 0 && serial.rays.reflection > 0 && serial.rays.refraction > 0);
    assert_eq!(serial.image.values, parallel.image.values);
    let rule = Scheme::Rule {
        rule: AnyRule::by_name("stratified").expect("rule"),
        n: 4,
    };
    let on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool")
            .install(|| render_parallel(&scene, &rule, 7).expect("render"))
    };
    let (one, three) = (on(1), on(3));
    assert_eq!(one.image.values, three.image.values);
    assert_eq!(one.rays, three.rays);
}

/// W-SS's grid and W-Corner's trapezoid sum a pixel's rays with
/// compensation: a 64 x 64 grid over a pixel whose left quarter shows 0.4
/// (1024 of 4096 rays) is 0.1 exactly (1024 * 0.4 / 4096 is a power-of-two
/// scaling of 0.4, so exact in f64), which W-Grey shows as 26 (25.5 rounded
/// up). A plain running sum gave 0.09999999999999849, shown as 25 (the
/// independent check's grid that was "1 off" the reference at n = 4096).
#[test]
fn a_pixels_rays_sum_to_their_exact_mean() {
    use lightquad::whitted::image::grey;
    let quarter = |p: [f64; 2]| if p[0] < 0.25 { 0.4 } else { 0.0 };
    let pixel = Pixel::new(0.0, 0.0, 1.0, 1.0).expect("pixel");
    let v: f64 = grid(&pixel, 64, quarter);
    assert_eq!(v, 0.1);
    assert_eq!(grey(v), 26);
    // The trapezoid rule on the corner lattice: 65 x 65 points with
    // weights 1/2 on the pixel's edges; x < 0.25 holds the columns 0..=15,
    // so the sum is 0.4 * 64 * (1/2 + 15) / 4096 = 0.096875 exactly.
    let image: Vec<f64> = corner_image([0.0, 0.0], 1, 1, 64, quarter);
    assert_eq!(image[0], 0.4 * 64.0 * 15.5 / 4096.0);
}
