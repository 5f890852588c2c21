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
//!   `sigma_r = max(sigma_bar - sigma_c, sigma_c) >= |sigma - sigma_c|`.
//!
//! Every piece of the medium along the ray is cut into 16 spans (32 for
//! [`transmittance`]'s delta tracking, see `DELTA_SPANS`; one on a shadow
//! ray, whose one walk pays for its set-up), each with its own majorant
//! (and control);
//! the per-walk scores of the spans multiply, and a free flight that leaves a
//! span carries its unused optical depth into the next.
//!
//! [`radiance`] extends delta tracking from `tau` to V-E, V-B, V-L and V-I
//! the way a renderer estimates them (free-flight sampling against the
//! majorant, emission and next-event light at the tentative collisions, the
//! shadow ray's transmittance by ratio tracking); see there for the estimator
//! and why it is unbiased.
//!
//! **Errors.** A tracking estimate's error is the standard error of its walks,
//! except where that is known to mislead:
//! - delta tracking's `tau` scores are 0 or 1: the error is the half-width
//!   of the Wilson score interval at `z = 1.96`, divided by 1.96 (so
//!   `value +- 1.96 error` is an interval as wide as Wilson's and the error
//!   still reads as one standard error: it is the ordinary standard error up
//!   to O(1/n) once `k` and `n - k` are large, and stays honest at `k = 0`
//!   or `k = n`, where the sample standard error is 0);
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
//! // Residual ratio tracking with the mean as its control is exact in a constant
//! // medium: every walk scores alike, which the estimate flags.
//! let rrt = transmittance(Tracker::ResidualRatio, sigma, &ray, 0.0, 10.0, 100, &mut rng)?;
//! assert!((rrt.value - exact).abs() < 1e-14 && rrt.all_alike);
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use rand::RngExt;
use rand_distr::{Distribution, Exp1};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use std::f64::consts::PI;

use super::medium::Medium;
use super::scene::{DirectionalLight, EmissionMap, VolumeScene};
use super::terms::ShadowMethod;
use crate::domain::Vec3;
use crate::error::QuadError;
use crate::geometry::Ray;
use crate::quadrature::monte_carlo::{Welford, power_of_two_above};

/// One span of a piece of the medium's extent with its majorant
/// `bar >= sigma`, the control extinction (residual ratio tracking) and the
/// rate tentative collisions are drawn at.
struct Span {
    a: f64,
    b: f64,
    /// `lambda` times the medium's density bound on the span.
    bar: f64,
    /// The medium's density bound on the span (`bar / lambda`).
    v_bar: f64,
    control: f64,
    /// The rate `walk` and `delta_walks` draw tentative collisions at
    /// (`radiance`, where it is 0, draws at `1 / (b - a)` to score emission
    /// and light).
    majorant: f64,
}

/// A span as a walk crosses it: the rate's optical depth across it and its
/// inverse, computed once for all walks (a walk then adds and multiplies
/// where it would divide at every collision).
struct Crossing<'a> {
    span: &'a Span,
    /// `majorant (b - a)`.
    depth: f64,
    /// `1 / majorant`.
    inverse: f64,
    /// The rate's optical depth from the first crossing's start to this
    /// one's start and end (`end = start + depth`, rounded; the next
    /// crossing's `start` is this `end`, the same number).
    start: f64,
    end: f64,
}

impl<'a> Crossing<'a> {
    /// The spans with a positive rate; the others draw no collisions.
    fn of(spans: &'a [Span]) -> Vec<Crossing<'a>> {
        let mut start = 0.0;
        spans
            .iter()
            .filter(|s| s.majorant > 0.0)
            .map(|span| {
                let depth = span.majorant * (span.b - span.a);
                let end = start + depth;
                let crossing = Crossing {
                    span,
                    depth,
                    inverse: 1.0 / span.majorant,
                    start,
                    end,
                };
                start = end;
                crossing
            })
            .collect()
    }
}

/// The `z` of the two-sided 95% intervals the errors stand for.
const Z: f64 = 1.96;

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
    /// ([`Welford::interval_error`]), or its honest substitute (module documentation):
    /// the Wilson half-width over 1.96 for 0/1 scores, `W(n) D` when every
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
}

/// `W(n) = z / (2 (n + z^2))`: the half-width of the Wilson score interval
/// for 0 successes in `n` trials, `z^2 / (2 (n + z^2))`, divided by `z`.
fn wilson_unseen(n: u64) -> f64 {
    let n = n as f64;
    Z / (2.0 * (n + Z * Z))
}

