//! Stochastic transmittance estimators, the peers renderers use for V-tau:
//! each draws free-flight distances against a majorant `sigma_bar >= sigma`
//! on every smooth piece of the ray and returns the mean of `n` independent
//! walks with its standard error.
//!
//! - Delta tracking (Woodcock): a tentative collision at `t` is real with
//!   probability `sigma(t)/sigma_bar`; a walk scores 1 if it leaves the piece
//!   without a real collision. Binary, unbiased.
//! - Ratio tracking (Cramer 1978; Novák et al. 2014): a walk scores
//!   `prod (1 - sigma(t_i)/mu)` over its tentative collisions, drawn at a
//!   rate `mu = k sigma_bar` a few times the bound, which trades look-ups
//!   for a much smaller variance (`k` and why: `ratio_rate_factor`).
//! - Residual ratio tracking (Novák et al. 2014): with a control extinction
//!   `sigma_c` (the span's mean, from a 4-point Gauss–Legendre rule),
//!   `tau = exp(-sigma_c L) E[prod (1 - (sigma(t_i) - sigma_c)/sigma_r)]`,
//!   tentative collisions drawn against the residual majorant
//!   `sigma_r = max(sigma_bar - sigma_c, sigma_c - sigma_min) >= |sigma - sigma_c|`
//!   (`sigma_min` the medium's lower bound, 0 unless it knows better). On a
//!   span where the bounds meet (a constant medium) the control is the
//!   extinction, the residual 0, and no walk draws a collision there; where
//!   every span is so, tau is exact.
//!
//! Every piece of the medium along the ray is cut into 16 spans (32 for
//! [`transmittance`]'s delta tracking, see `DELTA_SPANS`; one on a shadow
//! ray, whose one walk pays for its set-up), each with its own majorant
//! (and control);
//! the per-walk scores of the spans multiply, and a free flight that leaves a
//! span carries its unused optical depth into the next.
//!
//! [`radiance`](fn@radiance) extends delta tracking from `tau` to V-E, V-B, V-L and V-I
//! the way a renderer estimates them (free-flight sampling against the
//! majorant, emission and next-event light at the tentative collisions, the
//! shadow ray's transmittance by ratio tracking); see there for the estimator
//! and why it is unbiased.
//!
//! **Errors.** A tracking estimate's error is the standard error of its walks,
//! except where that is known to mislead:
//! - delta tracking's `tau` scores are 0 or 1: the error is the standard
//!   error of a proportion taken at the Wilson score interval's centre
//!   (`z = 1.96`) instead of at the mean ([`wilson_error`]): the ordinary
//!   standard error up to O(1/n) once `k` and `n - k` are large, and
//!   honest at `k = 0` or `k = n`, where the sample standard error is 0,
//!   and at few walks, where Wilson's half-width put around the mean
//!   covered 86% (16 walks, `tau = 0.2`);
//! - any estimate whose walks all scored alike (zero sample variance, which
//!   says nothing about outcomes not yet seen) carries `W(n) D`, with
//!   `W(n) = z / (2 (n + z^2))` the Wilson half-width at `k = 0` divided by
//!   `z` (an outcome not seen in `n` walks has a probability of order
//!   `z^2 / (2 n)` or less) and `D` the largest change one unseen outcome
//!   makes to a walk's score (see [`Tracked::all_alike`]), and is flagged.
//!
//! ```
//! use lightquad::domain::Vec3;
//! use lightquad::geometry::Ray;
//! use lightquad::volume::ConstantSphere;
//! use lightquad::volume::tracking::{Extinction, Tracker, transmittance};
//! use rand::SeedableRng;
//!
//! // tau = exp(-sigma L) along the diameter (L = 2) of a unit sphere, sigma = 1.
//! let sphere = ConstantSphere::new(Vec3::zeros(), 1.0, 1.0)?;
//! let sigma = Extinction { medium: &sphere, lambda: 1.0 };
//! let ray = Ray::new(Vec3::new(-3.0, 0.0, 0.0), Vec3::x())?;
//! let exact = (-2.0f64).exp();
//! let mut rng = rand_pcg::Pcg64::seed_from_u64(1);
//! // Delta tracking scores 0 or 1: unbiased, within a few standard errors.
//! let delta = transmittance(Tracker::Delta, sigma, &ray, 0.0, 10.0, 4000, &mut rng)?;
//! assert!((delta.value - exact).abs() < 3.0 * delta.error && delta.error < 0.01);
//! // Residual ratio tracking in a medium known constant: the control is the
//! // extinction itself, no residual is left to track, and tau is exact.
//! let rrt = transmittance(Tracker::ResidualRatio, sigma, &ray, 0.0, 10.0, 100, &mut rng)?;
//! assert!((rrt.value - exact).abs() < 1e-14 && rrt.error < 1e-14 && !rrt.all_alike);
//! # Ok::<(), lightquad::QuadError>(())
//! ```

