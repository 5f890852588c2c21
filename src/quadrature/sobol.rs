//! Randomised quasi-Monte Carlo: Owen-scrambled Sobol' points in 1 to
//! [`MAX_DIM`] = 21 dimensions.
//!
//! The first Sobol' coordinate is the van der Corput sequence (bit reversal of
//! the index); coordinates 2 to 21 take Joe and Kuo's direction numbers
//! (`new-joe-kuo-6.21201`, [`sobol_u32`]), the second being the sequence with
//! generator matrix "Pascal's triangle mod 2" (`m_1 = 1`,
//! `m_k = 2 m_(k-1) xor m_(k-1)`). Points come in natural order (point `i`
//! is the xor of the direction numbers of `i`'s set bits), not Gray-code
//! order. The first `2^k` points form a (0, k, 2)-net in the first two
//! coordinates (every elementary box of area `2^-k` holds exactly one point),
//! a (t, k, D)-net in more (`t` at most the sum of `s - 1` over the
//! coordinates, `s` the degree of a coordinate's primitive polynomial), and in every
//! single coordinate one point to each interval of width `2^-k`.
//!
//! Each coordinate is scrambled by a nested uniform (Owen) scramble realised as
//! a hash in the bit-reversed domain (Burley, "Practical hash-based Owen
//! scrambling", JCGT 9(4), 2020, after Laine and Karras 2011): each output bit
//! is the input bit flipped by a function of the more significant bits only, so
//! the net property survives. `R = 8` independent scrambles of `2^k` points
//! each give the estimate (their mean) and its standard error (spread of the
//! eight means / sqrt 8); each scramble draws one seed a coordinate, and
//! two in 1-D. For smooth integrands the error falls like `N^(-3/2)` up to
//! log factors (measured in 4-D and 6-D on `e^(x_1 + .. + x_D)`: tests/it/sobol_dims.rs).
//!
//! A standard error from `R` means has `R - 1` degrees of freedom, so
//! `+- 1.96` of it is a Student-t interval of only ~91% at `R = 8`
//! (measured: 89-92% coverage of V-E over 1000 repeats). The reported error
//! is therefore the standard error times `t_{R-1}(0.975) / 1.96` (1.21 at
//! `R = 8`): `value +- 1.96 error` is the 95% t interval, and the error still
//! reads as one standard error.
//!
//! The estimate is doubted (`reliable = false`) when the scrambles all gave
//! the same mean (in any channel: a standard error of 0), or when the
//! values at all the points fail the tail check of plain Monte Carlo
//! ([`Welford::doubtful`]: all alike, or a sample variance whose estimated
//! relative error exceeds [`variance_doubt_threshold`]).
//! From 256 points a scramble the tail check also runs at a scramble's own
//! count: a light that is a step in one coordinate (a small coaxial disk
//! in the uniform hemisphere map, 2.7 cells of 1/2048 wide) gets the same
//! 2 or 3 hits in every scramble, and when all eight agree (0.7^8 = 6% of
//! runs) their means differ only within the cells: 3913 standard errors
//! off at 16384 points, 8583 at 65536, unflagged before; the check sees 3
//! and 11 hits a scramble and doubts every run.
//! The first catches a constant integrand (truly: nothing varied), an
//! unseen rare event, and a step that the nets place identically in every
//! scramble: `[x < 0.1]` covered 82% at every n, `[x < 0.01]` 63% at 4096
//! points, unflagged; now 0-0.8% of runs are neither covered nor flagged (a
//! step at a dyadic point is exact and flagged). The second catches
//! infinite-variance integrands, whose scrambled-net variance is infinite
//! too: `x^-0.9` covered 25-30% unflagged, now 96-99% flagged from 64
//! points on, 1.4-3.7% neither. Measured over 1000 repeats at 16 .. 4096
//! points: smooth integrands (x, e^x, sin(pi x), x^2, sqrt x) flagged in
//! 0-0.6% of runs at 16 points and none from 64 on; peaked ones at 16
//! points (`1/(1 + 25 x^2)`: 11%) and 64 (e^{10x}: 31%, a Gaussian of width
//! 0.05: 53%, covered 76-95% there), none from 256 on. Not caught: integrable singularities of finite
//! variance (`x^-0.25`: 84-86% coverage, 14-16% of runs neither covered
//! nor flagged; `x^-0.45`: 77-79%, 17-23%), and `x^-0.6` from 1024 points
//! on, where the tail check's flag rate falls to 70-79% (21-29% neither),
//! because the eight scramble means are skewed by the point
//! nearest the singularity and eight of them cannot show it (a kurtosis
//! check on the means flagged 2-4% of smooth runs and caught little).

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::{Dimensions, Rule};
use super::monte_carlo::{Welford, variance_doubt_threshold};
use crate::error::QuadError;
use crate::estimate::{Estimate, t95_factor};
use crate::quadrature::nodes::non_finite;
use crate::sum::Compensated;
use crate::value::Value;

