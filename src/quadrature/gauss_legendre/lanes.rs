//! `L` numbers computed in lock step, so the Bogaert formulas are written once
//! and run on one node (`L = 1`) or several at once: lane-wise
//! arithmetic on arrays is code the compiler reliably turns into packed SIMD
//! instructions, which a node-at-a-time loop with long dependency chains is not.

use std::ops::{Add, Div, Mul, Neg, Sub};

/// `L` values computed in lock step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lanes<const L: usize>(pub [f64; L]);

impl<const L: usize> Lanes<L> {
    /// Every lane `x`.
    #[inline(always)]
    pub fn splat(x: f64) -> Self {
        Lanes([x; L])
    }

    /// Lane-wise `if self > threshold { then } else { otherwise }`.
    #[inline(always)]
    pub fn select_gt(self, threshold: f64, then: Self, otherwise: Self) -> Self {
        Lanes(std::array::from_fn(|i| {
            if self.0[i] > threshold {
                then.0[i]
            } else {
                otherwise.0[i]
            }
        }))
    }
}

/// Lane-wise binary operators: `Lanes op Lanes`, `Lanes op f64`, `f64 op Lanes`.
macro_rules! lane_op {
    ($trait:ident, $method:ident, $op:tt) => {
        impl<const L: usize> $trait for Lanes<L> {
            type Output = Self;
            #[inline(always)]
            fn $method(self, rhs: Self) -> Self {
                Lanes(std::array::from_fn(|i| self.0[i] $op rhs.0[i]))
            }
        }
        impl<const L: usize> $trait<f64> for Lanes<L> {
            type Output = Self;
            #[inline(always)]
            fn $method(self, rhs: f64) -> Self {
                Lanes(std::array::from_fn(|i| self.0[i] $op rhs))
            }
        }
        impl<const L: usize> $trait<Lanes<L>> for f64 {
            type Output = Lanes<L>;
            #[inline(always)]
            fn $method(self, rhs: Lanes<L>) -> Lanes<L> {
                Lanes(std::array::from_fn(|i| self $op rhs.0[i]))
            }
        }
    };
}
lane_op!(Add, add, +);
lane_op!(Sub, sub, -);
lane_op!(Mul, mul, *);
lane_op!(Div, div, /);

impl<const L: usize> Neg for Lanes<L> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Lanes(std::array::from_fn(|i| -self.0[i]))
    }
}

/// Dekker's exact product: `a b = p + e`, lane-wise, without FMA.
#[inline(always)]
pub fn two_prod<const L: usize>(a: Lanes<L>, b: f64) -> (Lanes<L>, Lanes<L>) {
    const SPLIT: f64 = 134_217_729.0; // 2^27 + 1
    let p = a * b;
    let t = a * SPLIT;
    let a_hi = t - (t - a);
    let a_lo = a - a_hi;
    let tb = b * SPLIT;
    let b_hi = tb - (tb - b);
    let b_lo = b - b_hi;
    (
        p,
        ((a_hi * b_hi - p) + a_hi * b_lo + a_lo * b_hi) + a_lo * b_lo,
    )
}

/// `a + b = s + e` exactly when `|a| >= |b|`, lane-wise.
#[inline(always)]
pub fn quick_two_sum<const L: usize>(a: Lanes<L>, b: Lanes<L>) -> (Lanes<L>, Lanes<L>) {
    let s = a + b;
    (s, b - (s - a))
}
