//! The SIMD lanes of the shared compensated sum (`lightquad::sum::Lanes`)
//! against two independent references: the scalar `Compensated` sum taken
//! one term at a time into the same four lanes (the same total to within
//! the final rounding, the same largest term bit for bit, at every length
//! and block size; RGB and six-channel values channel by channel, bit for
//! bit, as scalar sums), and
//! the exact sum of terms that are integers times a power of two, computed
//! in 128-bit integers (the compensated error bound must hold).

use lightquad::quadrature::product::WithError;
use lightquad::sum::{Compensated, LANES, LaneValues, Lanes};
use lightquad::value::{Rgb, Value};
use proptest::prelude::*;

/// The scalar reference: term `i` into lane `i mod 4` for the whole groups
/// of four, the rest into lane 0; the lanes' totals added compensated. Also `sum |w y|` lane by lane and
/// the largest `|w y|`.
fn reference<V: Value>(ys: &[V], ws: &[f64]) -> (V, V, V) {
    let mut lanes = [Compensated::<V>::new(); LANES];
    let mut magnitude = [V::zero(); LANES];
    let mut largest = V::zero();
    let whole = ys.len() / LANES * LANES;
    for (i, (y, &w)) in ys.iter().zip(ws).enumerate() {
        let k = if i < whole { i % LANES } else { 0 };
        let t = y.map(|v| v * w);
        lanes[k].add(t);
        magnitude[k] = magnitude[k].zip(t, |m, x| m + x.abs());
        largest = largest.zip(t, |l, x| l.max(x.abs()));
    }
    // The lanes' totals, combined compensated.
    let mut all = Compensated::<V>::new();
    for l in &lanes {
        all.add(l.total());
    }
    let magnitude = magnitude
        .into_iter()
        .fold(V::zero(), |s, m| s.zip(m, |a, b| a + b));
    (all.total(), magnitude, largest)
}

/// What `Lanes` gives: the products in blocks of `block` terms.
fn lanes<V: Value>(ys: &[V], ws: &[f64], block: usize) -> (V, V, V) {
    let mut sum = Lanes::<V>::new();
    let mut magnitude = LaneValues::<V>::zero();
    let mut largest = LaneValues::<V>::zero();
    for (y, w) in ys.chunks(block).zip(ws.chunks(block)) {
        let mut m = LaneValues::zero();
        sum.add_products_scaled(y, w, &mut m, &mut largest);
        magnitude.add(&m);
    }
    (sum.total(), magnitude.sum(), largest.max())
}

fn bits<V: Value>(v: V) -> Vec<u64> {
    (0..V::CHANNELS).map(|c| v.channel(c).to_bits()).collect()
}

