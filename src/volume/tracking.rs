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
//! - Residual ratio tracking (Novák et al. 2014): with a control extinction
//!   `sigma_c` (the span's mean, from a 4-point Gauss–Legendre rule),
//!   `tau = exp(-sigma_c L) E[prod (1 - (sigma(t_i) - sigma_c)/sigma_r)]`,
//!   tentative collisions drawn against the residual majorant
//!   `sigma_r = max(sigma_bar - sigma_c, sigma_c) >= |sigma - sigma_c|`.
//!
//! Every smooth piece is cut into 16 spans, each with its own majorant (and
//! control); the per-walk scores of the spans multiply.

use rand::RngExt;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::medium::Medium;
use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::geometry::Ray;
use crate::quadrature::monte_carlo::Welford;

/// One span of a smooth piece with its majorant `bar >= sigma`, the control
/// extinction (residual ratio tracking) and the rate tentative collisions are
/// drawn at.
struct Span {
    a: f64,
    b: f64,
    bar: f64,
    control: f64,
    majorant: f64,
}

/// Tentative collisions allowed per walk and span before tracking gives up
/// (its cost grows with the majorant's optical depth).
const MAX_COLLISIONS: u64 = 10_000_000;

/// Which tracking estimator; its serde form is the estimator's spec in an
/// experiment file (`{"rule": "ratio-tracking"}`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "rule", deny_unknown_fields)]
pub enum Tracker {
    /// Delta (Woodcock) tracking.
    #[serde(rename = "delta-tracking")]
    Delta,
    /// Ratio tracking.
    #[serde(rename = "ratio-tracking")]
    Ratio,
    /// Residual ratio tracking with a control extinction per span (its mean).
    #[serde(rename = "residual-ratio-tracking")]
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
    if !(sigma.lambda.is_finite() && sigma.lambda >= 0.0) {
        return Err(QuadError::invalid(
            "lambda",
            sigma.lambda,
            "a finite number >= 0",
        ));
    }
    if t0.is_nan() || t1.is_nan() || t1 < t0 {
        return Err(QuadError::invalid(
            "t1",
            t1,
            format!("a number >= t0 = {t0}"),
        ));
    }
    if n < 2 {
        return Err(QuadError::invalid(
            "n",
            n,
            "at least 2 walks (a standard error needs two)",
        ));
    }
    let Extinction { medium, lambda } = sigma;
    // Each smooth piece is cut into SPANS equal spans with a majorant of their
    // own (tight majorants mean few tentative collisions); residual ratio
    // tracking also gets a control extinction per span, the span's mean from a
    // 4-point Gauss–Legendre rule, computed once for all walks.
    const SPANS: usize = 16;
    let mut evaluations = 0u64;
    let mut spans: Vec<Span> = Vec::new();
    for piece in medium.support(ray, t0, t1) {
        let (a, b) = (piece.start(), piece.end());
        let width = (b - a) / SPANS as f64;
        for i in 0..SPANS {
            let s0 = a + width * i as f64;
            let s1 = if i + 1 == SPANS { b } else { s0 + width };
            let bar = lambda * medium.max_density(ray, s0, s1);
            if !bar.is_finite() {
                return Err(QuadError::invalid(
                    "majorant",
                    bar,
                    "a finite extinction bound (lambda times the medium's density)",
                ));
            }
            let control = match tracker {
                Tracker::ResidualRatio => {
                    let gl = crate::quadrature::gauss_legendre::unit_nodes(4)?;
                    evaluations += 4;
                    let mean: f64 =
                        gl.u.iter()
                            .zip(&gl.w)
                            .map(|(u, w)| w * lambda * medium.density(ray.at(s0 + (s1 - s0) * u)))
                            .sum();
                    mean.clamp(0.0, bar)
                }
                _ => 0.0,
            };
            // The residual |sigma - control| is bounded by max(bar - control, control).
            let majorant = if control > 0.0 {
                (bar - control).max(control)
            } else {
                bar
            };
            spans.push(Span {
                a: s0,
                b: s1,
                bar,
                control,
                majorant,
            });
        }
    }
    let mut walks = Welford::<f64>::default();
    for _ in 0..n {
        let mut score = 1.0;
        for span in &spans {
            if span.control > 0.0 {
                score *= (-span.control * (span.b - span.a)).exp();
            }
            if span.majorant <= 0.0 {
                continue;
            }
            let mut t = span.a;
            let mut collisions = 0u64;
            loop {
                // Free flight: -ln(1 - xi) / majorant, xi in [0, 1).
                t -= (-rng.random::<f64>()).ln_1p() / span.majorant;
                if t >= span.b {
                    break;
                }
                evaluations += 1;
                collisions += 1;
                if collisions > MAX_COLLISIONS {
                    return Err(QuadError::invalid(
                        "optical depth",
                        span.majorant * (span.b - span.a),
                        format!(
                            "at most {MAX_COLLISIONS} tentative collisions per walk and span: \
                             the majorant's optical depth is too large for tracking"
                        ),
                    ));
                }
                let sigma = lambda * medium.density(ray.at(t));
                match tracker {
                    Tracker::Delta => {
                        if rng.random::<f64>() < sigma / span.bar {
                            score = 0.0;
                            break;
                        }
                    }
                    Tracker::Ratio => score *= 1.0 - sigma / span.bar,
                    Tracker::ResidualRatio => score *= 1.0 - (sigma - span.control) / span.majorant,
                }
            }
            if score == 0.0 {
                break;
            }
        }
        walks.add(score);
    }
    Ok(Estimate::random(
        walks.mean(),
        walks.standard_error(),
        evaluations,
    ))
}
