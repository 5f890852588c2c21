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

    /// The compensated total `s + c`. A channel whose sum is infinite (or
    /// NaN) is that sum: once an infinite term enters, TwoSum's carry is
    /// `inf - inf`, NaN, and would turn the total of `+inf` terms into NaN.
    #[inline]
    pub fn total(&self) -> V {
        self.sum
            .zip(self.carry, |s, c| if s.is_finite() { s + c } else { s })
    }
}

/// Independent running sums a long sum is spread over, term `i` into lane
/// `i mod LANES`.
pub const LANES: usize = 4;

/// Most channels of a [`Value`] the lanes hold: an RGB value with its
/// error estimate ([`crate::quadrature::product::WithError`]).
const MAX_CHANNELS: usize = 6;

/// One number per lane for every channel of a value: channel `c`'s
/// [`LANES`] lanes side by side in one SIMD vector (two SSE2 registers in
/// x86-64's baseline; the long pass over a block of terms takes them into
/// one AVX register where the CPU has AVX), so an operation on the lanes is
/// one or two instructions instead of four.
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

    /// The lanes of the value's channels, channel 0 first: the part of
    /// the array in use ([`LaneValues::used_mut`] to set them).
    pub(crate) fn used(&self) -> &[f64x4] {
        &self.channels[..V::CHANNELS]
    }

    /// [`LaneValues::used`], to be set.
    pub(crate) fn used_mut(&mut self) -> &mut [f64x4] {
        &mut self.channels[..V::CHANNELS]
    }

    /// True when every lane of every channel is finite.
    pub fn all_finite(&self) -> bool {
        self.channels[..V::CHANNELS]
            .iter()
            .all(|v| v.to_array().iter().all(|x| x.is_finite()))
    }

    /// Whether the lanes are finite in every channel [`Value::all_finite`]
    /// reads: their sum taken at a quarter of each lane, which stays within
    /// the f64 range wherever the lanes are finite, tested as a value.
    pub(crate) fn finite_as_value(&self) -> bool {
        V::from_fn(|c| {
            self.channels[c]
                .to_array()
                .iter()
                .fold(0.0, |s, x| s + 0.25 * x)
        })
        .all_finite()
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
/// four terms at once (in AVX where the CPU has it, else two at a time in
/// x86-64's baseline SSE2): at
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

    /// The lanes' sums and carries, in that order.
    pub(crate) fn parts(&self) -> [&LaneValues<V>; 2] {
        [&self.sum, &self.carry]
    }

    /// [`Lanes::parts`], to be set.
    pub(crate) fn parts_mut(&mut self) -> [&mut LaneValues<V>; 2] {
        [&mut self.sum, &mut self.carry]
    }

    /// Adds `w_i y_i` for every `i` of `ys` and `ws` (of equal length): each
    /// group of [`LANES`] terms one per lane, the terms after the last whole
    /// group into lane 0. In AVX registers where the CPU has them
    /// (`with_kernel`); a loop that calls this for many short groups is
    /// better written as a `KernelTask`, which chooses once.
    pub fn add_products(&mut self, ys: &[V], ws: &[f64]) {
        with_kernel(Products {
            lanes: self,
            ys,
            ws,
            scale: None,
        })
    }

    /// [`Lanes::add_products`] and, in the same pass, the scale of the
    /// terms: `|w_i y_i|` added to `magnitude` and the largest kept in
    /// `largest`, lane by lane as the sum groups them. One pass, each product
    /// formed once. `magnitude` carries a NaN or infinite term, which is how
    /// a caller sees that a value was not finite. `largest` skips a NaN term
    /// on x86-64 (`maxpd` keeps the lane's largest); on other targets `wide`'s
    /// `fast_max` may keep the NaN instead.
    pub fn add_products_scaled(
        &mut self,
        ys: &[V],
        ws: &[f64],
        magnitude: &mut LaneValues<V>,
        largest: &mut LaneValues<V>,
    ) {
        with_kernel(Products {
            lanes: self,
            ys,
            ws,
            scale: Some((magnitude, largest)),
        })
    }

    /// [`Lanes::add_products`] with the pass `kernel`.
    #[inline(always)]
    pub(crate) fn add_products_in(&mut self, kernel: impl Kernel<V>, ys: &[V], ws: &[f64]) {
        let (mut unused_magnitude, mut unused_largest) = (f64x4::ZERO, f64x4::ZERO);
        for c in 0..V::CHANNELS {
            kernel.add_channel(
                ys,
                ws,
                c,
                [
                    &mut self.sum.channels[c],
                    &mut self.carry.channels[c],
                    &mut unused_magnitude,
                    &mut unused_largest,
                ],
                false,
            );
        }
    }

    /// [`Lanes::add_products_scaled`] with the pass `kernel`.
    #[inline(always)]
    pub(crate) fn add_products_scaled_in(
        &mut self,
        kernel: impl Kernel<V>,
        ys: &[V],
        ws: &[f64],
        magnitude: &mut LaneValues<V>,
        largest: &mut LaneValues<V>,
    ) {
        for c in 0..V::CHANNELS {
            kernel.add_channel(
                ys,
                ws,
                c,
                [
                    &mut self.sum.channels[c],
                    &mut self.carry.channels[c],
                    &mut magnitude.channels[c],
                    &mut largest.channels[c],
                ],
                true,
            );
        }
    }

    /// Adds another sum lane by lane: TwoSum of the two lanes' sums, the
    /// carries and TwoSum's error into the carry. So the lanes of a sum
    /// split into spans and merged in order hold the whole sum to within
    /// the carries' plain additions, `u` times the carries (each at most
    /// `u` times the sum of its span's running partial sums), and a single
    /// span merged into an empty sum is that span's sum bit for bit.
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
    /// the carries. Two kinds of channel are totalled otherwise:
    /// - one whose lanes are finite but whose total passes `f64::MAX` on
    ///   the way (each lane near a quarter of it: the sum of values within
    ///   rounding of `f64::MAX`) is totalled again from a quarter of each
    ///   lane, exact for normal numbers, and scaled back: a total beyond
    ///   the f64 range is infinite, one within it is found;
    /// - one where a lane's sum is infinite (an infinite term, such as the
    ///   error of a rule that has no estimate) is the plain sum of the
    ///   lanes' sums: infinite when the infinities agree in sign, NaN when
    ///   they do not. The carries are not added: TwoSum's carry is
    ///   `inf - inf`, NaN, from the infinite term on.
    ///
    /// ```
    /// use lightquad::sum::Lanes;
    ///
    /// let mut s = Lanes::<f64>::new();
    /// s.add_products(&[1.0, f64::INFINITY, 2.0, f64::INFINITY, 3.0], &[1.0; 5]);
    /// assert_eq!(s.total(), f64::INFINITY);
    /// ```
    pub fn total(&self) -> V {
        let total = self.total_scaled(1.0);
        if (0..V::CHANNELS).all(|c| total.channel(c).is_finite()) {
            return total;
        }
        let quarter = self.total_scaled(0.25);
        V::from_fn(|c| {
            let sums = self.sum.channels[c].to_array();
            match total.channel(c) {
                t if t.is_finite() => t,
                _ if sums.iter().all(|s| s.is_finite()) => 4.0 * quarter.channel(c),
                _ => sums.iter().fold(0.0, |t, s| t + s),
            }
        })
    }

    /// [`Lanes::total`] of every lane times `scale`.
    fn total_scaled(&self, scale: f64) -> V {
        let mut all = Compensated::new();
        for k in 0..LANES {
            all.add(V::from_fn(|c| scale * self.sum.channels[c].to_array()[k]));
        }
        for k in 0..LANES {
            all.add(V::from_fn(|c| scale * self.carry.channels[c].to_array()[k]));
        }
        all.total()
    }
}

