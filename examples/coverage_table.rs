//! Measures how often the stochastic methods' 95% intervals `value +- 1.96
//! error` cover the closed form, and prints a Markdown table.
//!
//! `cargo run --release --example coverage_table -- [REPEATS]` (400 by default)
//!
//! Methods: Monte Carlo, stratified, scrambled Sobol' (8 scrambles), path
//! tracing, ratio and delta tracking. Scenes: a smooth integrand (`e^x` on
//! `[0, 1]` for the rules; a constant sphere's `tau` at optical depths 2
//! and 0.5 for the trackers), the Gaussian-blob transmittance of tests/it/coverage.rs,
//! and a furnace (the white furnace at albedo 0.9 and a sphere with an
//! emitting cap at albedo 0.7: path tracing estimates `L`; the rules the
//! cap's irradiance at the wall point, the hemisphere integral the Neumann
//! series is built from, whose cap edge is a jump). At `n = 16` and `256`
//! (the budget: samples, cells, points, walks, paths) over `REPEATS` seeds,
//! each cell gives the runs flagged (a flag on the row or an estimate the
//! method doubts), the coverage among the unflagged runs, and the RMS of
//! `z = (value - exact) / error` among them (about 0.95 for an honest
//! Student-t widened standard error; much below 1 where the error bars are
//! too wide).

use std::sync::Arc;

use lightquad::QuadError;
use lightquad::domain::{Frame, Hemisphere, HemisphereMap, Vec3, integrate_over};
use lightquad::family::{Family, Method};
use lightquad::geometry::Ray;
use lightquad::quadrature::{AnyRule, Rule};
use lightquad::rand::SeedableRng;
use lightquad::rendering::furnace::IntegratingSphere;
use lightquad::volume::experiment::{Built, Volume, VolumeQuantity as Q};
use lightquad::volume::tracking::Tracker;
use lightquad::volume::{
    ConstantSphere, DepthScheme, GaussianBlob, GaussianBlobs, ShadowMethod, VolumeScene,
};

/// One run: the value, its error, and whether the method flagged it.
type Run = (f64, f64, bool);

/// A cell's method at a budget and seed, against its exact value.
type Cell = (
    String,
    f64,
    Box<dyn Fn(usize, u64) -> Result<Run, QuadError>>,
);

fn rng(seed: u64) -> lightquad::rand_pcg::Pcg64 {
    lightquad::rand_pcg::Pcg64::seed_from_u64(seed)
}

/// Two overlapping Gaussian blobs crossed off-centre (tests/it/coverage.rs).
fn blobs() -> Result<Built, QuadError> {
    let medium = GaussianBlobs::new(vec![
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
    ])?;
    let ray = Ray::new(Vec3::new(-6.0, 0.0, 0.05), Vec3::new(1.0, 0.02, 0.0))?;
    let mut s = VolumeScene::new(ray);
    s.medium = Some(Arc::new(medium));
    s.lambda = 1.5;
    Ok(built(s))
}

/// A unit sphere of density `kappa` crossed through its centre: `tau =
/// e^(-2 kappa)`.
fn sphere(kappa: f64) -> Result<Built, QuadError> {
    let ray = Ray::new(Vec3::new(-3.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0))?;
    let mut s = VolumeScene::new(ray);
    s.medium = Some(Arc::new(ConstantSphere::new(Vec3::zeros(), 1.0, kappa)?));
    Ok(built(s))
}

fn built(scene: VolumeScene) -> Built {
    Built {
        scene,
        scheme: DepthScheme::Cumulative,
        shadow: ShadowMethod::ClosedFormWhereAvailable,
        sphere_kappa: None,
        printed: None,
        field_sphere_value: None,
    }
}

/// `tau` of a built scene by `method`, flagged when the row carries a flag.
fn tau(b: &Built, method: &Method<Tracker>, n: usize, seed: u64) -> Result<Run, QuadError> {
    let out = Volume::evaluate(b, method, n, &mut rng(seed), &[Q::Tau])?;
    let m = &out[&Q::Tau];
    Ok((m.value[0], m.error[0], !m.flags.is_empty()))
}

/// `tau` of a built scene in closed form.
fn exact_tau(b: &Built) -> Result<f64, QuadError> {
    let s = &b.scene;
    let depth = s
        .medium
        .as_deref()
        .and_then(|m| m.density_integral(&s.ray, 0.0, f64::INFINITY))
        .ok_or(QuadError::invalid(
            "medium",
            "none",
            "one with a closed-form depth",
        ))?;
    Ok((-s.lambda * depth).exp())
}

