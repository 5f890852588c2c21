//! Zeros of the Bessel function `J_0` and the weight factor
//! `p_k = (pi/2) j_{0,k} J_1(j_{0,k})^2`, the two Bessel quantities Bogaert's
//! expansion of the Gauss–Legendre rule needs. (`p_k -> 1` as k grows; keeping
//! the product rather than `J_1^2` alone saves roundings in the weight.)
//!
//! The first 20 values are tabulated (mpmath at 40 digits: `besseljzero(0, k)`,
//! `pi/2 * z * besselj(1, z)**2`); beyond them McMahon's expansions are accurate
//! to better than 1e-18 relative (checked against mpmath for k = 21..100 when
//! this table was made).

use super::lanes::{Lanes, quick_two_sum, two_prod};

/// `(j_{0,k}` as `hi + lo`, `p_k - 1)` for k = 1..=20, where
/// `p_k = (pi/2) j_{0,k} J_1(j_{0,k})^2`; mpmath at 50 digits, each part
/// correctly rounded.
const TABLE: [(f64, f64, f64); 20] = [
    (
        2.404825557695773,
        -1.176691651530894e-16,
        0.018087218694297996,
    ),
    (
        5.520078110286311,
        8.088597146146722e-17,
        0.00392013621674922,
    ),
    (
        8.653727912911013,
        -2.92812607320779e-16,
        0.001636551843562515,
    ),
    (
        11.791534439014281,
        2.812956912778735e-16,
        0.0008892796349325885,
    ),
    (
        14.930917708487787,
        -7.070514505983074e-16,
        0.000556868684819165,
    ),
    (
        18.071063967910924,
        -9.658048089426209e-16,
        0.0003809718021230442,
    ),
    (
        21.21163662987926,
        4.947077428784068e-16,
        0.0002768652596050394,
    ),
    (
        24.352471530749302,
        9.169067133951066e-16,
        0.00021022693776474386,
    ),
    (
        27.493479132040253,
        1.6191941793302084e-15,
        0.00016502823272164556,
    ),
    (
        30.634606468431976,
        -5.390359852115135e-16,
        0.00013297372137155157,
    ),
    (
        33.77582021357357,
        1.454224241250595e-15,
        0.0001094222755141307,
    ),
    (
        36.917098353664045,
        -9.276489358569364e-16,
        9.16133256630134e-05,
    ),
    (
        40.05842576462824,
        -2.6782651477149736e-16,
        7.782167548719328e-05,
    ),
    (
        43.19979171317673,
        8.55713303876733e-16,
        6.692432209045039e-05,
    ),
    (
        46.341188371661815,
        -9.07797413846536e-16,
        5.816481661508719e-05,
    ),
    (
        49.482609897397815,
        2.382582551864974e-15,
        5.101855968357026e-05,
    ),
    (
        52.624051841115,
        -1.7558469541662502e-15,
        4.511249113423512e-05,
    ),
    (
        55.76551075501998,
        -2.2474605782970157e-15,
        4.017545054632166e-05,
    ),
    (
        58.90698392608094,
        1.8824761533828545e-15,
        3.6006519266516735e-05,
    ),
    (
        62.048469190227166,
        3.5462261037501757e-15,
        3.2454268447740936e-05,
    ),
];

/// `alpha_k = j_{0,k} / (n + 1/2)` as `hi + lo` (double-double) and `p_k - 1`,
/// where `p_k = (pi/2) j_{0,k} J_1(j_{0,k})^2`, k >= 1.
#[inline]
pub fn alpha_and_weight_factor(k: usize, n: usize) -> (f64, f64, f64) {
    match TABLE.get(k.wrapping_sub(1)) {
        Some(&(hi, lo, p)) => {
            let (a_hi, a_lo) = div_dd(Lanes([hi]), Lanes([lo]), n as f64 + 0.5);
            (a_hi.0[0], a_lo.0[0], p)
        }
        None => {
            let (a_hi, a_lo, p) = mcmahon(Lanes([k as f64]), n);
            (a_hi.0[0], a_lo.0[0], p.0[0])
        }
    }
}

