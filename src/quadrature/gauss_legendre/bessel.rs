//! Zeros of the Bessel function `J_0` and `J_1` squared at those zeros, the two
//! Bessel quantities Bogaert's expansion of the Gauss–Legendre rule needs.
//!
//! The first 20 values are tabulated (computed with mpmath at 40 digits,
//! `besseljzero(0, k)` and `besselj(1, z)**2`); beyond them the McMahon
//! expansions below are accurate to better than 1e-19 relative (checked against
//! mpmath for k = 21..100 when this table was made).

/// `(j_{0,k}, J_1(j_{0,k})^2)` for k = 1..=20, mpmath at 40 digits.
// The digits are kept as computed; the compiler rounds them correctly.
#[allow(clippy::excessive_precision)]
const TABLE: [(f64, f64); 20] = [
    (2.404_825_557_695_772_768_6, 0.269_514_123_941_916_926_14),
    (5.520_078_110_286_310_649_6, 0.115_780_138_582_203_695_81),
    (8.653_727_912_911_012_217, 0.073_686_351_136_408_215_141),
    (11.791_534_439_014_281_614, 0.054_037_573_198_116_282_042),
    (14.930_917_708_487_785_948, 0.042_661_429_017_243_091_266),
    (18.071_063_967_910_922_543, 0.035_242_103_490_996_101_359),
    (21.211_636_629_879_258_959, 0.030_021_070_103_054_672_675),
    (24.352_471_530_749_302_737, 0.026_147_391_495_308_088_59),
    (27.493_479_132_040_254_796, 0.023_159_121_824_691_392_265),
    (30.634_606_468_431_975_118, 0.020_783_829_122_267_857_604),
    (33.775_820_213_573_568_684, 0.018_850_450_669_317_667_816),
    (36.917_098_353_664_043_98, 0.017_246_157_569_665_008_3),
    (40.058_425_764_628_239_295, 0.015_893_518_105_923_597_803),
    (43.199_791_713_176_730_358, 0.014_737_626_096_472_189_59),
    (46.341_188_371_661_814_019, 0.013_738_465_145_387_117_918),
    (49.482_609_897_397_817_174, 0.012_866_181_737_615_132_879),
    (52.624_051_841_114_996_029, 0.012_098_051_548_626_797_547),
    (55.765_510_755_019_979_312, 0.011_416_471_224_491_608_517),
    (58.906_983_926_080_942_133, 0.010_807_592_791_180_204_012),
    (62.048_469_190_227_169_883, 0.010_260_372_926_280_762_811),
];

/// The k-th positive zero `j_{0,k}` of `J_0` and `J_1(j_{0,k})^2`, k >= 1.
///
/// For k > 20, McMahon's expansion (DLMF 10.21.19) in `beta = (k - 1/4) pi`:
/// `j = beta + 1/(8 beta) - 31/(384 beta^3) + 3779/(15360 beta^5)
///      - 6277237/(3440640 beta^7) + 2092163573/(82575360 beta^9)`,
/// and `J_1(j)^2 = (2/(pi beta)) [1 + t^2 (-7/48 + t (151/160 + t (-172913/16128
///      + t (461797/2304 - t 171497088497/30412800))))]`, `t = 1/beta^2`
/// (DLMF 10.17.3 evaluated at McMahon's zero).
#[inline]
pub fn j0_zero_and_j1_squared(k: usize) -> (f64, f64) {
    match TABLE.get(k.wrapping_sub(1)) {
        Some(&pair) => pair,
        None => mcmahon(k),
    }
}

/// Number of tabulated zeros; [`mcmahon`] serves k above it.
pub const TABULATED: usize = 20;

/// McMahon's expansions for `j_{0,k}` and `J_1(j_{0,k})^2`, accurate for k > 20.
#[inline(always)]
pub fn mcmahon(k: usize) -> (f64, f64) {
    let beta = (k as f64 - 0.25) * std::f64::consts::PI;
    let inv_beta = 1.0 / beta;
    let t = inv_beta * inv_beta;
    let zero = beta
        + (0.125
            + t * (-31.0 / 384.0
                + t * (3779.0 / 15360.0
                    + t * (-6_277_237.0 / 3_440_640.0 + t * (2_092_163_573.0 / 82_575_360.0)))))
            * inv_beta;
    let series = 1.0
        + t * t
            * (-7.0 / 48.0
                + t * (151.0 / 160.0
                    + t * (-172_913.0 / 16_128.0
                        + t * (461_797.0 / 2304.0 - t * (171_497_088_497.0 / 30_412_800.0)))));
    let j1_squared = std::f64::consts::FRAC_2_PI * inv_beta * series;
    (zero, j1_squared)
}
