//! The tracking estimators' cost estimate before a run
//! (`tracking::expected_lookups`, which the cost guard multiplies by the
//! walks) against closed forms and against the look-ups the walks make.

use lightquad::domain::Vec3;
use lightquad::geometry::Ray;
use lightquad::volume::tracking::{
    Extinction, Tracker, Walks, Wanted, expected_lookups, radiance, transmittance,
};
use lightquad::volume::{
    ConstantSphere, DirectionalLight, GaussianBlob, GaussianBlobs, LinearGradient, Medium,
    ShadowMethod, VolumeScene, VoxelGrid,
};
use rand::SeedableRng;
use std::sync::Arc;

fn along_x(medium: Arc<dyn Medium>, lambda: f64) -> VolumeScene {
    let ray = Ray::new(Vec3::new(-3.0, 0.01, -0.02), Vec3::x()).expect("ray");
    let mut s = VolumeScene::new(ray);
    s.medium = Some(medium);
    s.lambda = lambda;
    s
}

/// A 12^3 grid of pseudo-random densities in [lo, lo + 1) over [-1, 1]^3.
fn grid(lo: f64) -> Arc<dyn Medium> {
    let mut state = 12345u64;
    let data = (0..12 * 12 * 12)
        .map(|_| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            lo + (state >> 11) as f64 / (1u64 << 53) as f64
        })
        .collect();
    Arc::new(
        VoxelGrid::new(Vec3::repeat(-1.0), Vec3::repeat(1.0), [12, 12, 12], data).expect("grid"),
    )
}

/// The mean look-ups of `n` walks (their evaluations over `n`) and the
/// standard error of that mean, from `batches` independent batches.
fn measured(mut run: impl FnMut(&mut rand_pcg::Pcg64) -> u64, n: usize) -> (f64, f64) {
    let batches = 20;
    let means: Vec<f64> = (0..batches)
        .map(|i| {
            let mut rng = rand_pcg::Pcg64::seed_from_u64(1000 + i);
            run(&mut rng) as f64 / n as f64
        })
        .collect();
    let mean = means.iter().sum::<f64>() / batches as f64;
    let var = means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (batches - 1) as f64;
    (mean, (var / batches as f64).sqrt())
}

/// The mean look-ups of `tracker`'s transmittance walks over the whole eye
/// ray of `scene` ([`measured`], 20 batches of 20,000 walks).
fn walk_lookups(scene: &VolumeScene, tracker: Tracker) -> (f64, f64) {
    let sigma = Extinction {
        medium: scene.medium.as_deref().expect("medium"),
        lambda: scene.lambda,
    };
    let n = 20_000;
    measured(
        |rng| {
            transmittance(tracker, sigma, &scene.ray, 0.0, f64::INFINITY, n, rng)
                .expect("walks")
                .evaluations
        },
        n,
    )
}

/// In a sphere of constant extinction `sigma` a delta-tracking walk stops at
/// its first tentative collision that is real, and every one is
/// (`sigma_bar = sigma`): it makes one look-up with probability `1 - tau`,
/// so the expectation is `1 - exp(-sigma L)`; ratio tracking draws
/// `k sigma L` tentative collisions, `k = max(1, min(2 D, 256 / D))`, `D =
/// sigma L`, whatever the density does.
#[test]
fn a_constant_sphere_costs_the_closed_forms() {
    for (kappa, lambda) in [(0.05, 1.0), (1.3, 1.0), (40.0, 1.0), (2.0, 1e4)] {
        let scene = along_x(
            Arc::new(ConstantSphere::new(Vec3::zeros(), 1.0, kappa).expect("sphere")),
            lambda,
        );
        let chord = 2.0 * (1.0f64 - 0.01f64.powi(2) - 0.02f64.powi(2)).sqrt();
        let d = lambda * kappa * chord;
        let delta = expected_lookups(&scene, Walks::Transmittance(Tracker::Delta)).expect("delta");
        let want = -(-d).exp_m1();
        assert!(
            (delta / want - 1.0).abs() < 1e-9,
            "kappa {kappa}: delta {delta} against {want}"
        );
        let ratio = expected_lookups(&scene, Walks::Transmittance(Tracker::Ratio)).expect("ratio");
        let k = (2.0 * d).min(256.0 / d).max(1.0);
        assert!(
            (ratio / (k * d) - 1.0).abs() < 1e-9,
            "kappa {kappa}: ratio {ratio} against {}",
            k * d
        );

        // The walks themselves.
        for (tracker, want) in [(Tracker::Delta, delta), (Tracker::Ratio, ratio)] {
            if want > 1e4 {
                continue;
            }
            let (mean, se) = walk_lookups(&scene, tracker);
            assert!(
                (mean - want).abs() <= 5.0 * se + 1e-12 * want,
                "kappa {kappa} {tracker:?}: {mean} +- {se} look-ups a walk, expected {want}"
            );
        }
    }
}

