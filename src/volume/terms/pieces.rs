//! A ray's segment cut into pieces where the integrand is smooth up to and
//! including their ends: where the density crosses a transfer table's knots
//! (in closed form where the medium has them, else bracketed and bisected),
//! the medium's and an emission field's supports united, and pieces graded
//! at optical depths 1, 2, 4, ... from their start.

use crate::domain::Segment;
use crate::error::QuadError;
use crate::geometry::Ray;
use crate::volume::medium::Medium;

use super::Counted;

/// Equispaced samples per smooth piece when a knot crossing has to be
/// bracketed: two crossings of one level closer than `1/SCAN` of the piece
/// (the density touching a knot value and turning back) can fall between two
/// samples and go uncut.
const SCAN: usize = 64;

/// The parameters strictly inside `(lo, hi)` where `f` crosses one of
/// `levels`: a sign change of `f - level` between two of `SCAN + 1`
/// equispaced samples is bisected until the bracket cannot shrink in f64 (a
/// sample equal to the level is a crossing itself). Robust for any continuous
/// `f`; costs `SCAN + 1` evaluations plus ~60 per crossing.
fn bracket_crossings(f: &dyn Fn(f64) -> f64, lo: f64, hi: f64, levels: &[f64]) -> Vec<f64> {
    let at = |j: usize| {
        if j == SCAN {
            hi
        } else {
            lo + (hi - lo) * j as f64 / SCAN as f64
        }
    };
    let samples: Vec<(f64, f64)> = (0..=SCAN).map(|j| (at(j), f(at(j)))).collect();
    let mut out = Vec::new();
    for &level in levels {
        for (j, w) in samples.windows(2).enumerate() {
            let ((mut a, fa), (mut b, fb)) = (w[0], w[1]);
            let (ga, gb) = (fa - level, fb - level);
            if ga == 0.0 && j > 0 {
                out.push(a);
                continue;
            }
            let sign = ga * gb;
            if sign.is_nan() || sign >= 0.0 {
                continue;
            }
            // Keep f(a) - level and f(b) - level of opposite signs.
            let rising = ga < 0.0;
            loop {
                let m = 0.5 * (a + b);
                if !(a < m && m < b) {
                    break;
                }
                let gm = f(m) - level;
                if gm == 0.0 {
                    (a, b) = (m, m);
                    break;
                }
                if (gm < 0.0) == rising {
                    a = m;
                } else {
                    b = m;
                }
            }
            out.push(0.5 * (a + b));
        }
    }
    out.retain(|&t| lo < t && t < hi);
    out
}

/// The pieces of V-E with a transfer table: each support piece also cut
/// where the density crosses a knot of the table, where `c(v(t))` has a
/// kink. The medium's closed-form crossings where it has them
/// ([`Medium::level_crossings`]), else bracketed on each smooth piece.
pub(super) fn cut_at_knots(
    medium: &Counted,
    ray: &Ray,
    pieces: &[Segment],
    knots: &[f64],
) -> Result<Vec<Segment>, QuadError> {
    let mut out = Vec::with_capacity(pieces.len());
    for piece in pieces {
        let mut breaks = piece.breaks().to_vec();
        for (lo, hi) in piece.pieces() {
            let mid = 0.5 * (lo + hi);
            let inside = ray.at(mid);
            let closed: Option<Vec<f64>> = knots
                .iter()
                .map(|&k| medium.medium.level_crossings(ray, lo, hi, inside, k))
                .collect::<Option<Vec<Vec<f64>>>>()
                .map(|v| v.concat());
            match closed {
                Some(ts) => breaks.extend(ts.into_iter().filter(|&t| lo < t && t < hi)),
                None => breaks.extend(bracket_crossings(
                    &|t| medium.density(ray, t, mid),
                    lo,
                    hi,
                    knots,
                )),
            }
        }
        out.push(Segment::with_breaks(piece.start(), piece.end(), breaks)?);
    }
    Ok(out)
}

/// The pieces of V-E with an emission field: the union of the medium's and
/// the field's supports, each union piece cut at every end and break point of
/// either, so on every smooth piece both the density and `Le` are smooth.
pub(super) fn union_pieces(a: &[Segment], b: &[Segment]) -> Result<Vec<Segment>, QuadError> {
    let mut spans: Vec<(f64, f64)> = a.iter().chain(b).map(|s| (s.start(), s.end())).collect();
    spans.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut merged: Vec<(f64, f64)> = Vec::new();
    for (lo, hi) in spans {
        match merged.last_mut() {
            Some(last) if lo <= last.1 => last.1 = last.1.max(hi),
            _ => merged.push((lo, hi)),
        }
    }
    let points: Vec<f64> = a
        .iter()
        .chain(b)
        .flat_map(|s| {
            [s.start(), s.end()]
                .into_iter()
                .chain(s.breaks().iter().copied())
        })
        .collect();
    merged
        .into_iter()
        .map(|(lo, hi)| {
            let inner = points
                .iter()
                .copied()
                .filter(|&t| lo < t && t < hi)
                .collect();
            Segment::with_breaks(lo, hi, inner)
        })
        .collect()
}

/// The outer integration pieces of V-E and V-L: each support piece is cut at
/// optical depths 1, 2, 4, 8, ... from its start (measured with the majorant),
/// so the boundary layer `tau(t_n, t) = e^{-sigma (t - t_n)}` of a thick medium
/// is resolved by every rule: a piece of optical depth D costs
/// `1 + log2 D` times the budget instead of being missed.
pub(super) fn graded(medium: &dyn Medium, lambda: f64, ray: &Ray, piece: &Segment) -> Vec<Segment> {
    let (a, b) = (piece.start(), piece.end());
    let bar = lambda * medium.max_density(ray, a, b);
    let depth = bar * (b - a);
    if !(depth.is_finite() && depth > 2.0) {
        return vec![piece.clone()];
    }
    let mut cuts = vec![a];
    let mut d = 1.0;
    while d < depth {
        let t = a + d / bar;
        if t > *cuts.last().unwrap_or(&a) && t < b {
            cuts.push(t);
        }
        d *= 2.0;
    }
    cuts.push(b);
    cuts.windows(2)
        .filter_map(|w| piece.restrict(w[0], w[1]).ok())
        .collect()
}