/// The pass that adds one channel of a group of products `w_i y_i` to
/// that channel's lanes `[sum, carry, magnitude, largest]`, as
/// [`add_channel_portable`] adds them (with `scaled`, `|w_i y_i|` into
/// `magnitude` and the largest into `largest`). Two passes give the same
/// bits: the portable one and, on x86-64 with AVX, one in AVX registers.
pub(crate) trait Kernel<V: Value>: Copy {
    fn add_channel(self, ys: &[V], ws: &[f64], c: usize, lanes: [&mut f64x4; 4], scaled: bool);
}

/// A [`Kernel`] that is a closure: the AVX pass is a closure defined in a
/// function compiled for AVX, and AVX code where it is inlined there.
#[derive(Clone, Copy)]
struct PassFn<F>(F);

impl<V: Value, F: Fn(&[V], &[f64], usize, [&mut f64x4; 4], bool) + Copy> Kernel<V> for PassFn<F> {
    #[inline(always)]
    fn add_channel(self, ys: &[V], ws: &[f64], c: usize, lanes: [&mut f64x4; 4], scaled: bool) {
        (self.0)(ys, ws, c, lanes, scaled)
    }
}

/// The closure as a [`Kernel`], its signature taken from the bound.
#[inline(always)]
fn pass_fn<V: Value, F: Fn(&[V], &[f64], usize, [&mut f64x4; 4], bool) + Copy>(f: F) -> PassFn<F> {
    PassFn(f)
}