/// `(hi + lo) / m` as a double-double, for `|lo| <= ulp(hi)`, with the
/// reciprocal `1/m` (hoisted out of node loops) in place of two divisions:
/// `q1 = hi (1/m)` is within two ulps of the quotient; with `q1 m = p + e`
/// exactly (Dekker), the remainder `hi - q1 m = (hi - p) - e` is formed with
/// `hi - p` exact (Sterbenz: `p` is within a few ulps of `hi`), and
/// `q2 = ((hi - p) - e + lo) (1/m)` carries the rest to a relative error of
/// about `2^-52 |q2| <= 2^-103 |q1|`, as a second division would.
#[inline(always)]
fn div_dd<const L: usize>(hi: Lanes<L>, lo: Lanes<L>, m: f64) -> (Lanes<L>, Lanes<L>) {
    let inv_m = 1.0 / m;
    let q1 = hi * inv_m;
    let (p, e) = two_prod(q1, m);
    let q2 = (((hi - p) - e) + lo) * inv_m;
    quick_two_sum(q1, q2)
}

/// Number of tabulated zeros; [`mcmahon`] serves k above it.
pub const TABULATED: usize = 20;

/// McMahon's expansions (DLMF 10.21.19) for k > 20, lane-wise (`k` as a float):
/// `alpha_k = j_{0,k} / (n + 1/2)` as a double-double `(hi, lo)` and `p_k - 1`.
/// With `beta = (k - 1/4) pi` (formed exactly as a double-double) and
/// `t = 1/beta^2`:
///
/// `j_{0,k} = beta (1 + t/8 - 31 t^2/384 + 3779 t^3/15360 - 6277237 t^4/3440640
///            + 2092163573 t^5/82575360)`,
///
/// and, multiplying that by `J_1(j)^2 = (2/(pi beta)) (1 - 7 t^2/48 + 151 t^3/160
/// - 172913 t^4/16128 + 461797 t^5/2304 - ...)` (DLMF 10.17.3 at McMahon's zero),
///
/// `p_k = (pi/2) j J_1(j)^2 = 1 + t/8 - 29 t^2/128 + 3599 t^3/3072
///        - 6102707 t^4/491520 + 2058116637 t^5/9175040`.
///
/// Both are accurate to 1e-18 relative or better for k > 20 (t < 2.4e-4).
#[inline(always)]
pub fn mcmahon<const L: usize>(k: Lanes<L>, n: usize) -> (Lanes<L>, Lanes<L>, Lanes<L>) {
    /// `pi - PI`, the tail of pi beyond f64.
    const PI_LO: f64 = 1.224_646_799_147_353_2e-16;
    let quarter_off = k - 0.25;
    let (beta, beta_lo) = two_prod(quarter_off, std::f64::consts::PI);
    let beta_lo = beta_lo + quarter_off * PI_LO;
    let inv_beta = Lanes::splat(1.0) / beta;
    let t = inv_beta * inv_beta;
    // j - beta, small: its own rounding is far below an ulp of j.
    let zero_tail = (0.125
        + t * (-31.0 / 384.0
            + t * (3779.0 / 15360.0
                + t * (-6_277_237.0 / 3_440_640.0 + t * (2_092_163_573.0 / 82_575_360.0)))))
        * inv_beta;
    let (alpha, alpha_lo) = div_dd(beta, beta_lo + zero_tail, n as f64 + 0.5);
    let weight_factor_minus_one = t
        * (0.125
            + t * (-29.0 / 128.0
                + t * (3599.0 / 3072.0
                    + t * (-6_102_707.0 / 491_520.0 + t * (2_058_116_637.0 / 9_175_040.0)))));
    (alpha, alpha_lo, weight_factor_minus_one)
}