/// The error of `k` successes in `n` 0/1 trials: the half-width of the
/// Wilson score interval, `z/(n + z^2) sqrt(k (n - k)/n + z^2/4)`, divided
/// by `z`. Up to O(1/n) it is the standard error `sqrt(p (1 - p) / n)` once
/// `k` and `n - k` are large; at `k = 0` or `k = n` it is `W(n)`, not 0.
/// `k > n` or `n = 0` is an error.
pub fn wilson_error(k: u64, n: u64) -> Result<f64, QuadError> {
    if n == 0 || k > n {
        return Err(QuadError::invalid(
            "k",
            format!("{k} of n = {n}"),
            "0 <= k <= n successes of n >= 1 trials",
        ));
    }
    let (k, n) = (k as f64, n as f64);
    Ok((k * (n - k) / n + 0.25 * Z * Z).sqrt() / (n + Z * Z))
}

/// Walk scores summed as the tracking errors need them.
#[derive(Debug, Clone, Default)]
struct Scores {
    walks: Welford<f64>,
    first: Option<f64>,
    alike: bool,
}

impl Scores {
    fn add(&mut self, x: f64) {
        match self.first {
            None => {
                self.first = Some(x);
                self.alike = true;
            }
            Some(f) => self.alike &= f == x,
        }
        self.walks.add(x);
    }

    /// The mean with its standard error; when every walk scored alike, the
    /// bound `W(n) D` with `D = spread(x)` instead.
    fn tracked(&self, evaluations: u64, spread: impl Fn(f64) -> f64) -> Tracked {
        let (n, x) = (self.walks.count(), self.walks.mean());
        // No unseen outcome can move a score (D = 0): the walks are exact,
        // not merely alike, and carry neither a bound nor the flag.
        let exact = self.alike && spread(x) == 0.0;
        let error = if self.alike {
            wilson_unseen(n) * spread(x)
        } else {
            self.walks.interval_error()
        };
        Tracked {
            value: x,
            error,
            evaluations,
            walks: n,
            all_alike: self.alike && !exact,
        }
    }