/// Where the density varies the delta-tracking figure is a bound: the walks'
/// mean look-ups are below it (within the noise), and it is never above the
/// bound's optical depth, which was the estimate before. Through a dense
/// grid (densities 5e8 to 5e8 + 1 times lambda) a walk stops at its first
/// look-up, and the figure says so (the bound's depth, about 2e9, refused
/// such a job at any budget).
#[test]
fn delta_tracking_through_a_grid_costs_at_most_the_bound() {
    for (lo, lambda) in [(0.0, 0.5), (2.0, 1.0), (5e8, 1.0)] {
        let scene = along_x(grid(lo), lambda);
        let bound = expected_lookups(&scene, Walks::Transmittance(Tracker::Delta)).expect("delta");
        let (_, depth) = scene.depth_bound();
        assert!(
            bound <= depth * (1.0 + 1e-12),
            "lo {lo}: {bound} above the depth {depth}"
        );
        let (mean, se) = walk_lookups(&scene, Tracker::Delta);
        assert!(
            mean <= bound + 5.0 * se,
            "lo {lo}: {mean} +- {se} look-ups a walk above {bound}"
        );
        if lo >= 1.0 {
            // The lower bound is within a factor 1 + 1/lo of the density.
            assert!(
                bound < mean * (1.0 + 2.0 / lo) + 5.0 * se,
                "lo {lo}: {bound} against {mean}"
            );
        }
        if lo == 5e8 {
            assert!(
                bound < 1.0 + 1e-6 && depth > 1e9,
                "bound {bound}, depth {depth}"
            );
        }
    }
}

/// A radiance walk scoring V-L casts a shadow ray at each tentative
/// collision; through a linear gradient (no closed form for a shadow ray
/// toward the side) the figure counts them, and the walks' look-ups are
/// within a factor 2 of it (the shadow rays' cost is an estimate from three
/// of them).
#[test]
fn radiance_walks_count_their_shadow_rays() {
    let medium: Arc<dyn Medium> = Arc::new(
        LinearGradient::new(Vec3::zeros(), 1.0, 1.5, Vec3::new(0.4, 0.7, 0.0)).expect("gradient"),
    );
    let mut scene = along_x(medium, 1.0);
    scene.light =
        Some(DirectionalLight::new(Vec3::new(0.0, 1.0, 0.0), 1.0, Some(0.8)).expect("light"));
    let wanted = Wanted {
        emission: false,
        light: true,
    };
    let eye = expected_lookups(&scene, Walks::Transmittance(Tracker::Delta)).expect("eye");
    let figure = expected_lookups(&scene, Walks::Radiance(ShadowMethod::Quadrature, wanted))
        .expect("figure");
    assert!(figure > 2.0 * eye, "{figure} against the eye walk's {eye}");
    let n = 20_000;
    let (mean, se) = measured(
        |rng| {
            radiance(&scene, ShadowMethod::Quadrature, wanted, n, rng)
                .expect("walks")
                .light
                .evaluations
        },
        n,
    );
    assert!(
        mean / figure > 0.5 && mean / figure < 2.0,
        "{mean} +- {se} look-ups a walk against {figure}"
    );
}

