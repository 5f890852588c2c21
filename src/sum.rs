//! Compensated summation shared by every rule.
//!
//! Long quadrature sums (a million Gauss nodes, 10^7 Monte Carlo samples) lose
//! `O(n ε)` relative accuracy with naive accumulation. [`Compensated`] keeps a
//! running error term with Knuth's branch-free TwoSum, so the sum is as accurate
//! as if it were accumulated in twice the precision and then rounded, while
//! staying cheap enough to vectorise (six additions per term).
//!
//! ```
//! use lightquad::sum::{Compensated, sum_f64};
//!
//! // 1 + 1e-16 ten million times: a plain f64 sum stays at 1, the compensated
//! // sum keeps the 1e-9.
//! let mut s = Compensated::<f64>::new();
//! s.add(1.0);
//! for _ in 0..10_000_000 {
//!     s.add(1e-16);
//! }
//! assert!((s.total() - (1.0 + 1e-9)).abs() < 1e-15);
//! assert_eq!(sum_f64([1e100, 1.0, -1e100]), 1.0);
//! ```

use crate::value::Value;

/// A running sum `s + c` where `c` carries the rounding error of `s`.
#[derive(Debug, Clone, Copy)]
pub struct Compensated<V: Value> {
    sum: V,
    carry: V,
}

impl<V: Value> Default for Compensated<V> {
    fn default() -> Self {
        Self::new()
    }
}

impl<V: Value> Compensated<V> {
    /// An empty sum.
    pub fn new() -> Self {
        Self {
            sum: V::zero(),
            carry: V::zero(),
        }
    }

    /// Adds `x`: TwoSum `t = s + x`, `e = (s - (t - b)) + (x - b)` with `b = t - s`,
    /// which is exact: `s + x = t + e`.
    #[inline(always)]
    pub fn add(&mut self, x: V) {
        let t = self.sum.zip(x, |s, x| s + x);
        let err = V::from_fn(|i| {
            let (s, x, t) = (self.sum.channel(i), x.channel(i), t.channel(i));
            let b = t - s;
            (s - (t - b)) + (x - b)
        });
        self.sum = t;
        self.carry = self.carry.zip(err, |c, e| c + e);
    }

    /// The compensated total.
    #[inline]
    pub fn total(&self) -> V {
        self.sum.zip(self.carry, |s, c| s + c)
    }
}

/// Independent running sums a long sum is spread over, term `i` into lane
/// `i mod LANES`.
pub const LANES: usize = 4;

/// A compensated sum of products `w_i y_i` kept in [`LANES`] lanes. One
/// running sum is a chain of dependent additions, one addition's latency
/// (about four cycles) per term, longer than the rest of a cheap term's
/// work; four chains overlap. The lanes' sums and carries are combined,
/// compensated, at the end.
///
/// ```
/// use lightquad::sum::Lanes;
///
/// // Each term in its own lane: the lanes hold 1e16, 1, -1e16 and 1, and
/// // their compensated total is the exact 2 (a plain sum gives 0 or 2
/// // depending on order).
/// let mut s = Lanes::<f64>::new();
/// s.add_products(&[1e16, 1.0, -1e16, 1.0], &[1.0; 4]);
/// assert_eq!(s.total(), 2.0);
/// // Cancellation inside one lane too: 1e16 and -1e16 both land in lane 0.
/// let mut t = Lanes::<f64>::new();
/// t.add_products(&[1e16, 0.5, 0.25, 0.125, -1e16, 1.0], &[1.0; 6]);
/// assert_eq!(t.total(), 1.875);
/// ```
#[derive(Debug, Clone, Copy)]
pub struct Lanes<V: Value> {
    lanes: [Compensated<V>; LANES],
}

impl<V: Value> Default for Lanes<V> {
    fn default() -> Self {
        Self::new()
    }
}

impl<V: Value> Lanes<V> {
    /// An empty sum.
    pub fn new() -> Self {
        Self {
            lanes: [Compensated::new(); LANES],
        }
    }

    /// Adds `w_i y_i` for every `i` of `ys` and `ws` (of equal length): each
    /// group of [`LANES`] terms one per lane, the terms after the last whole
    /// group into lane 0 (every lane index a constant, so the lanes can stay
    /// in registers).
    #[inline(always)]
    pub fn add_products(&mut self, ys: &[V], ws: &[f64]) {
        // A local copy, which the compiler keeps in registers.
        let mut lanes = self.lanes;
        let mut y4 = ys.chunks_exact(LANES);
        let mut w4 = ws.chunks_exact(LANES);
        for (y, w) in (&mut y4).zip(&mut w4) {
            for k in 0..LANES {
                lanes[k].add(y[k].map(|v| v * w[k]));
            }
        }
        for (y, w) in y4.remainder().iter().zip(w4.remainder()) {
            lanes[0].add(y.map(|v| v * w));
        }
        self.lanes = lanes;
    }

    /// [`Lanes::add_products`] and, in the same pass, the scale of the
    /// terms: `|w_i y_i|` added to `magnitude` and the largest kept in
    /// `largest`, lane by lane as the sum groups them. One pass, each product
    /// formed once. `largest` is a plain comparison, without `f64::max`'s NaN
    /// handling, so it skips a NaN term; `magnitude` carries it (and an
    /// infinite one), which is how a caller sees that a value was not finite.
    #[inline(always)]
    pub fn add_products_scaled(
        &mut self,
        ys: &[V],
        ws: &[f64],
        magnitude: &mut [V; LANES],
        largest: &mut [V; LANES],
    ) {
        // Local copies, which the compiler keeps in registers.
        let (mut lanes, mut m, mut l) = (self.lanes, *magnitude, *largest);
        let mut add = |k: usize, y: V, w: f64| {
            let t = y.map(|v| v * w);
            lanes[k].add(t);
            let a = t.map(f64::abs);
            m[k] = m[k].zip(a, |p, q| p + q);
            l[k] = l[k].zip(a, |p, q| if q > p { q } else { p });
        };
        let mut y4 = ys.chunks_exact(LANES);
        let mut w4 = ws.chunks_exact(LANES);
        for (y, w) in (&mut y4).zip(&mut w4) {
            for k in 0..LANES {
                add(k, y[k], w[k]);
            }
        }
        for (y, &w) in y4.remainder().iter().zip(w4.remainder()) {
            add(0, *y, w);
        }
        (self.lanes, *magnitude, *largest) = (lanes, m, l);
    }

    /// The compensated total of every lane.
    pub fn total(&self) -> V {
        let mut all = Compensated::new();
        for lane in &self.lanes {
            all.add(lane.sum);
        }
        for lane in &self.lanes {
            all.add(lane.carry);
        }
        all.total()
    }
}

/// Compensated sum of an iterator of `f64`.
pub fn sum_f64(values: impl IntoIterator<Item = f64>) -> f64 {
    let mut acc = Compensated::<f64>::new();
    for v in values {
        acc.add(v);
    }
    acc.total()
}