    /// The mean of 0/1 scores with the Wilson error.
    fn binary(&self, evaluations: u64) -> Tracked {
        let n = self.walks.count();
        let x = self.walks.mean();
        // n >= 2 walks (checked on entry) and 0 <= k <= n by construction.
        let k = ((x * n as f64).round() as u64).min(n);
        Tracked {
            value: x,
            error: wilson_error(k, n.max(1)).unwrap_or(f64::INFINITY),
            evaluations,
            walks: n,
            all_alike: self.alike,
        }
    }
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
    // without end (the hostile review of issue 10).
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

/// Spans per piece of the eye ray: its walks share them, so tight majorants
/// (few tentative collisions) are worth their set-up.
const SPANS: usize = 16;

/// Spans per piece of the ray for [`transmittance`]'s delta tracking: a walk
/// stops at its first real collision, so its look-ups beyond that one are
/// its null collisions, which tighter majorants cut (on the 32^3 grid of
/// `scripts/tracking_race.py`, 32 spans take delta tracking from 1.17 to 1.10
/// look-ups a walk and 4M walks on one thread from 0.20 s to 0.17 s; 64
/// spans gave the same majorants). [`radiance`]'s delta walks keep
/// `SPANS`: they also score emission and light at the null collisions.
const DELTA_SPANS: usize = 32;

/// Spans per piece of a shadow ray: one walk uses them, so their set-up (a
/// majorant each, a scan of the voxel grid's blocks) is most of its cost. On
/// the grid of `scripts/tracking_race.py`, V-L's time times its variance
/// (400k walks, one thread) was 1.39 with 1 span, 1.45 with 2, 3.11 with 4
/// and 5.02 with 8: a looser bound's extra look-ups cost less than the
/// bounds. (With one span, the up-front refusal of `spans` limits a shadow
/// chord's bound to an optical depth of 5e6, where 4 spans allowed 2e7.)
const SHADOW_SPANS: usize = 1;

/// The spans of `[t0, t1]` along `ray`: each piece of the medium's extent is
/// cut into `per_piece` equal spans with a majorant of their own (tight
/// majorants mean few tentative collisions); residual ratio tracking also
/// gets a control extinction per span, the span's mean from a 4-point
/// Gauss–Legendre rule, computed once for all walks (its evaluations are
/// added to `evaluations`).
fn spans(
    tracker: Tracker,
    sigma: Extinction,
    ray: &Ray,
    (t0, t1): (f64, f64),
    per_piece: usize,
    evaluations: &mut u64,
) -> Result<Vec<Span>, QuadError> {
    let Extinction { medium, lambda } = sigma;
    let mut spans: Vec<Span> = Vec::new();
    for (a, b) in medium.extent(ray, t0, t1) {
        let width = (b - a) / per_piece as f64;
        for i in 0..per_piece {
            let s0 = a + width * i as f64;
            let s1 = if i + 1 == per_piece { b } else { s0 + width };
            let v_bar = medium.max_density(ray, s0, s1);
            let bar = lambda * v_bar;
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
                    *evaluations += 4;
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
            let span = Span {
                a: s0,
                b: s1,
                bar,
                v_bar,
                control,
                majorant,
            };
            // Ratio tracking crosses the whole span: about `majorant * length`
            // tentative collisions per walk, known before the first walk.
            // Refuse now instead of spinning up to the cap on every walk. (The
            // rate ratio tracking then draws at is k times this, with k > 1
            // only where k D <= 256: ratio_rate_factor.)
            if tracker != Tracker::Delta && majorant * (s1 - s0) > (MAX_COLLISIONS / 2) as f64 {
                return Err(too_deep(&span, MAX_COLLISIONS / 2));
            }
            spans.push(span);
        }
    }
    if tracker == Tracker::Ratio {
        let depth: f64 = spans.iter().map(|s| s.bar * (s.b - s.a)).sum();
        let k = ratio_rate_factor(depth);
        for span in &mut spans {
            span.majorant = k * span.bar;
        }
    }
    Ok(spans)
}

/// Most tentative collisions per walk that [`ratio_rate_factor`] spends to
/// cut ratio tracking's variance (where the bound's own optical depth is
/// smaller).
const RATIO_COLLISIONS: f64 = 256.0;

/// `k`: ratio tracking draws its tentative collisions at `k` times the span's
/// bound `sigma_bar`, `k = min(2 D, 256 / D)` floored at 1, where `D = int
/// sigma_bar` is the bound's optical depth over the ray.
///
/// Why: with a rate `mu >= sigma` a walk's weight `prod (1 - sigma/mu)` has
/// mean `tau` and second moment `exp(-int (2 sigma - sigma^2 / mu))`
/// (Campbell's theorem for the Poisson process of rate `mu`), so its relative
/// variance is `exp(int sigma^2 / mu) - 1`: it falls as the rate rises while
/// the cost, `int mu` look-ups, rises linearly. At `mu = k sigma_bar` the
/// product of the two is at most `k D (exp(D/k) - 1)`, which falls toward
/// `D^2` as `k` grows: at `k = 1` it is `D (e^D - 1)` (4.8x `D^2` at
/// `D = 2.6`), at `k = 2 D` within 30% of it. (For any rate the product is at
/// least `(int sigma)^2`, by Cauchy–Schwarz.) The cap keeps a walk at
/// about 256 look-ups (or `D`, where the bound alone needs more): past a
/// depth of about 11 the variance is large for every affordable `k`.
/// Scores stay in `[0, 1]` since `mu >= sigma`.
fn ratio_rate_factor(depth: f64) -> f64 {
    if depth > 0.0 {
        (2.0 * depth).min(RATIO_COLLISIONS / depth).max(1.0)
    } else {
        1.0
    }
}

/// The error returned when a walk needs more than `limit` tentative
/// collisions on one span: [`MAX_COLLISIONS`] for a walk that reached the
/// cap, half of it for a ratio-tracking span refused before the first walk
/// (its collisions are about the span's majorant depth).
fn too_deep(span: &Span, limit: u64) -> QuadError {
    QuadError::TooDeepForTracking {
        depth: span.majorant * (span.b - span.a),
        limit,
    }
}

/// A free flight's optical depth, a standard exponential variate: `rand_distr`'s
/// ziggurat sampler, a table look-up for all but about 1% of draws (a
/// logarithm per draw was a quarter of a ratio-tracking walk).
fn free_flight<Rg: rand::Rng + ?Sized>(rng: &mut Rg) -> f64 {
    Exp1.sample(rng)
}

/// One ratio-tracking walk's transmittance score over `crossings`, the spans
/// with a positive rate (module documentation): at each tentative collision
/// it is multiplied by `1 - (sigma - sigma_c) / mu`, with `sigma_c` the span's
/// control (residual ratio tracking; 0 for plain ratio tracking), and
/// `control` is the factor `exp(-int sigma_c)` of the controls (1 with none).
///
/// Free flights are drawn as optical depths `e ~ Exp(1)` in the rate,
/// measured from the span's start: a flight that leaves a span carries its
/// unused depth into the next (the exponential is memoryless), so crossing a
/// span costs a comparison, not a draw.
fn walk<Rg: rand::Rng + ?Sized>(
    sigma: Extinction,
    ray: &Ray,
    control: f64,
    crossings: &[Crossing],
    evaluations: &mut u64,
    rng: &mut Rg,
) -> Result<f64, QuadError> {
    let Extinction { medium, lambda } = sigma;
    let mut score = control;
    let mut e = free_flight(rng);
    for crossing in crossings {
        let span = crossing.span;
        let mut collisions = 0u64;
        while e < crossing.depth {
            let t = span.a + e * crossing.inverse;
            e += free_flight(rng);
            *evaluations += 1;
            collisions += 1;
            if collisions > MAX_COLLISIONS {
                return Err(too_deep(span, MAX_COLLISIONS));
            }
            let sigma = lambda * medium.density(ray.at(t));
            score *= 1.0 - (sigma - span.control) * crossing.inverse;
        }
        e -= crossing.depth;
    }
    Ok(score)
}

/// Where a free flight that starts at the first crossing lands, by its
/// accumulated optical depth `e` in the rate: the crossings' ends, and for
/// each of `cells` equal steps of depth the crossing its start lands in
/// (a table look-up and a step or two instead of a search).
struct Course {
    ends: Vec<f64>,
    first: Vec<usize>,
    /// Cells per unit of depth.
    scale: f64,
}

impl Course {
    /// Cells per crossing in the table.
    const CELLS: usize = 4;

