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

use std::marker::PhantomData;

use wide::f64x4;

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

/// Most channels of a [`Value`] the lanes hold: an RGB value with its
/// error estimate ([`crate::quadrature::product::WithError`]).
const MAX_CHANNELS: usize = 6;

/// One number per lane for every channel of a value: channel `c`'s
/// [`LANES`] lanes side by side in one SIMD vector (two SSE2 registers on
/// x86-64, one AVX register where the build enables AVX), so an operation
/// on the lanes is one or two instructions instead of four.
#[derive(Debug, Clone, Copy)]
pub struct LaneValues<V: Value> {
    channels: [f64x4; MAX_CHANNELS],
    value: PhantomData<V>,
}

impl<V: Value> Default for LaneValues<V> {
    fn default() -> Self {
        Self::zero()
    }
}

impl<V: Value> LaneValues<V> {
    /// Every lane of every channel 0.
    pub fn zero() -> Self {
        const {
            assert!(
                V::CHANNELS <= MAX_CHANNELS,
                "lightquad's lanes hold values of at most 6 channels"
            )
        };
        Self {
            channels: [f64x4::ZERO; MAX_CHANNELS],
            value: PhantomData,
        }
    }

    /// Adds `other` lane by lane.
    #[inline(always)]
    pub fn add(&mut self, other: &Self) {
        for c in 0..V::CHANNELS {
            self.channels[c] += other.channels[c];
        }
    }

    /// True when every lane of every channel is finite.
    pub fn all_finite(&self) -> bool {
        self.channels[..V::CHANNELS]
            .iter()
            .all(|v| v.to_array().iter().all(|x| x.is_finite()))
    }

    /// The lanes' plain sum, lane 0 first.
    pub fn sum(&self) -> V {
        V::from_fn(|c| self.channels[c].to_array().iter().fold(0.0, |s, x| s + x))
    }

    /// Keeps, lane by lane, the larger of `self` and `other` (`largest`
    /// merged from two spans of terms).
    pub fn max_with(&mut self, other: &Self) {
        for c in 0..V::CHANNELS {
            self.channels[c] = other.channels[c].fast_max(self.channels[c]);
        }
    }

    /// The largest lane (of lanes that are not NaN).
    pub fn max(&self) -> V {
        V::from_fn(|c| {
            self.channels[c]
                .to_array()
                .iter()
                .fold(0.0, |m, &x| m.max(x))
        })
    }
}

