//! Randomised quasi-Monte Carlo: Halton points scrambled by random digit
//! permutations, in 1 to [`MAX_DIM`] = 21 dimensions.
//!
//! Coordinate `j` of point `i` is the radical inverse of `i` in the `j`-th
//! prime base `p` ([`PRIMES`]: 2, 3, 5, .., 73): with `i = sum_l a_l p^l`,
//! `x = sum_l a_l p^-(l+1)`. A scramble replaces each digit `a_l` by
//! `pi_(j,l)(a_l)`, a permutation of `0..p` drawn uniformly for each
//! coordinate and digit level, on every one of the `L_p` levels with
//! `p^L_p <= 2^52` (those beyond `i`'s own digits too, where the digit is 0),
//! so each scrambled point is uniform on the grid of spacing `p^-L_p` (the
//! random-permutation Halton of Owen, "A randomized Halton algorithm in R",
//! 2017), taken at the centre of its cell. One permutation serves all points
//! of a level, so the first `p^k` points still put one value into each
//! interval of width `p^-k` of coordinate `j`.
//!
//! The estimate and its error are [`Sobol`](super::Sobol)'s: `R = 8`
//! independent scrambles of `n / R` points each (any count, not only powers
//! of two), their mean and the Student-t scaled standard error of the `R`
//! means, doubted on the same checks (the scrambles all agree; the values
//! fail the Monte Carlo tail check).

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::Rule;
use super::monte_carlo::Welford;
use super::sobol::{MAX_DIM, MAX_REPLICATES, over_scrambles};
use super::{Dimensions, sobol};
use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::quadrature::nodes::non_finite;
use crate::sum::Compensated;
use crate::value::Value;
use rand::RngExt;

/// The bases of the coordinates: the first [`MAX_DIM`] primes.
pub const PRIMES: [u32; MAX_DIM] = [
    2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37, 41, 43, 47, 53, 59, 61, 67, 71, 73,
];

/// Digit levels `L_p` of base `p`: the most with `p^L_p <= 2^52`, so that a
/// scaled coordinate plus one half is exact in f64 and its quotient by `p^L_p`
/// stays below 1.
pub const fn levels(p: u32) -> u32 {
    let (mut l, mut q) = (0, 1u64);
    while q * p as u64 <= 1 << 52 {
        q *= p as u64;
        l += 1;
    }
    l
}

/// `p^levels(p)`: the grid a scaled coordinate counts in.
pub const fn grid(p: u32) -> u64 {
    (p as u64).pow(levels(p))
}

/// One scramble's digit permutations, for the first `dims` coordinates.
#[derive(Debug, Clone)]
pub struct DigitPermutations {
    /// Per coordinate, `pi_l(a)` at `l * p + a` for `l < L_p`.
    perms: Vec<Vec<u8>>,
    /// Per coordinate, `tail[k] = sum_(l >= k) pi_l(0) p^(L_p - 1 - l)`: the
    /// levels beyond an index's digits.
    tails: Vec<Vec<u64>>,
}

impl DigitPermutations {
    /// The identity permutations: the unscrambled Halton points.
    pub fn identity(dims: usize) -> Self {
        Self::from_fn(dims, |_, _, perm| {
            for (a, v) in perm.iter_mut().enumerate() {
                *v = a as u8;
            }
        })
    }

    /// Independent uniform permutations (Fisher-Yates), coordinate by
    /// coordinate and level by level.
    pub fn random<R: rand::Rng + ?Sized>(dims: usize, rng: &mut R) -> Self {
        Self::from_fn(dims, |_, _, perm| {
            for (a, v) in perm.iter_mut().enumerate() {
                *v = a as u8;
            }
            for k in (1..perm.len()).rev() {
                perm.swap(k, rng.random_range(0..=k));
            }
        })
    }