    fn new(crossings: &[Crossing]) -> Course {
        let ends: Vec<f64> = crossings.iter().map(|c| c.end).collect();
        let total = ends.last().copied().unwrap_or(0.0);
        let cells = Self::CELLS * ends.len().max(1);
        let scale = if total > 0.0 {
            cells as f64 / total
        } else {
            0.0
        };
        let first = (0..=cells)
            .map(|k| ends.partition_point(|&end| end * scale <= k as f64))
            .collect();
        Course { ends, first, scale }
    }

    /// The crossing with `start <= e < end`, or the number of crossings
    /// where `e` is past the last end. Exact whatever the table's rounding:
    /// the steps from its entry compare with the ends themselves.
    #[inline]
    fn find(&self, e: f64) -> usize {
        // A saturating cast: e >= 0 (NaN, which cannot occur, gives 0).
        let cell = ((e * self.scale) as usize).min(self.first.len() - 1);
        let mut i = self.first[cell];
        while i > 0 && self.ends[i - 1] > e {
            i -= 1;
        }
        while i < self.ends.len() && self.ends[i] <= e {
            i += 1;
        }
        i
    }
}

/// `n` delta-tracking walks over `crossings`: how many got through without a
/// real collision.
///
/// A walk's free flights add up one optical depth `e ~ Exp(1) + Exp(1) +
/// ...` in the rate, measured from the first crossing's start: a flight ends
/// in the crossing with `start <= e < end` ([`Course::find`]), at `t = a +
/// (e - start) / majorant`, or past the last, where the walk got through (the
/// exponential is memoryless, so leaving a span costs no draw). A tentative
/// collision at `t` is real with probability `sigma(t) / sigma_bar`, and ends
/// the walk.
///
/// The walks advance side by side, up to `BATCH` of them, one tentative
/// collision each per round: the round's look-ups are one call of
/// [`Medium::densities`], where neighbouring look-ups overlap instead of
/// each waiting on its loads behind a dynamic call (the look-up was half a
/// walk's time: 0.165 s to 0.127 s for 4M walks on the race's grid), and a
/// walk that ends hands its place to a fresh one. Each walk is still a
/// walk of its own, drawn from its own variates. (A walk past the cap of
/// [`MAX_COLLISIONS`] a span ends them all with an error, but only after the
/// batch's other walks have taken as many steps: up to 64 times the cap's
/// look-ups.)
fn delta_walks<Rg: rand::Rng + ?Sized>(
    sigma: Extinction,
    ray: &Ray,
    crossings: &[Crossing],
    n: usize,
    evaluations: &mut u64,
    rng: &mut Rg,
) -> Result<u64, QuadError> {
    /// Walks in flight: their tentative collisions are looked up in one
    /// batch ([`Medium::densities`]).
    const BATCH: usize = 64;
    /// A walk in flight: its accumulated depth, the crossing of its last
    /// tentative collision and how many it has had there.
    #[derive(Clone, Copy)]
    struct Walker {
        e: f64,
        at: usize,
        collisions: u64,
    }
    let Extinction { medium, lambda } = sigma;
    let course = Course::new(crossings);
    let mut through = 0u64;
    let mut started = 0usize;
    let mut live: Vec<Walker> = Vec::with_capacity(BATCH);
    let mut points = [Vec3::zeros(); BATCH];
    let mut bars = [0.0; BATCH];
    let mut densities = [0.0; BATCH];
    while started < n || !live.is_empty() {
        // Fresh walks fill the batch.
        while live.len() < BATCH && started < n {
            live.push(Walker {
                e: free_flight(rng),
                at: usize::MAX,
                collisions: 0,
            });
            started += 1;
        }
        // Each walk's tentative collision, or its way out past the last
        // crossing (kept walks are packed to the front).
        let mut m = 0;
        for j in 0..live.len() {
            let mut w = live[j];
            let i = course.find(w.e);
            let Some(c) = crossings.get(i) else {
                through += 1;
                continue;
            };
            w.collisions = if i == w.at { w.collisions + 1 } else { 1 };
            w.at = i;
            if w.collisions > MAX_COLLISIONS {
                return Err(too_deep(c.span, MAX_COLLISIONS));
            }
            // Rounding must not carry the point past the span's end.
            let t = (c.span.a + (w.e - c.start) * c.inverse).min(c.span.b);
            points[m] = ray.at(t);
            bars[m] = c.span.bar;
            live[m] = w;
            m += 1;
        }
        live.truncate(m);
        medium.densities(&points[..m], &mut densities[..m]);
        *evaluations += m as u64;
        // Real collisions end their walks; the others fly on.
        let mut kept = 0;
        for j in 0..m {
            if rng.random::<f64>() * bars[j] < lambda * densities[j] {
                continue;
            }
            let mut w = live[j];
            w.e += free_flight(rng);
            live[kept] = w;
            kept += 1;
        }
        live.truncate(kept);
    }
    Ok(through)
}

/// Which walks a cost estimate ([`expected_lookups`]) is for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Walks {
    /// [`transmittance`]'s, with this tracker.
    Transmittance(Tracker),
    /// [`radiance`]'s, scoring these terms, shadow rays by this method.
    Radiance(ShadowMethod, Wanted),
}