fn cells() -> Result<Vec<Cell>, QuadError> {
    let mut out: Vec<Cell> = Vec::new();
    let blobs = Arc::new(blobs()?);
    let spheres = [
        (1.0, Arc::new(sphere(1.0)?)),
        (0.25, Arc::new(sphere(0.25)?)),
    ];
    let white = IntegratingSphere::furnace(1.0, 0.9, 1.0)?;
    let cap = IntegratingSphere::new(1.0, 0.7, 2.0, 0.6, Vec3::z())?;
    let x_white = white.wall(Vec3::new(0.0, 0.6, 0.8));
    let x_cap = cap.wall(Vec3::new(0.3, 0.0, -1.0));
    // The cap's irradiance at `x_cap`, `int L_e cos dw`, from the closed
    // form of one bounce: `L_1 = L_e + (rho / pi) E`.
    let cap_irradiance =
        (cap.truncated(&x_cap, 1) - cap.emitted(&x_cap)) * std::f64::consts::PI / cap.albedo();
    let inward = Hemisphere {
        frame: Frame::from_normal(-x_cap)?,
        map: HemisphereMap::Projected,
    };
    for name in ["monte-carlo", "stratified", "sobol"] {
        let rule = AnyRule::by_name(name)?;
        let r = rule.clone();
        out.push((
            format!("{name} | e^x on [0, 1]"),
            std::f64::consts::E - 1.0,
            Box::new(move |n, seed| {
                let e = r.integrate::<1, f64, _, _>(n, &mut rng(seed), |u: [f64; 1]| u[0].exp())?;
                Ok((e.value, e.error, !e.reliable))
            }),
        ));
        let (b, m) = (blobs.clone(), Method::Rule(rule.clone()));
        out.push((
            format!("{name} | blob tau"),
            exact_tau(&blobs)?,
            Box::new(move |n, seed| tau(&b, &m, n, seed)),
        ));
        let r = rule.clone();
        out.push((
            format!("{name} | cap furnace E"),
            cap_irradiance,
            Box::new(move |n, seed| {
                let e = integrate_over(&r, &inward, n, &mut rng(seed), |w: Vec3| {
                    cap.next_wall(&x_cap, &w).map_or(0.0, |y| cap.emitted(&y))
                })?;
                Ok((e.value, e.error, !e.reliable))
            }),
        ));
    }
    for (what, s, x) in [
        ("white furnace rho 0.9 L", white, x_white),
        ("cap furnace L", cap, x_cap),
    ] {
        out.push((
            format!("path tracing | {what}"),
            s.radiance(&x),
            Box::new(move |n, seed| {
                let e = s.path_trace(&x, n, &mut rng(seed))?;
                Ok((e.value, e.error, !e.reliable))
            }),
        ));
    }
    for tracker in [Tracker::Ratio, Tracker::Delta] {
        let on = spheres
            .iter()
            .map(|(kappa, b)| (format!("sphere tau, depth {}", 2.0 * kappa), b));
        for (what, b) in on.chain([("blob tau".to_string(), &blobs)]) {
            let (exact, b) = (exact_tau(b)?, b.clone());
            out.push((
                format!("{} | {what}", tracker.name()),
                exact,
                Box::new(move |n, seed| tau(&b, &Method::Estimator(tracker), n, seed)),
            ));
        }
    }
    Ok(out)
}

fn main() -> Result<(), QuadError> {
    let repeats: u64 = std::env::args()
        .nth(1)
        .map(|a| {
            a.parse()
                .map_err(|_| QuadError::invalid("REPEATS", a, "a count"))
        })
        .transpose()?
        .unwrap_or(400);
    println!("| method | scene | n | flagged | unflagged coverage | RMS z |");
    println!("|---|---|---:|---:|---:|---:|");
    for (name, exact, run) in cells()? {
        for n in [16usize, 256] {
            let (mut flagged, mut covered, mut z2, mut kept) = (0u64, 0u64, 0.0, 0u64);
            for seed in 0..repeats {
                let (value, error, flag) = run(n, 1_000_000 + seed)?;
                if flag {
                    flagged += 1;
                    continue;
                }
                kept += 1;
                let z = (value - exact) / error;
                covered += (z.abs() <= 1.96) as u64;
                z2 += z * z;
            }
            let k = kept.max(1) as f64;
            println!(
                "| {name} | {n} | {flagged}/{repeats} | {:.3} | {:.2} |",
                covered as f64 / k,
                (z2 / k).sqrt()
            );
        }
    }
    Ok(())
}