/// A walk is capped at 1e7 tentative collisions a span. On a diagonal ray
/// through a 3^3 grid whose only non-zero voxel (1e9 at (0, 0, 2)) the
/// ray's interpolation never reaches, though the spans around the middle
/// voxel take it into their bound, every tentative collision is null, and
/// delta tracking ends with an error that names the optical depth, not a
/// hang; the cost figure says as much before any walk.
#[test]
fn a_walk_through_a_bound_it_never_meets_stops_at_the_cap() {
    let mut data = vec![0.0; 27];
    data[2 * 9] = 1e9;
    let medium: Arc<dyn Medium> = Arc::new(
        VoxelGrid::new(Vec3::repeat(-1.0), Vec3::repeat(1.0), [3, 3, 3], data).expect("grid"),
    );
    let ray = Ray::new(Vec3::repeat(-2.0), Vec3::repeat(1.0)).expect("ray");
    let mut scene = VolumeScene::new(ray);
    scene.medium = Some(medium.clone());
    // The density along the ray is 0 everywhere (the voxel is off the
    // interpolation stencils of the diagonal).
    for i in 0..=1000 {
        let t = 3.0f64.sqrt() * (0.5 + 2.0 * i as f64 / 1000.0);
        assert_eq!(medium.density(ray.at(t)), 0.0, "t = {t}");
    }
    let figure = expected_lookups(&scene, Walks::Transmittance(Tracker::Delta)).expect("figure");
    assert!(figure > 1e7, "{figure} look-ups a walk");
    let sigma = Extinction {
        medium: medium.as_ref(),
        lambda: 1.0,
    };
    let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
    let e = transmittance(Tracker::Delta, sigma, &ray, 0.0, f64::INFINITY, 2, &mut rng)
        .expect_err("capped");
    let msg = e.to_string();
    assert!(
        msg.contains("optical depth")
            && msg.contains("tentative collisions")
            && msg.contains("`scene.medium`, `scene.lambda`"),
        "{msg}"
    );
}

/// Gaussian blobs: the lower bound (each blob's value at the farther end of
/// a stretch) is below the density at every sampled point, and through a
/// blob of amplitude 1e7 a delta-tracking walk's figure is tens of look-ups,
/// as the walks make (the bound's depth, about 1e7, refused 1e5 walks).
#[test]
fn delta_tracking_through_a_dense_blob_costs_tens_of_lookups() {
    let blobs = GaussianBlobs::new(vec![
        GaussianBlob {
            centre: Vec3::new(0.1, 0.0, 0.05),
            amplitude: 1e7,
            width: 0.4,
        },
        GaussianBlob {
            centre: Vec3::new(-0.5, 0.3, 0.0),
            amplitude: 2.0,
            width: 0.2,
        },
    ])
    .expect("blobs");
    let ray = Ray::new(Vec3::new(-3.0, 0.01, -0.02), Vec3::x()).expect("ray");
    for (t0, t1) in [(0.0, 6.0), (2.0, 2.3), (2.9, 3.4), (3.5, 9.0), (1.0, 4.0)] {
        let low = blobs.min_density(&ray, t0, t1);
        assert!(low > 0.0, "[{t0}, {t1}]");
        for i in 0..=200 {
            let t = t0 + (t1 - t0) * i as f64 / 200.0;
            let v = blobs.density(ray.at(t));
            assert!(v >= low, "density {v} below {low} at t = {t}");
        }
    }
    let scene = along_x(Arc::new(blobs), 1.0);
    let figure = expected_lookups(&scene, Walks::Transmittance(Tracker::Delta)).expect("figure");
    let (_, depth) = scene.depth_bound();
    assert!(
        figure < 100.0 && depth > 1e6,
        "figure {figure}, depth {depth}"
    );
    let (mean, se) = walk_lookups(&scene, Tracker::Delta);
    assert!(
        mean <= figure + 5.0 * se,
        "{mean} +- {se} look-ups a walk above {figure}"
    );
}