/// The expected density look-ups of one walk along the eye ray of `scene`
/// (its tentative collisions, and a shadow ray's for each where they are
/// tracked), from the spans the walks use, before any walk: what a run
/// costs. Over a span of length `L`, rate `mu` and extinction at least `m`
/// ([`Medium::min_density`]):
///
/// - ratio tracking crosses every span: `sum mu L`, `mu = k sigma_bar`
///   (`ratio_rate_factor`); residual ratio tracking's `mu` is its
///   residual bound;
/// - a delta-tracking walk reaches the span with probability at most
///   `S = exp(-sum of m L over the spans before it)`, and then has at most
///   `mu (1 - exp(-m L)) / m` tentative collisions there (`mu L` where
///   `m = 0`): the sum is an upper bound, equal to the expectation where
///   the density is constant;
/// - each tentative collision of a radiance walk that scores V-L casts a
///   shadow ray, ratio tracking over one span where the medium has no
///   closed form for it: on each span of the eye ray, the larger `mu L` of
///   the shadow rays from the span's two ends (an estimate, not a bound:
///   a shadow ray from inside the span may cross more).
pub fn expected_lookups(scene: &VolumeScene, walks: Walks) -> Result<f64, QuadError> {
    let Some(medium) = scene.medium.as_deref() else {
        return Ok(0.0);
    };
    let sigma = Extinction {
        medium,
        lambda: scene.lambda,
    };
    let (ray, t0, t1) = (scene.ray, scene.t_min, scene.t_max);
    let mut unused = 0;
    let crossing = |s: &Span| s.majorant * (s.b - s.a);
    match walks {
        Walks::Transmittance(Tracker::Delta) => {
            let spans = spans(
                Tracker::Delta,
                sigma,
                &ray,
                (t0, t1),
                DELTA_SPANS,
                &mut unused,
            )?;
            Ok(delta_lookups(sigma, &ray, &spans, |s| s.bar).iter().sum())
        }
        Walks::Transmittance(tracker) => {
            let spans = spans(tracker, sigma, &ray, (t0, t1), SPANS, &mut unused)?;
            Ok(spans.iter().map(crossing).sum())
        }
        Walks::Radiance(shadow, wanted) => {
            let spans = spans(Tracker::Delta, sigma, &ray, (t0, t1), SPANS, &mut unused)?;
            let light = scene.light.filter(|_| wanted.light);
            let scoring = light.is_some() || (wanted.emission && scene.emission.is_some());
            // radiance's rate: the bound, or one per span where it is 0 and
            // a walk scores there.
            let rate = |s: &Span| match (s.bar > 0.0, scoring) {
                (true, _) => s.bar,
                (false, true) => 1.0 / (s.b - s.a),
                (false, false) => 0.0,
            };
            let eye = delta_lookups(sigma, &ray, &spans, rate);
            let Some(l) = light else {
                return Ok(eye.iter().sum());
            };
            // A shadow ray's look-ups from the point at `t` of the eye ray.
            let mut shadow_from = |t: f64| -> Result<f64, QuadError> {
                let shadow_ray = Ray {
                    origin: ray.at(t),
                    dir: l.toward_light,
                };
                let closed = shadow == ShadowMethod::ClosedFormWhereAvailable
                    && medium
                        .density_integral(&shadow_ray, 0.0, f64::INFINITY)
                        .is_some();
                // A shadow ray that tracking refuses (too deep a bound)
                // counts at the refusal's threshold: walks that collide
                // near it fail when they run.
                Ok(if closed {
                    0.0
                } else {
                    spans_of_shadow(sigma, &shadow_ray, &mut unused)
                        .map_or((MAX_COLLISIONS / 2) as f64, |s| {
                            s.iter().map(crossing).sum()
                        })
                })
            };
            let mut total = 0.0;
            let mut before = spans.first().map_or(Ok(0.0), |s| shadow_from(s.a))?;
            for (span, eye) in spans.iter().zip(eye) {
                let after = shadow_from(span.b)?;
                total += eye * (1.0 + before.max(after));
                before = after;
            }
            Ok(total)
        }
    }
}

