//! Tests a cosine-weighted hemisphere sampler against its density with
//! `lightquad::testing`, and two planted bugs that such a test must catch:
//! a density missing its cos factor, and a sampler off by a Jacobian (the
//! disk's radius drawn as `u` where it is `sqrt(u)`). Also the estimator
//! each gives of the irradiance from a sky of radiance `1 + w_x` (`pi`:
//! the gradient integrates to 0), and the order of its error.
//!
//! `cargo run --release --example verify_a_sampler` prints the verdicts
//! and exits 0 only when the correct sampler passes and both bugs are
//! caught.

use std::f64::consts::PI;
use std::process::ExitCode;

use lightquad::domain::{Hemisphere, Vec3};
use lightquad::rand::RngExt;
use lightquad::testing::{ChiSquare, EstimatorTest, Order};

/// Malley's method: a uniform point of the unit disk lifted to the
/// hemisphere; `sqrt(u_0)` is the disk's radius (the Jacobian of area).
fn cosine_sample(u: [f64; 2]) -> Option<Vec3> {
    let (r, phi) = (u[0].sqrt(), 2.0 * PI * u[1]);
    Some(Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u[0]).sqrt()))
}

/// The planted Jacobian bug: radius `u_0`, so the disk is not uniform.
fn cosine_sample_no_jacobian(u: [f64; 2]) -> Option<Vec3> {
    let (r, phi) = (u[0], 2.0 * PI * u[1]);
    Some(Vec3::new(
        r * phi.cos(),
        r * phi.sin(),
        ((1.0 - r) * (1.0 + r)).sqrt(),
    ))
}

/// The correct density in solid angle: `cos theta / pi`.
fn cosine_pdf(w: &Vec3) -> f64 {
    w.z / PI
}

/// The planted density bug: the cos factor forgotten.
fn pdf_without_cos(_: &Vec3) -> f64 {
    1.0 / PI
}

/// One case: a sampler, the density it claims, and whether it is right.
struct Case {
    name: &'static str,
    sample: fn([f64; 2]) -> Option<Vec3>,
    pdf: fn(&Vec3) -> f64,
    correct: bool,
}

/// The irradiance estimate `E = (1/n) sum L cos / pdf` from the sky
/// `L(w) = 1 + w_x` with `n` samples, and its standard error.
fn irradiance(case: &Case, n: usize, rng: &mut lightquad::rand_pcg::Pcg64) -> (f64, f64) {
    let (mut sum, mut sq) = (0.0, 0.0);
    for _ in 0..n {
        let u = [rng.random::<f64>(), rng.random::<f64>()];
        let x = (case.sample)(u).map_or(0.0, |w| (1.0 + w.x) * w.z / (case.pdf)(&w));
        sum += x;
        sq += x * x;
    }
    let mean = sum / n as f64;
    let var = ((sq - sum * mean) / (n - 1) as f64).max(0.0);
    (mean, (var / n as f64).sqrt())
}

fn main() -> Result<ExitCode, lightquad::QuadError> {
    let cases = [
        Case {
            name: "cosine-weighted sampler",
            sample: cosine_sample,
            pdf: cosine_pdf,
            correct: true,
        },
        Case {
            name: "planted bug: the pdf misses its cos factor",
            sample: cosine_sample,
            pdf: pdf_without_cos,
            correct: false,
        },
        Case {
            name: "planted bug: the sampler misses the Jacobian sqrt(u)",
            sample: cosine_sample_no_jacobian,
            pdf: cosine_pdf,
            correct: false,
        },
    ];
    // Two tests per case (the sampler's fit, the estimator), one alpha for all.
    let tests = 2 * cases.len();
    let chi2 = ChiSquare::new(Hemisphere::uniform()).tests(tests);
    let estimator = EstimatorTest::new(200).seed(1).tests(tests);
    let mut as_expected = true;
    for case in &cases {
        println!("== {} ==", case.name);
        let fit = chi2.run(case.pdf, case.sample, 1)?;
        println!("{fit}");
        let est = estimator.run(PI, |rng| irradiance(case, 256, rng))?;
        println!("irradiance from the sky 1 + w_x (pi), 256 samples: {est}");
        let order = Order::measure(&[64, 256, 1024, 4096], 32, 1, PI, |n, rng| {
            irradiance(case, n, rng).0
        })?;
        println!("order of its RMS error: {order}");
        let caught = !fit.passed || !est.passed;
        let verdict = match (case.correct, caught) {
            (true, false) => "passes, as it should",
            (false, true) => "caught, as it should be",
            (true, true) => "WRONGLY FAILED",
            (false, false) => "NOT CAUGHT",
        };
        println!("=> {verdict}\n");
        as_expected &= case.correct != caught;
    }
    Ok(if as_expected {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}