/// Points a scramble from which the tail check also runs at a scramble's
/// count ([`Sobol`]'s module documentation): below it, a scramble of a
/// smooth integrand's values is too few for its kurtosis to mean much
/// (`e^{10x}` at 64 points a scramble sits on the threshold).
const PER_SCRAMBLE_CHECK: usize = 256;

/// Owen-scrambled Sobol' points, `replicates` independent scrambles.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Sobol {
    /// Number of independent scrambles (>= 2) used for the standard error
    /// (default 8).
    #[serde(
        default = "Sobol::default_replicates",
        deserialize_with = "Sobol::read_replicates"
    )]
    #[schemars(range(min = 2, max = 1_000_000))]
    pub replicates: usize,
}

impl Sobol {
    fn default_replicates() -> usize {
        8
    }

    /// The range named where a value does not fit (`-1` said `>= 0`).
    fn read_replicates<'de, D: serde::Deserializer<'de>>(d: D) -> Result<usize, D::Error> {
        crate::experiment::tagged::whole(d, 2, MAX_REPLICATES as i128, "")
    }
}

impl Default for Sobol {
    fn default() -> Self {
        Sobol {
            replicates: Sobol::default_replicates(),
        }
    }
}

/// Coordinates the rule integrates: van der Corput's and the first twenty of
/// Joe and Kuo's table (`new-joe-kuo-6.21201`, rows d = 2..21).
pub const MAX_DIM: usize = 21;

/// Direction numbers of Sobol' coordinates 2 to 21: rows d = 2..21 of S. Joe
/// and F. Y. Kuo's table `new-joe-kuo-6.21201` ("Constructing Sobol sequences
/// with better two-dimensional projections", SIAM J. Sci. Comput. 30 (2008)
/// 2635-2654; <https://web.maths.unsw.edu.au/~fkuo/sobol/>). Each row is
/// `(a, [m_1, .., m_s])`: `s` is the degree of the coordinate's primitive
/// polynomial `x^s + a_1 x^(s-1) + .. + a_(s-1) x + 1`, `a` its inner
/// coefficients as the bits `a_1 .. a_(s-1)` (`a_1` the most significant), and
/// `m_k` (odd, below `2^k`) the initial direction numbers. Checked against
/// scipy's points (tests/data/sobol_joe_kuo.json). Coordinate 1 is van der
/// Corput's, with no row.
const JOE_KUO: [(u32, &[u64]); MAX_DIM - 1] = [
    (0, &[1]),
    (1, &[1, 3]),
    (1, &[1, 3, 1]),
    (2, &[1, 1, 1]),
    (1, &[1, 1, 3, 3]),
    (4, &[1, 3, 5, 13]),
    (2, &[1, 1, 5, 5, 17]),
    (4, &[1, 1, 5, 5, 5]),
    (7, &[1, 1, 7, 11, 19]),
    (11, &[1, 1, 5, 1, 1]),
    (13, &[1, 1, 1, 3, 11]),
    (14, &[1, 3, 5, 5, 31]),
    (1, &[1, 3, 3, 9, 7, 49]),
    (13, &[1, 1, 1, 15, 21, 21]),
    (16, &[1, 3, 1, 13, 27, 49]),
    (19, &[1, 1, 1, 15, 7, 5]),
    (22, &[1, 3, 1, 15, 13, 25]),
    (25, &[1, 1, 5, 5, 19, 61]),
    (1, &[1, 3, 7, 11, 23, 15, 103]),
    (4, &[1, 3, 7, 13, 13, 15, 69]),
];