/// Work that sums with the lanes, run by [`with_kernel`] with the best
/// [`Kernel`] the CPU allows. `run` is compiled once for each kernel, and
/// with the AVX kernel inside a function compiled for AVX: the whole loop
/// (the integrand with it) is AVX code and the pass is inlined into it,
/// rather than called, once a short group, across the boundary between
/// code for the baseline and code for AVX (which the compiler cannot
/// inline).
///
/// `shared` is what the task reads through a shared reference, given to
/// the function compiled for AVX as an argument of its own rather than
/// inside `task`: the compiler then knows that nothing the task calls
/// writes to it, and need not load what it read of it again after each
/// call (an integrand's captures: once a group of nodes, not once a node).
pub(crate) trait KernelTask<V: Value, S: ?Sized = ()> {
    type Output;
    fn run(self, kernel: impl Kernel<V>, shared: &S) -> Self::Output;
}

/// Runs `task` with the AVX pass where the CPU has AVX (checked at every
/// call: a cached flag), the portable pass elsewhere.
#[inline(always)]
pub(crate) fn with_kernel<V: Value, T: KernelTask<V>>(task: T) -> T::Output {
    with_kernel_sharing(task, &())
}

/// [`with_kernel`] for a task that reads `shared` ([`KernelTask`]).
#[inline(always)]
pub(crate) fn with_kernel_sharing<V: Value, S: ?Sized, T: KernelTask<V, S>>(
    task: T,
    shared: &S,
) -> T::Output {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: `avx::run` is compiled for AVX, and the CPU has AVX:
        // checked just above.
        #[allow(unsafe_code)]
        return unsafe { avx::run(task, shared) };
    }
    task.run(portable_kernel(), shared)
}

/// The portable pass as a [`Kernel`].
#[inline(always)]
fn portable_kernel<V: Value>() -> impl Kernel<V> {
    pass_fn(|ys: &[V], ws: &[f64], c, lanes, scaled| {
        if scaled {
            add_channel_portable::<V, true>(ys, ws, c, lanes)
        } else {
            add_channel_portable::<V, false>(ys, ws, c, lanes)
        }
    })
}

/// [`Lanes::add_products`] or, with a scale, [`Lanes::add_products_scaled`]
/// as a [`KernelTask`].
struct Products<'a, V: Value> {
    lanes: &'a mut Lanes<V>,
    ys: &'a [V],
    ws: &'a [f64],
    scale: Option<(&'a mut LaneValues<V>, &'a mut LaneValues<V>)>,
}

impl<V: Value> KernelTask<V> for Products<'_, V> {
    type Output = ();
    /// Inlined into the kernel's function, where the AVX pass's
    /// intrinsics inline too (a call of its own left each intrinsic one).
    #[inline(always)]
    fn run(self, kernel: impl Kernel<V>, _: &()) {
        match self.scale {
            Some((magnitude, largest)) => self
                .lanes
                .add_products_scaled_in(kernel, self.ys, self.ws, magnitude, largest),
            None => self.lanes.add_products_in(kernel, self.ys, self.ws),
        }
    }
}