/// A compensated sum of products `w_i y_i` kept in [`LANES`] lanes. One
/// running sum is a chain of dependent additions, one addition's latency
/// (about four cycles) per term, longer than the rest of a cheap term's
/// work; four chains overlap. The lanes of each channel sit side by side in
/// one SIMD vector ([`LaneValues`]), so TwoSum's six additions are done for
/// four terms at once (on x86-64's baseline SSE2, two at a time): at
/// n = 1e6, Gauss–Legendre on `cos(50 x)` went from 10.7 to 10.05 ms
/// (the `wide` crate's `f64x4`; the same operations, so the same bits as
/// four [`Compensated`] sums taken one term at a time). The lanes' sums and
/// carries are combined, compensated, at the end.
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
    sum: LaneValues<V>,
    carry: LaneValues<V>,
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
            sum: LaneValues::zero(),
            carry: LaneValues::zero(),
        }
    }

    /// Adds `w_i y_i` for every `i` of `ys` and `ws` (of equal length): each
    /// group of [`LANES`] terms one per lane, the terms after the last whole
    /// group into lane 0. Not inlined, so a caller's loop that also inlines
    /// [`Lanes::add_products_scaled`] is not crowded by a second copy.
    #[inline(never)]
    pub fn add_products(&mut self, ys: &[V], ws: &[f64]) {
        let (mut unused_magnitude, mut unused_largest) = (f64x4::ZERO, f64x4::ZERO);
        for c in 0..V::CHANNELS {
            add_channel::<V, false>(
                ys,
                ws,
                c,
                [
                    &mut self.sum.channels[c],
                    &mut self.carry.channels[c],
                    &mut unused_magnitude,
                    &mut unused_largest,
                ],
            );
        }
    }

    /// [`Lanes::add_products`] and, in the same pass, the scale of the
    /// terms: `|w_i y_i|` added to `magnitude` and the largest kept in
    /// `largest`, lane by lane as the sum groups them. One pass, each product
    /// formed once. `magnitude` carries a NaN or infinite term, which is how
    /// a caller sees that a value was not finite. `largest` skips a NaN term
    /// on x86-64 (`maxpd` keeps the lane's largest); on other targets `wide`'s
    /// `fast_max` may keep the NaN instead.
    #[inline(always)]
    pub fn add_products_scaled(
        &mut self,
        ys: &[V],
        ws: &[f64],
        magnitude: &mut LaneValues<V>,
        largest: &mut LaneValues<V>,
    ) {
        for c in 0..V::CHANNELS {
            add_channel::<V, true>(
                ys,
                ws,
                c,
                [
                    &mut self.sum.channels[c],
                    &mut self.carry.channels[c],
                    &mut magnitude.channels[c],
                    &mut largest.channels[c],
                ],
            );
        }
    }

    /// Adds another sum lane by lane: TwoSum of the two lanes' sums, the
    /// carries and TwoSum's error into the carry. So the lanes of a sum
    /// split into spans and merged in order hold the whole sum to within
    /// the carries' plain additions, `u` times the carries (each at most
    /// `u` times the sum of its span's running partial sums), and a single span merged into an empty sum is
    /// that span's sum bit for bit.
    ///
    /// ```
    /// use lightquad::sum::Lanes;
    ///
    /// // 1e16 in one span, -1e16 and the ones in the other: merged, the
    /// // total is the exact 2.
    /// let (mut a, mut b) = (Lanes::<f64>::new(), Lanes::<f64>::new());
    /// a.add_products(&[1e16, 1.0], &[1.0; 2]);
    /// b.add_products(&[-1e16, 1.0], &[1.0; 2]);
    /// a.merge(&b);
    /// assert_eq!(a.total(), 2.0);
    /// ```
    pub fn merge(&mut self, other: &Self) {
        for c in 0..V::CHANNELS {
            let (s, t) = (self.sum.channels[c], other.sum.channels[c]);
            let u = s + t;
            let b = u - s;
            self.carry.channels[c] += ((s - (u - b)) + (t - b)) + other.carry.channels[c];
            self.sum.channels[c] = u;
        }
    }

    /// The compensated total of every lane: the sums, lane 0 first, then
    /// the carries.
    pub fn total(&self) -> V {
        let mut all = Compensated::new();
        for k in 0..LANES {
            all.add(V::from_fn(|c| self.sum.channels[c].to_array()[k]));
        }
        for k in 0..LANES {
            all.add(V::from_fn(|c| self.carry.channels[c].to_array()[k]));
        }
        all.total()
    }
}

/// Adds channel `c` of the products `w_i y_i`, four at a time, to the lanes
/// `[sum, carry, magnitude, largest]` of that channel: term `4 j + k` into
/// lane `k`, each term after the last whole group into lane 0 (the other
/// lanes adding 0, which leaves them as they were). With `SCALED`, `|w_i
/// y_i|` is added to `magnitude` and the largest kept in `largest`.
#[inline(always)]
fn add_channel<V: Value, const SCALED: bool>(
    ys: &[V],
    ws: &[f64],
    c: usize,
    [sum, carry, magnitude, largest]: [&mut f64x4; 4],
) {
    // Local copies, which the compiler keeps in registers.
    let (mut s, mut e, mut m, mut l) = (*sum, *carry, *magnitude, *largest);
    let mut add = |t: f64x4| {
        // TwoSum: s + t = u + (s - (u - b)) + (t - b) exactly, b = u - s.
        let u = s + t;
        let b = u - s;
        e += (s - (u - b)) + (t - b);
        s = u;
        if SCALED {
            let a = t.abs();
            m += a;
            l = a.fast_max(l);
        }
    };
    let mut y4 = ys.chunks_exact(LANES);
    let mut w4 = ws.chunks_exact(LANES);
    for (y, w) in (&mut y4).zip(&mut w4) {
        let y = f64x4::new([
            y[0].channel(c),
            y[1].channel(c),
            y[2].channel(c),
            y[3].channel(c),
        ]);
        add(y * f64x4::new([w[0], w[1], w[2], w[3]]));
    }
    for (y, &w) in y4.remainder().iter().zip(w4.remainder()) {
        add(f64x4::new([y.channel(c) * w, 0.0, 0.0, 0.0]));
    }
    (*sum, *carry, *magnitude, *largest) = (s, e, m, l);
}

/// Compensated sum of an iterator of `f64`.
pub fn sum_f64(values: impl IntoIterator<Item = f64>) -> f64 {
    let mut acc = Compensated::<f64>::new();
    for v in values {
        acc.add(v);
    }
    acc.total()
}
