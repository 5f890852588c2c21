//! The spans a ray's medium is cut into, each with its own majorant (and
//! control), and the rates walks draw their tentative collisions at.

use crate::error::QuadError;
use crate::geometry::Ray;

use super::{Extinction, MAX_COLLISIONS, Tracker};

/// One span of a piece of the medium's extent with its majorant
/// `bar >= sigma`, the control extinction (residual ratio tracking) and the
/// rate tentative collisions are drawn at.
pub(super) struct Span {
    pub(super) a: f64,
    pub(super) b: f64,
    /// `lambda` times the medium's density bound on the span.
    pub(super) bar: f64,
    /// The medium's density bound on the span (`bar / lambda`).
    pub(super) v_bar: f64,
    pub(super) control: f64,
    /// `lambda` times the medium's lower density bound on the span.
    pub(super) floor: f64,
    /// The rate `walk` and `delta_walks` draw tentative collisions at
    /// (`radiance`, where it is 0, draws at `1 / (b - a)` to score emission
    /// and light).
    pub(super) majorant: f64,
}

/// A span as a walk crosses it: the rate's optical depth across it and its
/// inverse, computed once for all walks (a walk then adds and multiplies
/// where it would divide at every collision).
pub(super) struct Crossing<'a> {
    pub(super) span: &'a Span,
    /// `majorant (b - a)`.
    pub(super) depth: f64,
    /// `1 / majorant`.
    pub(super) inverse: f64,
    /// The rate's optical depth from the first crossing's start to this
    /// one's start and end (`end = start + depth`, rounded; the next
    /// crossing's `start` is this `end`, the same number).
    pub(super) start: f64,
    pub(super) end: f64,
}

impl<'a> Crossing<'a> {
    /// The spans with a positive rate; the others draw no collisions.
    pub(super) fn of(spans: &'a [Span]) -> Vec<Crossing<'a>> {
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

/// Spans per piece of the eye ray: its walks share them, so tight majorants
/// (few tentative collisions) are worth their set-up.
pub(super) const SPANS: usize = 16;

/// Spans per piece of the ray for [`transmittance`](super::transmittance)'s delta tracking: a walk
/// stops at its first real collision, so its look-ups beyond that one are
/// its null collisions, which tighter majorants cut (on the 32^3 grid of
/// `scripts/tracking_race.py`, 32 spans take delta tracking from 1.17 to 1.10
/// look-ups a walk and 4M walks on one thread from 0.20 s to 0.17 s; 64
/// spans gave the same majorants). [`radiance`](fn@super::radiance)'s delta walks keep
/// `SPANS`: they also score emission and light at the null collisions.
pub(super) const DELTA_SPANS: usize = 32;

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
pub(super) fn spans(
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
            // A density known constant on the span (its bounds meet) is its
            // own control, with no residual to track.
            let floor = lambda * medium.min_density(ray, s0, s1);
            let constant = tracker == Tracker::ResidualRatio && floor >= bar && bar > 0.0;
            let control = match tracker {
                Tracker::ResidualRatio if constant => bar,
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
            // The residual |sigma - control| is bounded by
            // max(bar - control, control - floor), floor a lower bound of
            // sigma (0 unless the medium knows better): 0 on a constant span.
            let majorant = if constant {
                0.0
            } else if control > 0.0 {
                (bar - control).max(control - floor)
            } else {
                bar
            };
            let span = Span {
                a: s0,
                b: s1,
                bar,
                v_bar,
                control,
                floor,
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
pub(super) fn too_deep(span: &Span, limit: u64) -> QuadError {
    QuadError::TooDeepForTracking {
        depth: span.majorant * (span.b - span.a),
        limit,
    }
}

/// `exp(-int sigma_c)`: the controls' factor of residual ratio tracking's
/// score (1 for the other trackers, whose control is 0).
/// True when `tau` over the spans is certainly below the smallest normal
/// f64: the optical depth of their lower bounds, `sum floor (b - a)`,
/// exceeds `-ln(f64::MIN_POSITIVE)` (708.4).
pub(super) fn underflows(spans: &[Span]) -> bool {
    let depth: f64 = spans.iter().map(|s| s.floor * (s.b - s.a)).sum();
    depth > -f64::MIN_POSITIVE.ln()
}

pub(super) fn control_factor(spans: &[Span]) -> f64 {
    let depth: f64 = spans.iter().map(|s| s.control * (s.b - s.a)).sum();
    (-depth).exp()
}

/// The ratio-tracking spans of a shadow ray from its origin to infinity.
pub(super) fn spans_of_shadow(
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