/// The 32 direction numbers `v_k = m_k / 2^k` (k = 1..32) of one row of
/// [`JOE_KUO`], as 32-bit fractions `m_k 2^(32-k)`. Beyond the initial
/// `m_1..m_s`, Sobol's recurrence
/// `m_k = 2 a_1 m_(k-1) xor 4 a_2 m_(k-2) xor .. xor 2^(s-1) a_(s-1) m_(k-s+1) xor 2^s m_(k-s) xor m_(k-s)`.
/// Coordinate 2 (`s = 1`, `a = 0`, `m_1 = 1`) gives `m_k = 2 m_(k-1) xor m_(k-1)`:
/// Pascal's triangle mod 2.
const fn directions(a: u32, init: &[u64]) -> [u32; 32] {
    let s = init.len();
    // m[k] for k = 1..=32 (m[0] unused); m_k < 2^k, so the u64s never overflow.
    let mut m = [0u64; 33];
    let mut v = [0u32; 32];
    let mut k = 1;
    while k <= 32 {
        if k <= s {
            m[k] = init[k - 1];
        } else {
            let mut x = m[k - s] ^ (m[k - s] << s);
            let mut j = 1;
            while j < s {
                if (a >> (s - 1 - j)) & 1 == 1 {
                    x ^= m[k - j] << j;
                }
                j += 1;
            }
            m[k] = x;
        }
        v[k - 1] = (m[k] << (32 - k)) as u32;
        k += 1;
    }
    v
}

/// True when every row of [`JOE_KUO`] is well formed: `a < 2^(s-1)`, and
/// every `m_k` odd and below `2^k`.
const fn table_is_well_formed() -> bool {
    let mut d = 0;
    while d < JOE_KUO.len() {
        let (a, init) = JOE_KUO[d];
        let s = init.len();
        if s == 0 || s > 31 || a >= 1 << (s - 1) {
            return false;
        }
        let mut k = 1;
        while k <= s {
            if init[k - 1] & 1 == 0 || init[k - 1] >= 1 << k {
                return false;
            }
            k += 1;
        }
        d += 1;
    }
    true
}
const _: () = assert!(table_is_well_formed());

/// Direction numbers of coordinates 2 to [`MAX_DIM`], computed at compile time.
const DIRECTIONS: [[u32; 32]; MAX_DIM - 1] = {
    let mut all = [[0u32; 32]; MAX_DIM - 1];
    let mut d = 0;
    while d < MAX_DIM - 1 {
        all[d] = directions(JOE_KUO[d].0, JOE_KUO[d].1);
        d += 1;
    }
    all
};

/// Unscrambled Sobol' coordinate `dim` (0-based: 0 is van der Corput's) of
/// point `index` in natural (not Gray-code) order, as a 32-bit fraction: the
/// xor of the direction numbers `v_k` over the set bits `k` of `index`.
///
/// # Panics
///
/// When `dim >= MAX_DIM`.
#[inline]
pub fn sobol_u32(index: u32, dim: usize) -> u32 {
    if dim == 0 {
        return index.reverse_bits();
    }
    let v = &DIRECTIONS[dim - 1];
    let mut x = 0u32;
    let mut i = index;
    while i != 0 {
        x ^= v[i.trailing_zeros() as usize];
        // Clear the lowest set bit.
        i &= i - 1;
    }
    x
}

/// Nested uniform scramble of a 32-bit fraction with `seed`.
///
/// In the bit-reversed domain, adding the seed and `x ^= x * even` only let a
/// bit depend on less significant bits; reversed back, each bit of the
/// fraction is flipped by a function of the more significant bits: an Owen
/// scramble (Burley 2020's constants).
#[inline]
pub fn owen_scramble(x: u32, seed: u32) -> u32 {
    let mut r = x.reverse_bits();
    r = r.wrapping_add(seed);
    r ^= r.wrapping_mul(0x6c50_b47c);
    r ^= r.wrapping_mul(0xb82f_1e52);
    r ^= r.wrapping_mul(0xc7af_e638);
    r ^= r.wrapping_mul(0x8d22_f6e6);
    r.reverse_bits()
}

/// The most scrambles: each needs a point of the budget, and a replicate
/// count of 1e12 was refused only as "no budget reaches" it, at `budgets`.
pub const MAX_REPLICATES: usize = 1_000_000;

/// A 32-bit fraction to the centre of its cell in `[0, 1)`.
#[inline]
fn to_unit(x: u32) -> f64 {
    (x as f64 + 0.5) * (1.0 / 4_294_967_296.0)
}