/// The bound of [`expected_lookups`] on a delta-tracking walk's tentative
/// collisions on each of `spans` at the rate `rate(span)`.
fn delta_lookups(
    sigma: Extinction,
    ray: &Ray,
    spans: &[Span],
    rate: impl Fn(&Span) -> f64,
) -> Vec<f64> {
    let mut reach = 1.0;
    let mut each = Vec::with_capacity(spans.len());
    for s in spans {
        let length = s.b - s.a;
        // A span rounded to length 0 takes no collision (its rate may be
        // 1 / 0 where radiance scores on a span without extinction).
        if length <= 0.0 {
            each.push(0.0);
            continue;
        }
        let depth = sigma.lambda * sigma.medium.min_density(ray, s.a, s.b) * length;
        // int_0^L exp(-m t) dt = L (1 - exp(-m L)) / (m L).
        let within = if depth > 0.0 {
            length * (-(-depth).exp_m1() / depth)
        } else {
            length
        };
        each.push(reach * rate(s) * within);
        reach *= (-depth).exp();
    }
    each
}

/// `exp(-int sigma_c)`: the controls' factor of residual ratio tracking's
/// score (1 for the other trackers, whose control is 0).
fn control_factor(spans: &[Span]) -> f64 {
    let depth: f64 = spans.iter().map(|s| s.control * (s.b - s.a)).sum();
    (-depth).exp()
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
        });
    }
    let (control, crossings) = (control_factor(&spans), Crossing::of(&spans));
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
    Ok(scores.tracked(evaluations, |x| x.max(1.0 - x)))
}

/// What [`radiance`] scores besides `tau`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Wanted {
    /// V-E.
    pub emission: bool,
    /// V-L.
    pub light: bool,
}

/// The quantities of one set of delta-tracking walks along the eye ray, each
/// with the evaluations of all of them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Radiance {
    /// V-tau over the looked-at part.
    pub tau: Tracked,
    /// V-B: `I_b` times each walk's `tau` score.
    pub background: Tracked,
    /// V-E (0 with no error when not wanted or the scene does not emit).
    pub emission: Tracked,
    /// V-L (0 with no error when not wanted or the scene has no light).
    pub light: Tracked,
    /// V-I: each walk's V-E + V-B + V-L scores summed, so the error holds
    /// their covariance.
    pub total: Tracked,
}

