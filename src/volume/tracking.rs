//! Stochastic transmittance estimators, the peers renderers use for V-tau:
//! each draws free-flight distances against a majorant `sigma_bar >= sigma`
//! on every smooth piece of the ray and returns the mean of `n` independent
//! walks with its standard error.
//!
//! - Delta tracking (Woodcock): a tentative collision at `t` is real with
//!   probability `sigma(t)/sigma_bar`; a walk scores 1 if it leaves the piece
//!   without a real collision. Binary, unbiased.
//! - Ratio tracking (Cramer 1978; Novák et al. 2014): a walk scores
//!   `prod (1 - sigma(t_i)/sigma_bar)` over its tentative collisions.
//! - Residual ratio tracking (Novák et al. 2014): with a control
//!   `sigma_c = sigma_bar / 2`, `tau = exp(-sigma_c L) E[prod (1 - (sigma(t_i) - sigma_c)/sigma_r)]`,
//!   tentative collisions drawn against the residual majorant
//!   `sigma_r = sigma_bar / 2 >= |sigma - sigma_c|`.
//!
//! Over several pieces the per-walk scores multiply (independent pieces).

use rand::RngExt;

use super::medium::Medium;
use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::geometry::Ray;
use crate::quadrature::monte_carlo::Welford;

/// Which tracking estimator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tracker {
    /// Delta (Woodcock) tracking.
    Delta,
    /// Ratio tracking.
    Ratio,
    /// Residual ratio tracking with control `sigma_bar / 2`.
    ResidualRatio,
}

impl Tracker {
    /// Registry name.
    pub fn name(&self) -> &'static str {
        match self {
            Tracker::Delta => "delta-tracking",
            Tracker::Ratio => "ratio-tracking",
            Tracker::ResidualRatio => "residual-ratio-tracking",
        }
    }
}

/// Extinction `sigma = lambda v_r` of a medium.
#[derive(Debug, Clone, Copy)]
pub struct Extinction<'a> {
    /// The density field `v_r`.
    pub medium: &'a dyn Medium,
    /// The factor `lambda`.
    pub lambda: f64,
}

/// Estimates `tau(t0, t1)` along `ray` with `n` walks: the estimate, its
/// standard error and the density evaluations spent.
pub fn transmittance<Rg: rand::Rng + ?Sized>(
    tracker: Tracker,
    sigma: Extinction,
    ray: &Ray,
    t0: f64,
    t1: f64,
    n: usize,
    rng: &mut Rg,
) -> Result<Estimate<f64>, QuadError> {
    if n < 2 {
        return Err(QuadError::invalid(
            "n",
            n,
            "at least 2 walks (a standard error needs two)",
        ));
    }
    let Extinction { medium, lambda } = sigma;
    let pieces: Vec<(f64, f64, f64)> = medium
        .support(ray, t0, t1)
        .iter()
        .map(|s| {
            let bar = lambda * medium.max_density(ray, s.start(), s.end());
            (s.start(), s.end(), bar)
        })
        .collect();
    let mut walks = Welford::<f64>::default();
    let mut evaluations = 0u64;
    for _ in 0..n {
        let mut score = 1.0;
        for &(a, b, bar) in &pieces {
            if bar <= 0.0 {
                continue;
            }
            let (control, majorant) = match tracker {
                Tracker::ResidualRatio => (0.5 * bar, 0.5 * bar),
                _ => (0.0, bar),
            };
            if control > 0.0 {
                score *= (-control * (b - a)).exp();
            }
            let mut t = a;
            loop {
                // Free flight: -ln(1 - xi) / majorant, xi in [0, 1).
                t -= (-rng.random::<f64>()).ln_1p() / majorant;
                if t >= b {
                    break;
                }
                evaluations += 1;
                let sigma = lambda * medium.density(ray.at(t));
                match tracker {
                    Tracker::Delta => {
                        if rng.random::<f64>() < sigma / bar {
                            score = 0.0;
                            break;
                        }
                    }
                    Tracker::Ratio => score *= 1.0 - sigma / bar,
                    Tracker::ResidualRatio => score *= 1.0 - (sigma - control) / majorant,
                }
            }
            if score == 0.0 {
                break;
            }
        }
        walks.add(score);
    }
    Ok(Estimate {
        value: walks.mean(),
        error: walks.standard_error(),
        evaluations,
    })
}