/// Adds channel `c` of the products `w_i y_i`, four at a time, to the lanes
/// `[sum, carry, magnitude, largest]` of that channel: term `4 j + k` into
/// lane `k`, each term after the last whole group into lane 0 (the other
/// lanes adding 0, which leaves them as they were). With `SCALED`, `|w_i
/// y_i|` is added to `magnitude` and the largest kept in `largest`.
#[inline(always)]
fn add_channel_portable<V: Value, const SCALED: bool>(
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

/// The lanes' pass in AVX registers. `wide`'s `f64x4` is fixed when the
/// crate is built, to x86-64's baseline SSE2, which takes the four lanes
/// two at a time; AVX takes them at once. The sum pass is what lightquad
/// took over a plain loop (Gauss–Legendre on `cos(50 x)` at n = 1e6,
/// `examples/gl_race.rs`): 1.03 to 1.04 times it in SSE2.
#[cfg(target_arch = "x86_64")]
mod avx {
    use std::arch::x86_64::{
        __m256d, _mm256_add_pd, _mm256_andnot_pd, _mm256_max_pd, _mm256_mul_pd, _mm256_set1_pd,
        _mm256_setr_pd, _mm256_sub_pd,
    };

    use wide::f64x4;

    use super::{KernelTask, LANES, pass_fn};
    use crate::value::Value;

    /// `task` with the AVX pass (and `shared`, as [`KernelTask`] says),
    /// compiled for AVX. The pass is a closure defined here and
    /// `inline(always)` (AVX code once inlined here), which a
    /// function compiled for AVX may not be: in one of two callers that
    /// asked the same, the compiler left a `#[inline]` pass a call of its
    /// own once a group (`line_sum_par`'s spans, not `product_sum`). The
    /// same operations on each lane in the same order as
    /// [`super::add_channel_portable`], so the same bits, but for which NaN
    /// comes out where two meet in one operation (a NaN term added to a
    /// carry already made NaN by infinities of both signs): the compiler
    /// may swap the operands of an addition, and x86 keeps the first NaN.
    /// A NaN is a NaN to every caller in the crate, which stops at a value that is not
    /// finite.
    #[target_feature(enable = "avx")]
    pub(super) fn run<V: Value, S: ?Sized, T: KernelTask<V, S>>(task: T, shared: &S) -> T::Output {
        let pass = pass_fn(
            #[inline(always)]
            |ys: &[V], ws: &[f64], c, [sum, carry, magnitude, largest]: [&mut f64x4; 4], scaled| {
                let mut state = [
                    to_avx(*sum),
                    to_avx(*carry),
                    to_avx(*magnitude),
                    to_avx(*largest),
                ];
                let mut y4 = ys.chunks_exact(LANES);
                let mut w4 = ws.chunks_exact(LANES);
                for (y, w) in (&mut y4).zip(&mut w4) {
                    let y = _mm256_setr_pd(
                        y[0].channel(c),
                        y[1].channel(c),
                        y[2].channel(c),
                        y[3].channel(c),
                    );
                    let t = _mm256_mul_pd(y, _mm256_setr_pd(w[0], w[1], w[2], w[3]));
                    add(&mut state, t, scaled);
                }
                for (y, &w) in y4.remainder().iter().zip(w4.remainder()) {
                    let t = _mm256_setr_pd(y.channel(c) * w, 0.0, 0.0, 0.0);
                    add(&mut state, t, scaled);
                }
                let [s, e, m, l] = state;
                (*sum, *carry, *magnitude, *largest) =
                    (from_avx(s), from_avx(e), from_avx(m), from_avx(l));
            },
        );
        task.run(pass, shared)
    }

    /// One group of four terms `t` into `[sum, carry, magnitude, largest]`,
    /// as [`super::add_channel_portable`] adds it: TwoSum and, with
    /// `scaled`, `|t|` and `maxpd`.
    #[target_feature(enable = "avx")]
    #[inline]
    fn add([s, e, m, l]: &mut [__m256d; 4], t: __m256d, scaled: bool) {
        let u = _mm256_add_pd(*s, t);
        let b = _mm256_sub_pd(u, *s);
        let err = _mm256_add_pd(_mm256_sub_pd(*s, _mm256_sub_pd(u, b)), _mm256_sub_pd(t, b));
        *e = _mm256_add_pd(*e, err);
        *s = u;
        if scaled {
            let a = _mm256_andnot_pd(_mm256_set1_pd(-0.0), t);
            *m = _mm256_add_pd(*m, a);
            *l = _mm256_max_pd(a, *l);
        }
    }

    /// The four lanes of `v` as one AVX register, and back
    /// ([`from_avx`]): the same 32 bytes, `wide`'s own conversion (a cast).
    /// The compiler then keeps a sum's lanes as one 256-bit value from
    /// group to group. Rebuilt from `to_array` with `_mm256_setr_pd` and
    /// taken apart lane by lane, they were kept as `wide`'s two SSE2 halves
    /// and put together again at every group: some 20 shuffles a group
    /// once the pass was unrolled (`nodes::line::group_before`). With both,
    /// lightquad went from 1.0050 to 0.9988 times bilby
    /// (`examples/gl_race.rs`, medians of 10 processes each).
    #[target_feature(enable = "avx")]
    #[inline]
    fn to_avx(v: f64x4) -> __m256d {
        v.into()
    }

    /// [`to_avx`] back.
    #[target_feature(enable = "avx")]
    #[inline]
    fn from_avx(v: __m256d) -> f64x4 {
        v.into()
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

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use rand::{RngExt, SeedableRng};
    use wide::f64x4;

    use super::{Kernel, KernelTask, add_channel_portable, with_kernel};
    use crate::value::{Rgb, Value};

    /// One channel's pass with the kernel [`with_kernel`] chooses.
    struct Channel<'a, V: Value> {
        ys: &'a [V],
        ws: &'a [f64],
        c: usize,
        lanes: [&'a mut f64x4; 4],
        scaled: bool,
    }

    impl<V: Value> KernelTask<V> for Channel<'_, V> {
        type Output = ();
        fn run(self, kernel: impl Kernel<V>, _: &()) {
            kernel.add_channel(self.ys, self.ws, self.c, self.lanes, self.scaled)
        }
    }

    /// The four lanes of one channel after a pass, as bits (every NaN as
    /// `f64::NAN`'s).
    fn pass<V: Value, const SCALED: bool>(
        ys: &[V],
        ws: &[f64],
        c: usize,
        avx: bool,
    ) -> [[u64; 4]; 4] {
        // Lanes that start away from 0, the largest below some terms.
        let mut lanes = [1e-3, -2e-17, 0.5, 1e-4].map(|x| f64x4::new([x, -x, 2.0 * x, 0.0]));
        let [s, e, m, l] = &mut lanes;
        if avx {
            with_kernel(Channel {
                ys,
                ws,
                c,
                lanes: [s, e, m, l],
                scaled: SCALED,
            });
        } else {
            add_channel_portable::<V, SCALED>(ys, ws, c, [s, e, m, l]);
        }
        lanes.map(|v| {
            v.to_array()
                .map(|x| if x.is_nan() { f64::NAN } else { x }.to_bits())
        })
    }

    /// The AVX pass gives the portable pass's bits: every lane of the sum,
    /// the carry, `sum |w y|` and the largest term, for scalars and each
    /// channel of a colour, on lengths with every remainder, with terms of
    /// both signs over many scales, -0, a subnormal, -MAX, infinities and
    /// a NaN among them. Any NaN counts as one value (see `avx::run` on
    /// which NaN comes out).
    #[test]
    fn the_avx_pass_gives_the_portable_bits() {
        if !std::arch::is_x86_feature_detected!("avx") {
            eprintln!("no AVX on this CPU: the AVX pass cannot run, nothing to compare");
            return;
        }
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        for n in (0..=9).chain([255, 256, 257]) {
            for nan in [None, Some(n / 2)] {
                // Every seventh term one of the edge values.
                let edges = [-0.0, 5e-324, -f64::MAX, f64::INFINITY, f64::NEG_INFINITY];
                let mut term = |i: usize| {
                    if nan == Some(i) {
                        f64::NAN
                    } else if i % 7 == 6 {
                        edges[(i / 7) % edges.len()]
                    } else {
                        (rng.random::<f64>() - 0.5) * 10f64.powi(rng.random_range(-20..20))
                    }
                };
                let ys: Vec<f64> = (0..n).map(&mut term).collect();
                let rgb: Vec<Rgb> = (0..n).map(|i| Rgb::new(term(i), ys[i], -ys[i])).collect();
                let ws: Vec<f64> = (0..n).map(|_| rng.random::<f64>()).collect();
                assert_eq!(
                    pass::<f64, true>(&ys, &ws, 0, true),
                    pass::<f64, true>(&ys, &ws, 0, false),
                    "n = {n}, NaN at {nan:?}"
                );
                assert_eq!(
                    pass::<f64, false>(&ys, &ws, 0, true),
                    pass::<f64, false>(&ys, &ws, 0, false)
                );
                for c in 0..3 {
                    assert_eq!(
                        pass::<Rgb, true>(&rgb, &ws, c, true),
                        pass::<Rgb, true>(&rgb, &ws, c, false),
                        "n = {n}, channel {c}"
                    );
                }
            }
        }
    }
}