/// Estimates V-tau, V-B, V-E, V-L and V-I along the eye ray of `scene` with
/// `n` delta-tracking walks, the way a renderer does (pbrt-v4's volumetric
/// path tracer, restricted to single scattering toward the light):
///
/// A walk draws tentative collisions `t_i` at the piecewise-constant rate
/// `mu` (the span's majorant `sigma_bar`; `1 / span length` on a span whose
/// majorant is 0) and stops at the first that is real (probability
/// `sigma(t_i) / mu`). At every tentative collision before it stops, the
/// stopping one included, it scores
///
/// `[c(v(t_i)) + I_p^(t_i) s(t_i)] / mu(t_i)`,
///
/// with `c` the emission map, `s = albedo sigma / (4 pi)` (V-L with single
/// scattering) or 1 (V-L as printed), and `I_p^(t)` the light reaching
/// `r(t)` (V-Lp): `I_p exp(-lambda int v)` along the shadow ray in closed
/// form where `shadow` allows and the medium has one, else `I_p` times one
/// ratio-tracking walk of the shadow ray (an unbiased estimate of its
/// transmittance, drawn independently of the eye walk).
///
/// Unbiased: the tentative collisions are a Poisson process of rate `mu`,
/// and the walk is still going at `t` exactly when no real collision fell
/// in `[t_n, t)`, which has probability `tau(t_n, t)` (real collisions are
/// the thinned process of rate `sigma`). So the expected sum is
/// `int mu(t) tau(t_n, t) [c + I_p(t) s] / mu dt = I_E + I_L` (V-E, V-L),
/// for every `mu > 0` with `mu >= sigma`, also where `sigma = 0` (where a
/// collision estimator `c / sigma` at the real collision would be undefined
/// and miss the emission). With `s = albedo sigma / (4 pi)` this is the
/// expectation, over the real/null choice, of the renderer's next-event
/// estimate at real collisions (`albedo I_p^ / (4 pi)` with probability
/// `sigma / mu`); the emission part is pbrt-v4's `sigma_a L_e / sigma_maj` at
/// every majorant event. A walk that leaves the looked-at part scores
/// `tau = 1` and `I_b` for V-B.
pub fn radiance<Rg: rand::Rng + ?Sized>(
    scene: &VolumeScene,
    shadow: ShadowMethod,
    wanted: Wanted,
    n: usize,
    rng: &mut Rg,
) -> Result<Radiance, QuadError> {
    scene.validate()?;
    let (t0, t1) = (scene.t_min, scene.t_max);
    check(scene.lambda, t0, t1, n)?;
    let lambda = scene.lambda;
    let ray = scene.ray;
    let background = scene.background.unwrap_or(0.0);
    let emission = scene.emission.as_ref().filter(|_| wanted.emission);
    // Collisions score c(v) of the density they happen at; an emission field
    // of its own (which may emit where the medium does not) is not a map of
    // the density, and walks confined to the medium would miss it.
    if let Some(EmissionMap::Field(_)) = emission {
        return Err(QuadError::invalid(
            "emission",
            "field",
            "a map of the density (constant, proportional, table) for delta tracking, which \
             scores c(v) at its collisions; integrate an emission field with a quadrature rule",
        ));
    }
    let light = scene.light.filter(|_| wanted.light);
    let Some(medium) = scene.medium.as_deref() else {
        // No medium: tau = 1, I_B = I_b, no emission and no scattering.
        let exact = |value: f64| Tracked {
            value,
            error: 0.0,
            evaluations: 0,
            walks: n as u64,
            all_alike: false,
        };
        return Ok(Radiance {
            tau: exact(1.0),
            background: exact(background),
            emission: exact(0.0),
            light: exact(0.0),
            total: exact(background),
        });
    };
    let sigma = Extinction { medium, lambda };
    let mut evaluations = 0u64;
    let spans = spans(
        Tracker::Delta,
        sigma,
        &ray,
        (t0, t1),
        SPANS,
        &mut evaluations,
    )?;
    let scoring = emission.is_some() || light.is_some();

    // The largest score one tentative collision can add on a span, for the
    // bound of Tracked::all_alike: |c| at the density bound (constant and
    // proportional maps are monotone in v; a table's largest value bounds it
    // anywhere) and I_p s at the density bound, over the rate.
    let rate = |span: &Span| {
        if span.bar > 0.0 {
            span.bar
        } else {
            1.0 / (span.b - span.a)
        }
    };
    let largest_c = |span: &Span, map: &EmissionMap| match map {
        EmissionMap::Table(table) => table.points().iter().map(|p| p.1.abs()).fold(0.0, f64::max),
        _ => map.at(span.v_bar).abs(),
    };
    let largest_s =
        |span: &Span, l: &DirectionalLight| l.albedo.map_or(1.0, |a| a * span.bar / (4.0 * PI));
    // Scores are summed in units: a power of two no smaller than the largest
    // |c| (V-E) or I_p s (V-L), so that one collision's `c / mu` stays finite
    // where `mu` is small (c = 8e306 and sigma = 2.6e-3 overflowed to inf
    // although I_E is 4e304) and scaling back is exact.
    let unit_of = |largest: f64| {
        if largest > 0.0 && largest.is_finite() {
            power_of_two_above(largest)
        } else {
            1.0
        }
    };
    let em_unit = unit_of(emission.map_or(0.0, |map| {
        spans.iter().map(|s| largest_c(s, map)).fold(0.0, f64::max)
    }));
    let li_unit = unit_of(light.map_or(0.0, |l| {
        spans
            .iter()
            .map(|s| l.intensity * largest_s(s, &l))
            .fold(0.0, f64::max)
    }));
    let total_unit = em_unit.max(li_unit).max(unit_of(background.abs()));
    let mut one_emission: f64 = 0.0;
    let mut one_light: f64 = 0.0;
    for span in &spans {
        if let Some(map) = emission {
            one_emission = one_emission.max(largest_c(span, map) / em_unit / rate(span));
        }
        if let Some(l) = light {
            one_light = one_light.max(l.intensity / li_unit * largest_s(span, &l) / rate(span));
        }
    }

    let (mut tau_s, mut bg_s, mut em_s, mut li_s, mut tot_s) = (
        Scores::default(),
        Scores::default(),
        Scores::default(),
        Scores::default(),
        Scores::default(),
    );
    for _ in 0..n {
        let (mut alive, mut em, mut li) = (true, 0.0, 0.0);
        'spans: for span in &spans {
            // Spans without extinction are crossed without tentative
            // collisions unless emission or light is scored on them.
            if span.bar <= 0.0 && !scoring {
                continue;
            }
            let mu = rate(span);
            let mut t = span.a;
            let mut collisions = 0u64;
            loop {
                t += free_flight(rng) / mu;
                if t >= span.b {
                    break;
                }
                evaluations += 1;
                collisions += 1;
                if collisions > MAX_COLLISIONS {
                    return Err(too_deep(span, MAX_COLLISIONS));
                }
                let p = ray.at(t);
                let v = medium.density(p);
                let sigma_t = lambda * v;
                if let Some(map) = emission {
                    em += map.at(v) / em_unit / mu;
                }
                if let Some(l) = light {
                    let shadow_ray = Ray {
                        origin: p,
                        dir: l.toward_light,
                    };
                    let closed = match shadow {
                        ShadowMethod::ClosedFormWhereAvailable => {
                            medium.density_integral(&shadow_ray, 0.0, f64::INFINITY)
                        }
                        ShadowMethod::Quadrature => None,
                    };
                    let shadow_tau = match closed {
                        Some(integral) => (-lambda * integral).exp(),
                        None => {
                            let mut evals = 0;
                            let s = spans_of_shadow(sigma, &shadow_ray, &mut evals)?;
                            let c = Crossing::of(&s);
                            let tau = walk(sigma, &shadow_ray, 1.0, &c, &mut evals, rng)?;
                            evaluations += evals;
                            tau
                        }
                    };
                    let s = l.albedo.map_or(1.0, |a| a * sigma_t / (4.0 * PI));
                    li += l.intensity / li_unit * shadow_tau * s / mu;
                }
                if rng.random::<f64>() < sigma_t / mu {
                    alive = false;
                    break 'spans;
                }
            }
        }
        let tau = if alive { 1.0 } else { 0.0 };
        tau_s.add(tau);
        bg_s.add(background * tau);
        em_s.add(em);
        li_s.add(li);
        tot_s.add(
            em * (em_unit / total_unit)
                + background / total_unit * tau
                + li * (li_unit / total_unit),
        );
    }
    let tau = tau_s.binary(evaluations);
    let scaled = |t: Tracked, s: f64| Tracked {
        value: t.value * s,
        error: t.error * s,
        ..t
    };
    // An unseen outcome moves a V-E, V-L or V-I score by at most the larger
    // of its own size and one tentative collision's largest score (plus I_b
    // for the escape or not of V-I).
    let unseen = |one: f64| move |x: f64| x.abs().max(one);
    // A term the scene lacks (or that was not asked for) is exactly 0; the
    // others are scaled back from their units.
    let term = |present: bool, scores: &Scores, one: f64, unit: f64| {
        if present {
            scaled(scores.tracked(evaluations, unseen(one)), unit)
        } else {
            Tracked {
                value: 0.0,
                error: 0.0,
                evaluations,
                walks: n as u64,
                all_alike: false,
            }
        }
    };
    let one_total = one_emission * (em_unit / total_unit)
        + one_light * (li_unit / total_unit)
        + background.abs() / total_unit;
    Ok(Radiance {
        tau,
        background: scaled(tau, background),
        emission: term(emission.is_some(), &em_s, one_emission, em_unit),
        light: term(light.is_some(), &li_s, one_light, li_unit),
        total: scaled(tot_s.tracked(evaluations, unseen(one_total)), total_unit),
    })
}

