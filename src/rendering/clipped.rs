//! A cone of directions about an axis, cut by the receiver's horizon, as
//! pieces on which an integrand that vanishes below the horizon is smooth:
//! the split of a Phong lobe at the horizon (splitting at the kinks the
//! scene can compute).
//!
//! About the axis `r` (the lobe's mirror direction) with the unit `t`
//! toward the normal `n` in the plane of `r` and `n`, a direction at angle
//! `alpha` from `r` and azimuth `phi` from `t` is `w = cos alpha r + sin
//! alpha (cos phi t + sin phi s)`, and `n . w = cos alpha (n . r) + sin
//! alpha cos phi (n . t)`. It is above the horizon for every `phi` while
//! `alpha < e`, `e = atan2(n . r, n . t)` the elevation of `r`; beyond, for
//! `|phi| < phi_0(alpha) = acos(-cot alpha (n . r)/(n . t))`. So
//!
//! - piece 1: `alpha` in `[0, min(e, alpha_max)]`, the whole circle;
//! - piece 2: `alpha` in `[e, alpha_max]`, `phi` in `[-phi_0, phi_0]`,
//!
//! each uniform in `1 - cos alpha` and in `phi`: the integrand `f(w) cos
//! theta` falls to 0 at the horizon (the ends of the `phi` range) instead
//! of jumping or kinking inside the domain. The Phong lobe `cos^n alpha`
//! about `r` under a sky, its mirror direction 0.3 degrees above the
//! horizon (`n` = 1e4), over the BRDF's own map kept a kink and converged to
//! 1.3e-8 while its successive values differed by 2.4e-10.

use std::f64::consts::PI;

use crate::domain::{Domain, Vec3};
use crate::error::QuadError;

/// One piece of a cone about `r` cut by the horizon of `n` (module text).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClippedCone {
    r: Vec3,
    t: Vec3,
    s: Vec3,
    /// `n . r` and `n . t`.
    nr: f64,
    nt: f64,
    /// `1 - cos alpha` at the piece's ends.
    k_lo: f64,
    k_hi: f64,
    /// True for the whole circle of azimuths (piece 1).
    full: bool,
}

/// The pieces of the cone `alpha <= alpha_max` (`1 - cos alpha_max =
/// one_minus_cos_max` in `(0, 1]`) about the unit `axis` above the horizon of
/// the unit `normal` (`axis . normal > 0`).
pub fn pieces(
    axis: Vec3,
    normal: Vec3,
    one_minus_cos_max: f64,
) -> Result<Vec<ClippedCone>, QuadError> {
    let nr = normal.dot(&axis);
    if !(nr > 0.0 && nr <= 1.0 + 1e-12) {
        return Err(QuadError::invalid(
            "axis",
            format!("{:?}", axis.as_slice()),
            "a unit axis above the horizon of a unit normal",
        ));
    }
    if !(one_minus_cos_max > 0.0 && one_minus_cos_max <= 1.0) {
        return Err(QuadError::invalid(
            "one_minus_cos_max",
            one_minus_cos_max,
            "1 - cos alpha_max in (0, 1]",
        ));
    }
    // t: the normal's part across the axis (any perpendicular when they
    // coincide), s completing the frame.
    let across = normal - axis * nr;
    let t = if across.norm() > 1e-300 {
        across.normalize()
    } else {
        crate::domain::Frame::from_normal(axis)?.s
    };
    let s = axis.cross(&t);
    let nt = normal.dot(&t).max(0.0);
    // 1 - cos e, e = atan2(nr, nt): cos e = nt / hypot (as 1 - cos without
    // cancellation: (1 - cos^2) / (1 + cos)).
    let h = nr.hypot(nt);
    let cos_e = nt / h;
    let k_e = (nr / h).powi(2) / (1.0 + cos_e);
    let cone = |k_lo: f64, k_hi: f64, full: bool| ClippedCone {
        r: axis,
        t,
        s,
        nr,
        nt,
        k_lo,
        k_hi,
        full,
    };
    let mut out = vec![cone(0.0, k_e.min(one_minus_cos_max), true)];
    if one_minus_cos_max > k_e {
        out.push(cone(k_e, one_minus_cos_max, false));
    }
    Ok(out)
}

impl ClippedCone {
    /// `phi_0` at `1 - cos alpha = k`: the half-range of azimuths above the
    /// horizon.
    fn half_range(&self, k: f64) -> f64 {
        if self.full {
            return PI;
        }
        let cos_a = 1.0 - k;
        let sin_a = (k * (2.0 - k)).max(0.0).sqrt();
        if sin_a == 0.0 || self.nt == 0.0 {
            return PI;
        }
        (-(cos_a * self.nr) / (sin_a * self.nt))
            .clamp(-1.0, 1.0)
            .acos()
    }
}

