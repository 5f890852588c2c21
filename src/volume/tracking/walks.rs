//! The walks: ratio tracking's, one at a time, and delta tracking's, side
//! by side in batches.

use rand::RngExt;
use rand_distr::{Distribution, Exp1};

use crate::domain::Vec3;
use crate::error::QuadError;
use crate::geometry::Ray;

use super::span::{Crossing, too_deep};
use super::{Extinction, MAX_COLLISIONS};

/// A free flight's optical depth, a standard exponential variate: `rand_distr`'s
/// ziggurat sampler, a table look-up for all but about 1% of draws (a
/// logarithm per draw was a quarter of a ratio-tracking walk).
pub(super) fn free_flight<Rg: rand::Rng + ?Sized>(rng: &mut Rg) -> f64 {
    Exp1.sample(rng)
}

/// One ratio-tracking walk's transmittance score over `crossings`, the spans
/// with a positive rate ([module documentation](super)): at each tentative collision
/// it is multiplied by `1 - (sigma - sigma_c) / mu`, with `sigma_c` the span's
/// control (residual ratio tracking; 0 for plain ratio tracking), and
/// `control` is the factor `exp(-int sigma_c)` of the controls (1 with none).
///
/// Free flights are drawn as optical depths `e ~ Exp(1)` in the rate,
/// measured from the span's start: a flight that leaves a span carries its
/// unused depth into the next (the exponential is memoryless), so crossing a
/// span costs a comparison, not a draw.
pub(super) fn walk<Rg: rand::Rng + ?Sized>(
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
/// [`Medium::densities`](crate::volume::medium::Medium::densities), where neighbouring look-ups overlap instead of
/// each waiting on its loads behind a dynamic call (the look-up was half a
/// walk's time: 0.165 s to 0.127 s for 4M walks on the race's grid), and a
/// walk that ends hands its place to a fresh one. Each walk is still a
/// walk of its own, drawn from its own variates. (A walk past the cap of
/// [`MAX_COLLISIONS`] a span ends them all with an error, but only after the
/// batch's other walks have taken as many steps: up to 64 times the cap's
/// look-ups.)
pub(super) fn delta_walks<Rg: rand::Rng + ?Sized>(
    sigma: Extinction,
    ray: &Ray,
    crossings: &[Crossing],
    n: usize,
    evaluations: &mut u64,
    rng: &mut Rg,
) -> Result<u64, QuadError> {
    /// Walks in flight: their tentative collisions are looked up in one
    /// batch ([`Medium::densities`](crate::volume::medium::Medium::densities)).
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

#[cfg(test)]
mod tests {
    use super::super::span::Span;
    use super::{Course, Crossing};
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
                    floor: 0.0,
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