/// Values with a wide spread of exponents and signs, so that the carries
/// are not zero and cancellation happens inside lanes.
fn spread(seed: u64, n: usize) -> Vec<f64> {
    let mut x = seed | 1;
    (0..n)
        .map(|_| {
            // xorshift64*
            x ^= x >> 12;
            x ^= x << 25;
            x ^= x >> 27;
            let r = x.wrapping_mul(0x2545_F491_4F6C_DD1D);
            let mantissa = (r >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            let exponent = ((r & 0x3f) as i32) - 32;
            mantissa * 2f64.powi(exponent)
        })
        .collect()
}

#[test]
fn a_lanes_total_matches_four_scalar_compensated_lanes() {
    // Lengths around the groups of four and the blocks, blocks of 1 to 64.
    for n in [0usize, 1, 2, 3, 4, 5, 7, 8, 63, 64, 65, 127, 130, 1001] {
        for block in [1usize, 3, 4, 64] {
            let ys = spread(17 + n as u64, n);
            let ws = spread(91 + n as u64, n);
            // The reference puts the terms after the last whole group of a
            // block into lane 0, block by block, as `Lanes` does.
            let (mut value, mut magnitude, mut largest) =
                ([Compensated::<f64>::new(); LANES], [0.0f64; LANES], 0.0f64);
            for (y, w) in ys.chunks(block).zip(ws.chunks(block)) {
                let whole = y.len() / LANES * LANES;
                for (i, (&y, &w)) in y.iter().zip(w).enumerate() {
                    let k = if i < whole { i % LANES } else { 0 };
                    value[k].add(y * w);
                    magnitude[k] += (y * w).abs();
                    largest = largest.max((y * w).abs());
                }
            }
            let (v, m, l) = lanes(&ys, &ws, block);
            let mut all = Compensated::<f64>::new();
            for lane in &value {
                all.add(lane.total());
            }
            // The value against the scalar lanes' combined total, within the
            // combination's own rounding (the reference adds each lane's sum
            // and carry first, `Lanes` all sums and then all carries).
            let expected = all.total();
            assert!(
                (v - expected).abs() <= f64::EPSILON * expected.abs(),
                "n = {n}, block = {block}: {v:e} against {expected:e}"
            );
            let m_ref = magnitude.iter().fold(0.0, |s, x| s + x);
            // `magnitude` is summed a block at a time, so only its last bits
            // may differ from the term-by-term lanes.
            assert!(
                (m - m_ref).abs() <= 1e-13 * m_ref,
                "n = {n}, block = {block}: {m:e} against {m_ref:e}"
            );
            assert_eq!(l.to_bits(), largest.to_bits(), "n = {n}, block = {block}");
        }
    }
}

#[test]
fn rgb_and_six_channel_values_sum_channel_by_channel() {
    // Each channel of an RGB (and of an RGB with its error, six channels)
    // sum equals the scalar sum of that channel, bit for bit.
    let n = 203;
    let ws = spread(5, n);
    let chans: Vec<Vec<f64>> = (0..6).map(|c| spread(100 + c, n)).collect();
    let rgb: Vec<Rgb> = (0..n)
        .map(|i| Rgb::new(chans[0][i], chans[1][i], chans[2][i]))
        .collect();
    let six: Vec<WithError<Rgb>> = (0..n)
        .map(|i| WithError {
            value: rgb[i],
            error: Rgb::new(chans[3][i], chans[4][i], chans[5][i]),
        })
        .collect();
    let (v3, m3, l3) = lanes(&rgb, &ws, 64);
    let (v6, m6, l6) = lanes(&six, &ws, 64);
    for (c, chan) in chans.iter().enumerate() {
        let (v, m, l) = lanes(chan, &ws, 64);
        if c < 3 {
            assert_eq!(bits(v3)[c], v.to_bits(), "rgb channel {c}");
            assert_eq!(bits(m3)[c], m.to_bits(), "rgb channel {c}");
            assert_eq!(bits(l3)[c], l.to_bits(), "rgb channel {c}");
        }
        assert_eq!(bits(v6)[c], v.to_bits(), "six-channel {c}");
        assert_eq!(bits(m6)[c], m.to_bits(), "six-channel {c}");
        assert_eq!(bits(l6)[c], l.to_bits(), "six-channel {c}");
    }
    // And the scalar reference agrees with the lanes on the RGB sum.
    let (r, _, rl) = reference(&rgb, &ws);
    for c in 0..3 {
        let expected = r.channel(c);
        assert!((v3.channel(c) - expected).abs() <= f64::EPSILON * expected.abs());
        assert_eq!(l3.channel(c), rl.channel(c));
    }
}

/// Three spans merged in order, each with a carry or a rounded merge:
/// every piece reaches the total. Span A holds `1 + 2^-60` (sum 1, carry
/// `2^-60`), span B `1 + 2^-52 + 2^-61` (carry `2^-61`); merged, `2 +
/// 2^-52` rounds to 2 (ties to even) with TwoSum's error `2^-52`; span C's
/// `-2` cancels the sums. What is left is the exact `2^-52 + 3 2^-61`,
/// which leaving out either carry or TwoSum's error would change.
#[test]
fn merged_spans_keep_their_carries_and_the_merges_rounding() {
    let p = |e: i32| 2f64.powi(e);
    let span = |ys: &[f64]| {
        let mut lanes = Lanes::<f64>::new();
        // One term a group of four, so every term lands in lane 0.
        let spread: Vec<f64> = ys.iter().flat_map(|&y| [y, 0.0, 0.0, 0.0]).collect();
        lanes.add_products(&spread, &vec![1.0; spread.len()]);
        lanes
    };
    let mut merged = Lanes::<f64>::new();
    for part in [
        span(&[1.0, p(-60)]),
        span(&[1.0 + p(-52), p(-61)]),
        span(&[-2.0]),
    ] {
        merged.merge(&part);
    }
    assert_eq!(merged.total(), p(-52) + 3.0 * p(-61));
}

/// Terms `k 2^e` and weights `2^p` from `(k, e, p)`, the exact sum of the
/// products rounded once to `f64` (exact: `k 2^(e + p + 68)` units of
/// `2^-68` in an i128, at most 2^116 a term, 600 terms below 2^126), and
/// `sum |w y|`.
fn exact_terms(terms: &[(i64, i32, i32)]) -> (Vec<f64>, Vec<f64>, f64, f64) {
    let ys: Vec<f64> = terms
        .iter()
        .map(|&(k, e, _)| k as f64 * 2f64.powi(e))
        .collect();
    let ws: Vec<f64> = terms.iter().map(|&(_, _, p)| 2f64.powi(p)).collect();
    let exact: i128 = terms
        .iter()
        .map(|&(k, e, p)| (k as i128) << (e + p + 68))
        .sum();
    let magnitude = ys.iter().zip(&ws).map(|(y, w)| (y * w).abs()).sum();
    (ys, ws, exact as f64 * 2f64.powi(-68), magnitude)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Terms `k_i 2^e_i` with |k_i| < 2^40 and e_i in [-60, 0], weights
    /// powers of two: every product is exact, and the exact sum is an
    /// integer multiple of 2^-68 held in an i128. The compensated total is
    /// within `eps |S| + 2 (n eps)^2 sum |t|` of it (Ogita, Rump and Oishi's
    /// bound for a twice-precision sum, `eps/2 |S| + gamma_(n-1)^2 sum |t|`,
    /// with room for the lanes' combining and the reference's rounding).
    #[test]
    fn the_total_is_within_the_compensated_bound_of_the_exact_sum(
        terms in prop::collection::vec((-(1i64 << 40)..(1i64 << 40), -60i32..=0, -8i32..=8), 0..600),
    ) {
        let (ys, ws, exact_f, magnitude) = exact_terms(&terms);
        let n = ys.len() as f64;
        let (v, m, _) = lanes(&ys, &ws, 64);
        let bound = 1.5 * f64::EPSILON * exact_f.abs() + 2.0 * (n * f64::EPSILON).powi(2) * magnitude;
        prop_assert!((v - exact_f).abs() <= bound, "{v:e} against exact {exact_f:e} (bound {bound:e})");
        prop_assert!((m - magnitude).abs() <= 1e-12 * magnitude);
    }

    /// The same exact sums, the terms cut into consecutive spans at random
    /// points, each span summed apart and the spans merged in order
    /// (`Lanes::merge`, what `line_sum_par` does): the same bound holds.
    #[test]
    fn spans_merged_in_order_keep_the_compensated_bound(
        terms in prop::collection::vec((-(1i64 << 40)..(1i64 << 40), -60i32..=0, -8i32..=8), 1..600),
        cuts in prop::collection::vec(0usize..600, 0..6),
    ) {
        let (ys, ws, exact_f, magnitude) = exact_terms(&terms);
        let mut cuts: Vec<usize> = cuts.into_iter().map(|c| c % ys.len()).collect();
        cuts.push(0);
        cuts.push(ys.len());
        cuts.sort_unstable();
        let mut merged = Lanes::<f64>::new();
        for span in cuts.windows(2) {
            let mut part = Lanes::<f64>::new();
            part.add_products(&ys[span[0]..span[1]], &ws[span[0]..span[1]]);
            merged.merge(&part);
        }
        let v = merged.total();
        let n = ys.len() as f64;
        let bound = 1.5 * f64::EPSILON * exact_f.abs() + 2.0 * (n * f64::EPSILON).powi(2) * magnitude;
        prop_assert!((v - exact_f).abs() <= bound, "{v:e} against exact {exact_f:e} (bound {bound:e})");
    }
}

/// Infinite terms (the error of a rule that has no estimate is infinite,
/// and `Product` sums such errors) give the IEEE sum of the terms, not the
/// NaN of TwoSum's carry (`inf - inf`): `+inf` where every infinity is
/// `+inf`, whatever lanes or spans hold it, NaN where both signs occur. A
/// finite channel beside an infinite one keeps its compensated total.
#[test]
fn infinite_terms_total_to_their_ieee_sum_not_a_nan() {
    let inf = f64::INFINITY;
    // The scalar sum.
    let mut s = Compensated::<f64>::new();
    for t in [1.0, inf, 2.0, inf] {
        s.add(t);
    }
    assert_eq!(s.total(), inf);
    s.add(-inf);
    assert!(s.total().is_nan());
    // One infinity in each position of the lanes, and in a leftover term.
    for n in [1usize, 4, 5, 9, 64, 67] {
        for at in 0..n {
            let mut ys = vec![1.0; n];
            ys[at] = inf;
            let mut lanes = Lanes::<f64>::new();
            lanes.add_products(&ys, &vec![0.5; n]);
            assert_eq!(lanes.total(), inf, "n = {n}, +inf at {at}");
            ys[at] = -inf;
            let mut lanes = Lanes::<f64>::new();
            lanes.add_products(&ys, &vec![0.5; n]);
            assert_eq!(lanes.total(), -inf, "n = {n}, -inf at {at}");
            // Both signs: NaN.
            if n > 1 {
                ys[(at + 1) % n] = inf;
                let mut lanes = Lanes::<f64>::new();
                lanes.add_products(&ys, &vec![0.5; n]);
                assert!(lanes.total().is_nan(), "n = {n}, both signs");
            }
        }
    }
    // Spans merged in order, the infinity in the second of three.
    let mut merged = Lanes::<f64>::new();
    for ys in [[1.0, 2.0, 3.0, 4.0], [inf, 1.0, inf, 1.0], [5.0; 4]] {
        let mut part = Lanes::<f64>::new();
        part.add_products(&ys, &[1.0; 4]);
        merged.merge(&part);
    }
    assert_eq!(merged.total(), inf);
    // A value with its error: the error infinite at one term, the value's
    // channel still the exact compensated 2 of `1e16 + 1 - 1e16 + 1`.
    let ys: Vec<WithError<f64>> = [(1e16, 0.0), (1.0, inf), (-1e16, 0.0), (1.0, 0.0)]
        .iter()
        .map(|&(value, error)| WithError { value, error })
        .collect();
    let mut lanes = Lanes::<WithError<f64>>::new();
    lanes.add_products(&ys, &[1.0; 4]);
    let total = lanes.total();
    assert_eq!((total.value, total.error), (2.0, inf));
}