impl Domain<2> for ClippedCone {
    type Point = Vec3;

    /// `1 - cos alpha = k_lo + u_1 (k_hi - k_lo)`, `phi = phi_0 (2 u_2 - 1)`
    /// (`2 pi u_2` for the whole circle), `|J| = (k_hi - k_lo) 2 phi_0`.
    fn map(&self, u: [f64; 2]) -> (Vec3, f64) {
        let k = self.k_lo + u[0] * (self.k_hi - self.k_lo);
        let half = self.half_range(k);
        let phi = if self.full {
            2.0 * PI * u[1]
        } else {
            half * (2.0 * u[1] - 1.0)
        };
        let cos_a = 1.0 - k;
        let sin_a = (k * (2.0 - k)).max(0.0).sqrt();
        let (sin_p, cos_p) = phi.sin_cos();
        let w = self.r * cos_a + (self.t * cos_p + self.s * sin_p) * sin_a;
        (w, (self.k_hi - self.k_lo) * 2.0 * half)
    }

    /// `u` of a direction of the piece, or `None` outside it.
    fn invert(&self, w: &Vec3) -> Option<[f64; 2]> {
        let cos_a = w.dot(&self.r);
        let (x, y) = (w.dot(&self.t), w.dot(&self.s));
        let k = (x * x + y * y) / (1.0 + cos_a).max(f64::MIN_POSITIVE);
        let span = self.k_hi - self.k_lo;
        let u1 = (k - self.k_lo) / span;
        let phi = y.atan2(x);
        let half = self.half_range(k);
        let u2 = if self.full {
            phi.rem_euclid(2.0 * PI) / (2.0 * PI)
        } else {
            (phi / half + 1.0) / 2.0
        };
        let inside = |v: f64| (-1e-9..=1.0 + 1e-9).contains(&v);
        (inside(u1) && inside(u2)).then_some([u1.clamp(0.0, 1.0), u2.clamp(0.0, 1.0)])
    }

    /// Solid angle: `int 2 phi_0 d(1 - cos alpha)` (exact for the whole
    /// circle; for a clipped piece by 64-point Gauss–Legendre in `t`, `k =
    /// k_lo + (k_hi - k_lo) t^2`, which takes out the square root with which
    /// `phi_0` leaves `pi` at the piece's start; 1e-10 relative with the
    /// mirror direction 0.003 rad above the horizon).
    fn measure(&self) -> f64 {
        let span = self.k_hi - self.k_lo;
        if self.full {
            return 2.0 * PI * span;
        }
        crate::quadrature::gauss_legendre::table(64).map_or(f64::NAN, |table| {
            table
                .x()
                .iter()
                .zip(table.w())
                .map(|(x, w)| {
                    let t = (x + 1.0) / 2.0;
                    // (w / 2) 2 phi_0 (2 span t) over t in [0, 1].
                    w * self.half_range(self.k_lo + span * t * t) * 2.0 * span * t
                })
                .sum::<f64>()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The pieces of the hemisphere about an axis at elevation `e` cover the
    /// lune it shares with the upper hemisphere, `2 (pi - beta)` for poles
    /// `beta = pi/2 - e` apart; every mapped direction is above the horizon,
    /// and `invert` undoes `map`.
    #[test]
    fn the_pieces_cover_the_lune_above_the_horizon_and_invert() -> Result<(), QuadError> {
        let normal = Vec3::z();
        for e in [0.003_f64, 0.3, 1.2] {
            let axis = Vec3::new(e.cos(), 0.0, e.sin());
            let pieces = pieces(axis, normal, 1.0)?;
            let total: f64 = pieces.iter().map(|p| p.measure()).sum();
            let want = 2.0 * (PI - (PI / 2.0 - e));
            assert!((total - want).abs() < 1e-9 * want, "{e}: {total} vs {want}");
            for p in &pieces {
                for u in [[0.1, 0.2], [0.5, 0.5], [0.9, 0.97]] {
                    let (w, jacobian) = p.map(u);
                    assert!(w.z >= -1e-15 && jacobian > 0.0, "{e} {u:?}: {w:?}");
                    let back = p.invert(&w).ok_or(QuadError::invalid("u", 0, "inverted"))?;
                    assert!((back[0] - u[0]).abs() < 1e-9 && (back[1] - u[1]).abs() < 1e-9);
                }
            }
        }
        Ok(())
    }
}