/// The linear gradient's lower bound is below the density at every sampled
/// interior point of sub-chords of random rays, and positive where the
/// field is positive along the whole stretch.
#[test]
fn the_linear_gradients_lower_bound_is_below_its_density() {
    let medium = LinearGradient::new(
        Vec3::new(0.2, -0.1, 0.0),
        1.0,
        1.2,
        Vec3::new(0.5, 0.9, -0.3),
    )
    .expect("gradient");
    let mut positive = 0;
    for i in 0..200 {
        let a = i as f64 * 0.731;
        let ray = Ray::new(
            Vec3::new(-3.0, 0.4 * a.sin(), 0.3 * a.cos()),
            Vec3::new(1.0, 0.2 * (1.7 * a).sin(), 0.2 * (2.3 * a).cos()),
        )
        .expect("ray");
        let Some((t0, t1)) = medium.extent(&ray, 0.0, f64::INFINITY).first().copied() else {
            continue;
        };
        let (s, e) = (
            t0 + (t1 - t0) * 0.1 * (i % 7) as f64,
            t1 - (t1 - t0) * 0.05 * (i % 5) as f64,
        );
        let low = medium.min_density(&ray, s, e);
        positive += usize::from(low > 0.0);
        for j in 1..100 {
            let t = s + (e - s) * j as f64 / 100.0;
            let v = medium.density(ray.at(t));
            assert!(v >= low, "density {v} below {low} at t = {t}");
        }
        assert_eq!(
            medium.min_density(&ray, s, t1 + 1.0),
            0.0,
            "a stretch leaving the sphere"
        );
    }
    assert!(positive > 50, "{positive} positive lower bounds");
}

/// A walk that scores emission where there is no extinction (lambda 0)
/// takes one tentative collision a span; on a chord a few ulps long, past a
/// corner of a voxel grid, spans round to length 0, and the figure stays
/// finite (it was 1/0 times 0).
#[test]
fn a_chord_of_a_few_ulps_costs_a_finite_figure() {
    let medium: Arc<dyn Medium> = grid(1.0);
    let eps = 1e-14;
    let ray = Ray::new(Vec3::new(-3.0, 5.0 - eps, 0.0), Vec3::new(1.0, -1.0, 0.0)).expect("ray");
    let mut scene = VolumeScene::new(ray);
    scene.medium = Some(medium);
    scene.lambda = 0.0;
    scene.emission = Some(lightquad::volume::EmissionMap::Constant(1.0));
    let wanted = Wanted {
        emission: true,
        light: false,
    };
    let figure = expected_lookups(&scene, Walks::Radiance(ShadowMethod::Quadrature, wanted))
        .expect("figure");
    assert!(
        figure.is_finite() && (0.0..=16.0).contains(&figure),
        "{figure}"
    );
}

/// Ratio tracking through a span whose majorant depth is past half the cap
/// (a linear gradient from 0 to 2e8 over a chord of 1.96: its spans'
/// bounds reach depths between 5e6 and 1e7) is refused before the first
/// walk, and the error names the limit it applied, below the depth it
/// reports (it said 1e7 against a depth of 5.5e6: hostile probe, session 31).
#[test]
fn a_refused_ratio_span_names_the_limit_applied() {
    let medium: Arc<dyn Medium> = Arc::new(
        LinearGradient::new(Vec3::zeros(), 1.0, 1e8, Vec3::new(1e8, 0.0, 0.0)).expect("medium"),
    );
    let ray = Ray::new(Vec3::new(-3.0, 0.2, 0.0), Vec3::x()).expect("ray");
    let sigma = Extinction {
        medium: medium.as_ref(),
        lambda: 1.0,
    };
    let mut rng = rand_pcg::Pcg64::seed_from_u64(3);
    let e = transmittance(Tracker::Ratio, sigma, &ray, 0.0, f64::INFINITY, 2, &mut rng)
        .expect_err("refused");
    match e {
        lightquad::QuadError::TooDeepForTracking { depth, limit } => {
            assert_eq!(limit, 5_000_000);
            // No span's bound exceeds the whole chord's: 2e8 times 1.96.
            assert!(depth > limit as f64 && depth <= 2e8 * 1.96, "depth {depth}");
        }
        other => panic!("{other}"),
    }
}