    /// Tables filled by `fill(coordinate, level, permutation)`.
    fn from_fn(dims: usize, mut fill: impl FnMut(usize, u32, &mut [u8])) -> Self {
        assert!(dims <= MAX_DIM, "{dims} coordinates, at most {MAX_DIM}");
        let mut perms = Vec::with_capacity(dims);
        let mut tails = Vec::with_capacity(dims);
        for (j, &p) in PRIMES.iter().enumerate().take(dims) {
            let (p, l_p) = (p as usize, levels(p));
            let mut perm = vec![0u8; l_p as usize * p];
            for (l, level) in perm.chunks_mut(p).enumerate() {
                fill(j, l as u32, level);
            }
            // tail[k] from the deepest level up: weights p^(L_p - 1 - l).
            let mut tail = vec![0u64; l_p as usize + 1];
            let mut w = 1u64;
            for l in (0..l_p as usize).rev() {
                tail[l] = tail[l + 1] + perm[l * p] as u64 * w;
                w *= p as u64;
            }
            perms.push(perm);
            tails.push(tail);
        }
        DigitPermutations { perms, tails }
    }

    /// Coordinate `dim` of point `index`, scaled by `p^L_p` to an integer:
    /// `sum_l pi_l(a_l) p^(L_p - 1 - l)` over the base-`p` digits `a_l` of
    /// `index` (0 beyond them).
    pub fn scaled(&self, index: u32, dim: usize) -> u64 {
        let p = PRIMES[dim] as u64;
        let perm = &self.perms[dim];
        let mut w = grid(PRIMES[dim]) / p;
        let (mut v, mut i, mut l) = (0u64, index as u64, 0usize);
        // An index below 2^32 has fewer digits than L_p in every base.
        while i != 0 {
            v += perm[l * p as usize + (i % p) as usize] as u64 * w;
            i /= p;
            w /= p;
            l += 1;
        }
        v + self.tails[dim][l]
    }

    /// Coordinate `dim` of point `index` in `(0, 1)`: the centre
    /// `(scaled + 1/2) / p^L_p` of its cell.
    pub fn coordinate(&self, index: u32, dim: usize) -> f64 {
        (self.scaled(index, dim) as f64 + 0.5) / grid(PRIMES[dim]) as f64
    }
}

/// Halton points scrambled by random digit permutations, `replicates`
/// independent scrambles.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Halton {
    /// Number of independent scrambles (>= 2) used for the standard error
    /// (default 8).
    #[serde(
        default = "Halton::default_replicates",
        deserialize_with = "Halton::read_replicates"
    )]
    #[schemars(range(min = 2, max = 1_000_000))]
    pub replicates: usize,
}

impl Halton {
    fn default_replicates() -> usize {
        8
    }

    /// The range named where a value does not fit (`-1` said `>= 0`).
    fn read_replicates<'de, D: serde::Deserializer<'de>>(d: D) -> Result<usize, D::Error> {
        crate::experiment::tagged::whole(d, 2, MAX_REPLICATES as i128, "")
    }
}

impl Default for Halton {
    fn default() -> Self {
        Halton {
            replicates: Halton::default_replicates(),
        }
    }
}

impl Rule for Halton {
    fn name(&self) -> &'static str {
        "halton"
    }

    fn about(&self) -> &'static str {
        "Halton points (1-D to 21-D) scrambled by random digit permutations, independent scrambles (default 8); standard error over scrambles, Student-t scaled"
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
        sobol::check_replicates(self.replicates)
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
                rule: "halton",
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
        // Indices stay below 2^31, as Sobol's.
        let per = (n / reps).min(1 << 31);
        let mut means = Welford::<V>::default();
        // Every point's value, for the tail diagnostic only.
        let mut points = Welford::<V>::default();
        for _ in 0..reps {
            let perms = DigitPermutations::random(D, rng);
            let mut sum = Compensated::<V>::new();
            for i in 0..per as u32 {
                let mut p = [0.0; D];
                for (d, c) in p.iter_mut().enumerate() {
                    *c = perms.coordinate(i, d);
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
