//! lightquad in a renderer's `cargo test`: statistical tests of samplers
//! and estimators, convergence orders, and ground truth for scenes built
//! in code.
//!
//! | what | where |
//! |---|---|
//! | a sampler against its density over a domain (chi-square, and the density's integral against the sampler's success rate) | [`ChiSquare`] |
//! | an estimator against a value: mean (t-test), variance, coverage of its error bars | [`EstimatorTest`] |
//! | the convergence order of a method over budgets, with its confidence interval | [`Order`] |
//! | the value of a quantity of any family's scene, by closed form or converged evaluation, with its accuracy | [`truth()`] |
//!
//! Every test is seeded (the same seed gives the same verdict) and made at
//! a stated `alpha`, Šidák-corrected over the checks of one call and over
//! the `tests` a suite says it makes, so that correct code fails a suite
//! with probability about `alpha` (measured in `tests/it/testing_api.rs`). Bad settings and bad values from the
//! code under test (a density that is negative or NaN, a point off the
//! domain) are an `Err` naming them, never a panic.
//!
//! The domains are those of [`crate::domain`], binned in their own
//! parameterization: [`Hemisphere::uniform`](crate::domain::Hemisphere::uniform)
//! (cells of equal solid angle), the sphere of directions
//! ([`SphericalCap::sphere`](crate::domain::SphericalCap::sphere) of radius
//! 1 about the origin), a spherical cap, a disk, a rectangle, a triangle,
//! a pixel, and the unit square ([`Pixel::unit_square`](crate::domain::Pixel::unit_square)).
//!
//! ```
//! use lightquad::testing::{EstimatorTest, Order};
//! use lightquad::rand::RngExt;
//!
//! // Monte Carlo of int_0^1 3 x^2 dx = 1 with n samples, and its standard error.
//! let mc = |n: usize, rng: &mut lightquad::rand_pcg::Pcg64| {
//!     let xs: Vec<f64> = (0..n).map(|_| 3.0 * rng.random::<f64>().powi(2)).collect();
//!     let mean = xs.iter().sum::<f64>() / n as f64;
//!     let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
//!     (mean, (var / n as f64).sqrt())
//! };
//! // Unbiased, with honest error bars, over 400 seeded repeats.
//! let outcome = EstimatorTest::new(400).seed(7).run(1.0, |rng| mc(64, rng))?;
//! outcome.assert_passed();
//! // Order 1/2 in the RMS error, within 0.1.
//! let order = Order::measure(&[16, 64, 256, 1024, 4096], 40, 7, 1.0, |n, rng| mc(n, rng).0)?;
//! order.assert_near(-0.5, 0.1);
//! # Ok::<(), lightquad::QuadError>(())
//! ```

pub mod chi_square;
pub mod estimator;
pub mod order;
pub mod truth;

pub use chi_square::ChiSquare;
pub use estimator::{Draw, EstimatorTest, Reference};
pub use order::Order;
pub use truth::{Truth, truth};

use crate::error::QuadError;

/// The per-test level that keeps the chance of any false call among `m`
/// tests at `alpha` (Šidák): `1 - (1 - alpha)^(1/m)`.
pub fn sidak(alpha: f64, m: usize) -> f64 {
    crate::experiment::report::verdict::sidak(alpha, m)
}

/// `alpha` in `(0, 1)`, else an error naming it.
fn check_alpha(alpha: f64) -> Result<(), QuadError> {
    if alpha > 0.0 && alpha < 1.0 {
        Ok(())
    } else {
        Err(QuadError::invalid(
            "alpha",
            alpha,
            "a probability in (0, 1)",
        ))
    }
}

/// `count` in `lo..=hi`, else an error naming it.
fn check_count(name: &str, count: usize, lo: usize, hi: usize) -> Result<(), QuadError> {
    if (lo..=hi).contains(&count) {
        Ok(())
    } else {
        Err(QuadError::invalid(
            name,
            count,
            format!("an integer in {lo}..={hi}"),
        ))
    }
}

/// The generator of repeat `k` of a test seeded with `seed`: its own
/// stream, so a repeat's draws do not depend on how many the others took.
fn repeat_rng(seed: u64, k: usize) -> rand_pcg::Pcg64 {
    rand_pcg::Pcg64::new(
        0xcafe_f00d_d15e_a5e5_u128 ^ (u128::from(seed) << 64),
        k as u128,
    )
}