mod lookups;
mod radiance;
mod scores;
mod span;
mod walks;

pub use lookups::{Walks, expected_lookups};
pub use radiance::{Radiance, Wanted, radiance};
pub use scores::wilson_error;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::error::QuadError;
use crate::geometry::Ray;
use crate::volume::medium::Medium;

use scores::Scores;
use span::{Crossing, DELTA_SPANS, SPANS, control_factor, spans, underflows};
use walks::{delta_walks, walk};

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

/// A tracking estimate: the mean of `walks` walks and its error (see the
/// module documentation), with the density evaluations spent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tracked {
    /// The mean score.
    pub value: f64,
    /// One standard error widened to the Student-t interval
    /// ([`Welford::interval_error`](crate::quadrature::monte_carlo::Welford::interval_error)), or its honest substitute (module documentation):
    /// the Wilson-centred standard error for 0/1 scores
    /// ([`wilson_error`]), `W(n) D` when every
    /// walk scored alike.
    pub error: f64,
    /// Density evaluations spent (shared by every quantity of one set of walks).
    pub evaluations: u64,
    /// The number of walks.
    pub walks: u64,
    /// True when every walk scored the same: the sample variance is 0 and
    /// `error` is the bound `W(n) D`, where `D` bounds how far one unseen
    /// outcome moves a score: `max(x, 1 - x)` for a transmittance `x` (scores
    /// of delta and ratio tracking lie in [0, 1], and a score in [0, 1]
    /// equals 1 with probability at most its mean, so at the ends the bound
    /// is the binomial one; residual ratio tracking's scores may pass 1, and
    /// there it is a heuristic); for V-E, V-L and V-I the larger of `|x|`
    /// and one tentative collision's largest score.
    pub all_alike: bool,
    /// True when the walks' scores are carried by a few of them (their
    /// sample variance is itself too uncertain to stand behind the error,
    /// [`Welford::doubtful`](crate::quadrature::monte_carlo::Welford::doubtful)):
    /// the mean of a product of many factors (ratio tracking through an
    /// optical depth of hundreds, a shadow ray's transmittance inside a
    /// light's score) is carried by walks not yet seen, and the error can
    /// fall short of the truth by any factor. 0/1 scores (delta tracking's
    /// `tau`) are never heavy: their Wilson error is honest at any count.
    /// Measured over 200 seeds at 16, 256 and 4096 walks
    /// (tests/it/tracking_diagnostic.rs): every run of ratio tracking's
    /// `tau` through a constant sphere of optical depth 200 (and 173) and
    /// of delta tracking's `I_L` under a light along a ray of optical depth
    /// 100 is 4 or more standard errors off, and every one is flagged; on
    /// optical depths 0.1 to 5 (a light across the ray), Gaussian blobs and
    /// a voxel grid at most 3 of 200 runs at one budget are. What it cannot see: a skewed score whose rare large
    /// values 16 walks did not reach looks like a tame one (delta tracking's
    /// `I_L` under a light along a ray of optical depth 5: 31 of 200 runs at
    /// 16 walks are more than 4 standard errors off, unflagged; 3 at 256,
    /// none at 4096).
    pub heavy: bool,
    /// True when the true `tau` is certainly below the smallest normal f64
    /// (the optical depth of the medium's lower density bounds along the
    /// ray exceeds 708.4): an estimate of 0 then says nothing of its
    /// relative error, and `ln_tau` by quadrature holds the value.
    pub underflows: bool,
}