/// The ratio-tracking spans of a shadow ray from its origin to infinity.
fn spans_of_shadow(
    sigma: Extinction,
    shadow_ray: &Ray,
    evaluations: &mut u64,
) -> Result<Vec<Span>, QuadError> {
    let whole = (0.0, f64::INFINITY);
    spans(
        Tracker::Ratio,
        sigma,
        shadow_ray,
        whole,
        SHADOW_SPANS,
        evaluations,
    )
}

#[cfg(test)]
mod tests {
    use super::{Course, Crossing, Span};
    use rand::{RngExt, SeedableRng};

    /// `Course::find` against a count of the ends at or below `e`, on
    /// crossings of very unequal depths (a table cell then spans several
    /// crossings, or a crossing several cells), at the ends themselves, just
    /// beside them, past the last and at 0.
    #[test]
    fn course_find_is_the_count_of_ends_at_or_below() {
        let widths = [1e-9, 0.5, 3.0, 1e-6, 0.25, 7.0, 1e-3, 0.125];
        let mut a = 0.0;
        let spans: Vec<Span> = widths
            .iter()
            .enumerate()
            .map(|(i, &w)| {
                let majorant = 1.0 + i as f64 / 3.0;
                let span = Span {
                    a,
                    b: a + w,
                    bar: majorant,
                    v_bar: majorant,
                    control: 0.0,
                    majorant,
                };
                a += w;
                span
            })
            .collect();
        let crossings = Crossing::of(&spans);
        let course = Course::new(&crossings);
        let ends: Vec<f64> = crossings.iter().map(|c| c.end).collect();
        let count = |e: f64| ends.iter().filter(|&&end| end <= e).count();
        let mut probes = vec![0.0, 2.0 * ends[ends.len() - 1], f64::MAX];
        for &end in &ends {
            probes.extend([end, end.next_down(), end.next_up()]);
        }
        let mut rng = rand_pcg::Pcg64::seed_from_u64(5);
        probes.extend((0..10_000).map(|_| rng.random::<f64>() * 1.1 * ends[ends.len() - 1]));
        for e in probes {
            assert_eq!(course.find(e), count(e), "e = {e:e}");
        }
    }
}