impl Rule for Sobol {
    fn name(&self) -> &'static str {
        "sobol"
    }

    fn about(&self) -> &'static str {
        "Owen-scrambled Sobol' points (1-D to 21-D, Joe-Kuo direction numbers), independent scrambles (default 8); standard error over scrambles, Student-t scaled"
    }

    /// One point per scramble.
    fn min_budget(&self, _dim: usize) -> usize {
        self.replicates
    }

    fn is_random(&self) -> bool {
        true
    }

    fn dimensions(&self) -> Dimensions {
        Dimensions {
            min: 1,
            max: MAX_DIM,
        }
    }

    fn check(&self) -> Result<(), QuadError> {
        check_replicates(self.replicates)
    }

    fn integrate_unguarded<
        const D: usize,
        V: Value,
        R: rand::Rng + ?Sized,
        F: FnMut([f64; D]) -> Result<V, QuadError>,
    >(
        &self,
        n: usize,
        rng: &mut R,
        mut f: F,
    ) -> Result<Estimate<V>, QuadError> {
        crate::quadrature::check_budget(n)?;
        if D > MAX_DIM {
            return Err(QuadError::UnsupportedDimension {
                rule: "sobol",
                dim: D,
                supported: "1 to 21",
            });
        }
        self.check()?;
        let reps = self.replicates;
        if n < reps {
            return Err(QuadError::invalid(
                "n",
                n,
                format!("at least {reps} evaluations (one point per scramble)"),
            ));
        }
        // 2^k points per scramble, the largest power of two that fits.
        let per = (n / reps).min(1 << 31);
        let per = 1usize << (usize::BITS - 1 - per.leading_zeros());
        let mut means = Welford::<V>::default();
        // Every point's value, for the tail diagnostic only.
        let mut points = Welford::<V>::default();
        for _ in 0..reps {
            // One seed a coordinate, and at least two: the 1-D rule drew two
            // before coordinates 3 to 21 came, and draws them still, so that a
            // seed gives the same 1-D estimate as then.
            let mut seeds = [0u32; MAX_DIM];
            for s in seeds.iter_mut().take(D.max(2)) {
                *s = rng.next_u32();
            }
            let mut sum = Compensated::<V>::new();
            for i in 0..per as u32 {
                let mut p = [0.0; D];
                for (d, c) in p.iter_mut().enumerate() {
                    *c = to_unit(owen_scramble(sobol_u32(i, d), seeds[d]));
                }
                let y = f(p)?;
                if !y.all_finite() {
                    return Err(non_finite(&p, &y));
                }
                sum.add(y);
                points.add(y);
            }
            means.add(sum.total().map(|s| s / per as f64));
        }
        Ok(over_scrambles(&means, &points, reps, per))
    }
}

/// The replicate count in `2..=MAX_REPLICATES`, or why not.
pub(super) fn check_replicates(replicates: usize) -> Result<(), QuadError> {
    if !(2..=MAX_REPLICATES).contains(&replicates) {
        return Err(QuadError::invalid(
            "replicates",
            replicates,
            format!(
                "an integer in 2..={MAX_REPLICATES} (the standard error needs two scrambles, \
                 and each scramble at least one point of the budget)"
            ),
        ));
    }
    Ok(())
}

/// The estimate from `reps` scrambles of `per` points: the mean of the
/// scramble `means`, the standard error of the mean times
/// `t_(reps-1)(0.975) / 1.96`, doubted when the scrambles agree or the
/// values at all the `points` fail the tail check (module documentation).
pub(super) fn over_scrambles<V: Value>(
    means: &Welford<V>,
    points: &Welford<V>,
    reps: usize,
    per: usize,
) -> Estimate<V> {
    let t = t95_factor(reps as f64 - 1.0);
    let estimate = Estimate::random(
        means.mean(),
        means.standard_error().map(|e| e * t),
        (reps * per) as u64,
    );
    // Scrambles that all gave the same mean (SE 0), or points whose
    // spread is carried by a few values: over all the points, or, from
    // PER_SCRAMBLE_CHECK points a scramble, within one scramble (the
    // tail check at a scramble's count: sqrt((b2 - 1) / per) from the
    // kurtosis b2 of all the points; module documentation).
    let alike = (0..V::CHANNELS).any(|c| means.standard_error().channel(c) == 0.0);
    let per_scramble = points.worst_variance_relative_error() * (reps as f64).sqrt();
    let few = points.doubtful()
        || (per >= PER_SCRAMBLE_CHECK && per_scramble > variance_doubt_threshold(per as u64));
    if alike || few {
        estimate.doubted()
    } else {
        estimate
    }
}