/// Checks the common arguments of the estimators.
fn check(lambda: f64, t0: f64, t1: f64, n: usize) -> Result<(), QuadError> {
    if !(lambda.is_finite() && lambda >= 0.0) {
        return Err(QuadError::invalid("lambda", lambda, "a finite number >= 0"));
    }
    if t0.is_nan() {
        return Err(QuadError::invalid("t0", t0, "a number <= t1"));
    }
    if t1.is_nan() || t1 < t0 {
        return Err(QuadError::invalid(
            "t1",
            t1,
            format!("a number >= t0 = {t0}"),
        ));
    }
    // The rules' budget limit holds for walks too: usize::MAX walks ran
    // without end.
    let max = crate::quadrature::MAX_BUDGET;
    if !(2..=max).contains(&n) {
        return Err(QuadError::invalid(
            "n",
            n,
            format!("2 to 2^40 = {max} walks (a standard error needs two)"),
        ));
    }
    Ok(())
}

/// Estimates `tau(t0, t1)` along `ray` with `n` walks: the estimate, its
/// error (module documentation) and the density evaluations spent.
pub fn transmittance<Rg: rand::Rng + ?Sized>(
    tracker: Tracker,
    sigma: Extinction,
    ray: &Ray,
    t0: f64,
    t1: f64,
    n: usize,
    rng: &mut Rg,
) -> Result<Tracked, QuadError> {
    check(sigma.lambda, t0, t1, n)?;
    let mut evaluations = 0u64;
    let per_piece = match tracker {
        Tracker::Delta => DELTA_SPANS,
        _ => SPANS,
    };
    let spans = spans(tracker, sigma, ray, (t0, t1), per_piece, &mut evaluations)?;
    // A majorant of 0 everywhere: no collision is possible, every walk scores
    // 1, and tau = 1 is exact (no Wilson bound, no flag).
    if spans.iter().all(|s| s.bar == 0.0) {
        return Ok(Tracked {
            value: 1.0,
            error: 0.0,
            evaluations,
            walks: n as u64,
            all_alike: false,
            heavy: false,
            underflows: false,
        });
    }
    let (control, crossings) = (control_factor(&spans), Crossing::of(&spans));
    let under = underflows(&spans);
    // Residual ratio tracking on spans whose density is known constant:
    // every residual is 0, no walk draws a collision, and tau is the
    // controls' factor, exact up to the rounding of its exponent.
    if tracker == Tracker::ResidualRatio && crossings.is_empty() {
        let depth: f64 = spans.iter().map(|s| s.control * (s.b - s.a)).sum();
        return Ok(Tracked {
            value: control,
            error: control * 4.0 * f64::EPSILON * (depth + spans.len() as f64),
            evaluations,
            walks: n as u64,
            all_alike: false,
            heavy: false,
            underflows: under,
        });
    }
    if tracker == Tracker::Delta {
        // Scores are 0 or 1: a count of the walks that got through is all
        // the Wilson error needs.
        let through = delta_walks(sigma, ray, &crossings, n, &mut evaluations, rng)?;
        let n = n as u64;
        return Ok(Tracked {
            value: through as f64 / n as f64,
            error: wilson_error(through, n)?,
            evaluations,
            walks: n,
            all_alike: through == 0 || through == n,
            heavy: false,
            underflows: under,
        });
    }
    let mut scores = Scores::default();
    for _ in 0..n {
        scores.add(walk(
            sigma,
            ray,
            control,
            &crossings,
            &mut evaluations,
            rng,
        )?);
    }
    // Scores in [0, 1] (residual ratio: a heuristic, see Tracked::all_alike).
    Ok(Tracked {
        underflows: under,
        ..scores.tracked(evaluations, |x| x.max(1.0 - x))
    })
}
