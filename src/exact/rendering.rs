//! Closed forms of the rendering equation's integrals (docs/EQUATIONS.md,
//! `R-*`): form factors and irradiance from Lambertian emitters, cosine-power
//! lobe integrals and the white furnace.
//!
//! A Lambertian emitter of radiance `L` seen from a point with normal `n`
//! gives the irradiance `E = L int_A cos(theta) cos(theta') / r^2 dA` (R-A
//! without the BRDF, the geometry term `g` of R-3P integrated over the
//! emitter), which is `pi L F` with `F` the point-to-surface form factor.
//! The form factors here are those of the radiative heat-transfer
//! literature: J. R. Howell, M. P. Mengüç, K. Daun, R. Siegel, *Thermal
//! Radiation Heat Transfer*, 7th ed., CRC Press 2021, and Howell's online
//! catalogue of configuration factors (configurations named "B-n"
//! differential-to-finite, "C-n" finite-to-finite); each formula below is
//! also derived in its doc comment, and the tests check it against
//! [`polygon_form_factor`] (Lambert's contour formula), summation and
//! reciprocity rules and quadrature.
//!
//! ```
//! use lightquad::exact::rendering::{disk_coaxial, polygon_form_factor, rectangle_corner};
//! use lightquad::domain::Vec3;
//!
//! // A point 1 below the corner of a 2 x 3 rectangle: Howell B-3 and
//! // Lambert's contour formula over the same rectangle agree.
//! let f = rectangle_corner(2.0, 3.0, 1.0)?;
//! let corners = [[0.0, 0.0, 1.0], [2.0, 0.0, 1.0], [2.0, 3.0, 1.0], [0.0, 3.0, 1.0]]
//!     .map(|[x, y, z]| Vec3::new(x, y, z));
//! let g = polygon_form_factor(Vec3::zeros(), Vec3::z(), &corners)?;
//! assert!((f - g).abs() < 1e-15);
//! // A disk of radius 1 at height 1 above the point: F = R^2 / (h^2 + R^2) = 1/2.
//! assert!((disk_coaxial(1.0, 1.0)? - 0.5).abs() < 1e-16);
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use std::f64::consts::PI;

use crate::domain::Vec3;
use crate::error::QuadError;

/// `x` if it is finite and positive, else the error naming `name`.
fn positive(name: &str, x: f64) -> Result<f64, QuadError> {
    if x.is_finite() && x > 0.0 {
        Ok(x)
    } else {
        Err(QuadError::invalid(name, x, "a finite number > 0"))
    }
}

/// R-A, form factor from a differential area to a parallel coaxial disk of
/// radius `r` at height `h` above it (Howell's catalogue, element to a
/// parallel coaxial disk):
///
/// `F = R^2 / (h^2 + R^2)`.
///
/// Derivation: rings of radius `rho` give `cos = cos' = h / s`, `s^2 = h^2 +
/// rho^2`, so `F = (1/pi) int_0^R h^2 / s^4 2 pi rho d rho = R^2 / (h^2 +
/// R^2)`. Written as `1 / (1 + (h/R)^2)`, it keeps full precision for a
/// receiver at any distance.
pub fn disk_coaxial(h: f64, r: f64) -> Result<f64, QuadError> {
    let (h, r) = (positive("h", h)?, positive("r", r)?);
    let q = h / r;
    Ok(1.0 / (1.0 + q * q))
}

/// R-A, form factor from a differential area to a parallel `a x b`
/// rectangle at distance `c`, the area's normal through one corner (Howell
/// B-3):
///
/// `F = 1/(2 pi) [ A/sqrt(1+A^2) atan(B/sqrt(1+A^2)) + B/sqrt(1+B^2) atan(A/sqrt(1+B^2)) ]`,
/// `A = a/c`, `B = b/c`.
///
/// It is Lambert's contour formula ([`polygon_form_factor`]) over the
/// rectangle's four edges: the two edges through the corner above the
/// point lie in planes through the normal and add nothing; each far edge
/// subtends `atan(B / sqrt(1 + A^2))` (resp. `A`, `B` swapped) in a plane
/// whose normal makes `cos = A / sqrt(1 + A^2)` with the area's normal.
pub fn rectangle_corner(a: f64, b: f64, c: f64) -> Result<f64, QuadError> {
    let (a, b, c) = (positive("a", a)?, positive("b", b)?, positive("c", c)?);
    let (x, y) = (a / c, b / c);
    let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    Ok(((x / sx) * (y / sx).atan() + (y / sy) * (x / sy).atan()) / (2.0 * PI))
}

/// R-A, form factor from a differential area to a rectangle perpendicular
/// to it: the rectangle stands on the line at distance `d` from the area in
/// the area's plane, facing it, `a` wide along that line from the foot of
/// the area's perpendicular and `b` high (Howell's B-series, element on the
/// line through a rectangle's corner, planes at 90 degrees):
///
/// `F = 1/(2 pi) [ atan X - atan(X / sqrt(1 + Y^2)) / sqrt(1 + Y^2) ]`,
/// `X = a/d`, `Y = b/d`.
///
/// Derivation by Lambert's contour formula with the point at the origin,
/// normal `z`, corners `(0,d,0), (a,d,0), (a,d,b), (0,d,b)`: the bottom edge
/// lies in the area's plane (its plane's normal is `z`: weight 1, angle
/// `atan X`); the top edge's plane has normal `(0, -b, d)/sqrt(b^2 + d^2)`
/// (weight `1/sqrt(1 + Y^2)`, angle `atan(X / sqrt(1 + Y^2))`), with the
/// opposite orientation; the two vertical edges' planes contain `z`.
///
/// A short rectangle (`Y` small) makes the bracket cancel (`F = O(Y^2)`, its
/// terms `O(1)`); it is evaluated as `atan(X (s - 1) / (s + X^2)) + atan(X / s)
/// (s - 1) / s` with `s = sqrt(1 + Y^2)` and `s - 1 = Y^2 / (s + 1)`
/// (`atan u - atan v = atan((u - v) / (1 + u v))`), which does not.
pub fn rectangle_perpendicular(a: f64, b: f64, d: f64) -> Result<f64, QuadError> {
    let (a, b, d) = (positive("a", a)?, positive("b", b)?, positive("d", d)?);
    let (x, y) = (a / d, b / d);
    let s = (1.0 + y * y).sqrt();
    let s_minus_1 = y * y / (s + 1.0);
    let difference = (x * s_minus_1 / (s + x * x)).atan();
    Ok((difference + (x / s).atan() * s_minus_1 / s) / (2.0 * PI))
}

/// R-A, form factor between two directly opposed identical parallel `a x b`
/// rectangles at distance `c` (Howell C-11):
///
/// ```text
/// F = 2/(pi X Y) { ln sqrt[(1+X^2)(1+Y^2)/(1+X^2+Y^2)] + X sqrt(1+Y^2) atan(X/sqrt(1+Y^2))
///                  + Y sqrt(1+X^2) atan(Y/sqrt(1+X^2)) - X atan X - Y atan Y },   X = a/c, Y = b/c.
/// ```
///
/// The logarithm is taken as `ln_1p` of its small part. For distant plates
/// (`X`, `Y` small, `F ~ X Y / pi`) the bracket is `O(X^2 Y^2)` while its
/// terms are `O(X^2 + Y^2)`: the relative rounding error grows as
/// `eps / min(X, Y)^2` (about 1e-10 at `X = Y = 1e-3`).
pub fn parallel_rectangles(a: f64, b: f64, c: f64) -> Result<f64, QuadError> {
    let (a, b, c) = (positive("a", a)?, positive("b", b)?, positive("c", c)?);
    let (x, y) = (a / c, b / c);
    let (x2, y2) = (x * x, y * y);
    let (sx, sy) = ((1.0 + x2).sqrt(), (1.0 + y2).sqrt());
    // (1+X^2)(1+Y^2)/(1+X^2+Y^2) = 1 + X^2 Y^2/(1+X^2+Y^2).
    let log = 0.5 * (x2 * y2 / (1.0 + x2 + y2)).ln_1p();
    let bracket =
        log + x * sy * (x / sy).atan() + y * sx * (y / sx).atan() - x * x.atan() - y * y.atan();
    Ok(2.0 / (PI * x * y) * bracket)
}

/// R-A, form factor from an `l x w` rectangle to an `l x h` rectangle
/// perpendicular to it along their common edge of length `l` (Howell C-14):
///
/// ```text
/// F = 1/(pi W) { W atan(1/W) + H atan(1/H) - sqrt(H^2+W^2) atan(1/sqrt(H^2+W^2))
///     + 1/4 ln( [(1+W^2)(1+H^2)/(1+W^2+H^2)]
///               [W^2(1+W^2+H^2)/((1+W^2)(W^2+H^2))]^(W^2)
///               [H^2(1+H^2+W^2)/((1+H^2)(H^2+W^2))]^(H^2) ) },   H = h/l, W = w/l.
/// ```
///
/// The logarithm is summed term by term (the powers overflow for large
/// `W`, `H`), each as `ln_1p` of its exact distance from 1:
/// `(1+W^2)(1+H^2)/(1+W^2+H^2) = 1 + W^2 H^2/(1+W^2+H^2)`,
/// `W^2(1+W^2+H^2)/((1+W^2)(W^2+H^2)) = 1 - H^2/((1+W^2)(W^2+H^2))`, and
/// the same with `W`, `H` swapped: a tall face multiplies a logarithm near
/// 0 by `H^2`, which the plain `ln` of the ratio got wrong by `H^2 eps`.
pub fn perpendicular_rectangles(l: f64, w: f64, h: f64) -> Result<f64, QuadError> {
    let (l, w, h) = (positive("l", l)?, positive("w", w)?, positive("h", h)?);
    let (ww, hh) = (w / l, h / l);
    let (w2, h2) = (ww * ww, hh * hh);
    let s2 = w2 + h2;
    let s = s2.sqrt();
    let log = (w2 * h2 / (1.0 + s2)).ln_1p()
        + w2 * (-h2 / ((1.0 + w2) * s2)).ln_1p()
        + h2 * (-w2 / ((1.0 + h2) * s2)).ln_1p();
    let bracket =
        ww * (1.0 / ww).atan() + hh * (1.0 / hh).atan() - s * (1.0 / s).atan() + 0.25 * log;
    Ok(bracket / (PI * ww))
}

/// R-A, form factor from a differential area at `p` with unit normal `n` to
/// a planar polygon (its corners in order, either orientation), by Lambert's
/// contour formula (J. H. Lambert, *Photometria*, 1760; J. Arvo, "Applications
/// of irradiance tensors to the simulation of non-Lambertian phenomena",
/// SIGGRAPH 1995):
///
/// `F = 1/(2 pi) | sum_i Theta_i (n . Gamma_i) |`,
///
/// with `Theta_i` the angle the edge `v_i v_(i+1)` subtends at `p` and
/// `Gamma_i` the unit normal of the plane through `p` and the edge. The
/// part of the polygon below the tangent plane of `p` is clipped off first
/// (Sutherland–Hodgman), so a polygon partly below the horizon is exact too.
/// Angles are `atan2(|a x b|, a . b)`, accurate for edges seen at any angle.
pub fn polygon_form_factor(p: Vec3, n: Vec3, corners: &[Vec3]) -> Result<f64, QuadError> {
    lambert(p, n, corners, None)
}

/// Lambert's contour formula at `p` (module functions above): the checks,
/// the clip at `p`'s horizon and the sum, with each term's limit along
/// `toward` where given ([`contour_sum`]).
fn lambert(p: Vec3, n: Vec3, corners: &[Vec3], toward: Option<Vec3>) -> Result<f64, QuadError> {
    if corners.len() < 3 {
        return Err(QuadError::invalid(
            "corners",
            corners.len(),
            "a polygon of at least 3 corners",
        ));
    }
    let n_len = n.norm();
    if !(n_len.is_finite() && n_len > 0.0) {
        return Err(QuadError::invalid(
            "n",
            format!("{n:?}"),
            "a finite non-zero normal",
        ));
    }
    let n = n / n_len;
    if let Some(c) = corners
        .iter()
        .chain([&p])
        .find(|c| !c.iter().all(|x| x.is_finite()))
    {
        return Err(QuadError::invalid(
            "corners",
            format!("{c:?}"),
            "finite points",
        ));
    }
    // Corners relative to p, clipped to the upper half-space n . v >= 0.
    let rel: Vec<Vec3> = corners.iter().map(|c| c - p).collect();
    let mut clipped = Vec::with_capacity(rel.len() + 2);
    for (i, &a) in rel.iter().enumerate() {
        let b = rel[(i + 1) % rel.len()];
        let (ha, hb) = (n.dot(&a), n.dot(&b));
        if ha >= 0.0 {
            clipped.push(a);
        }
        if (ha >= 0.0) != (hb >= 0.0) {
            // The edge crosses the tangent plane where n . (a + t (b - a)) = 0.
            let t = ha / (ha - hb);
            let mut x = a + (b - a) * t;
            x -= n * n.dot(&x);
            clipped.push(x);
        }
    }
    Ok(contour_sum(&clipped, n, toward).abs() / (2.0 * PI))
}

/// Lambert's sum `sum_i Theta_i (n . Gamma_i)` over the polygon of corners
/// `rel` (relative to the point). With `toward = Some(d)`, the point lies
/// in the polygon's plane and each term is its limit at `p + t d`,
/// `t -> 0+`: a corner at the point stands for `-d`, and an edge through
/// the point (its ends on opposite sides) subtends `pi` in the plane
/// through it and `d`, `Gamma = unit((b - a) x d)`.
fn contour_sum(rel: &[Vec3], n: Vec3, toward: Option<Vec3>) -> f64 {
    let tiny = |v: &Vec3, scale: f64| v.norm() <= 1e-12 * scale;
    let scale = rel.iter().map(|v| v.norm()).fold(0.0, f64::max);
    let mut sum = 0.0;
    for (i, &a0) in rel.iter().enumerate() {
        let b0 = rel[(i + 1) % rel.len()];
        let (mut a, mut b) = (a0, b0);
        if let Some(d) = toward {
            if tiny(&a, scale) {
                a = -d;
            }
            if tiny(&b, scale) {
                b = -d;
            }
            let c = a.cross(&b);
            if c.norm() <= 1e-12 * a.norm() * b.norm() && a.dot(&b) < 0.0 {
                let g = (b - a).cross(&d);
                let len = g.norm();
                if len > 0.0 {
                    sum += PI * n.dot(&g) / len;
                }
                continue;
            }
        }
        let c = a.cross(&b);
        let len = c.norm();
        if len > 0.0 {
            sum += len.atan2(a.dot(&b)) * n.dot(&c) / len;
        }
    }
    sum
}

/// R-A, [`polygon_form_factor`] at a point `p` in the polygon's own plane,
/// as its limit from the side the direction `d` leads to: `lim F(p + t d)`
/// for `t -> 0+` (`d` not in that plane). A receiver touching a light along
/// an edge (two faces of a box) has its points on the shared edge here,
/// where `F` at the point itself is 0/0 and the limit (1/2 at right angles,
/// away from the edge's ends) is the value that keeps the integrand
/// continuous up to the receiver's edge. Lambert's sum with each term
/// taken to its limit; the part below `p`'s horizon is clipped first, as
/// in [`polygon_form_factor`]. The polygon must be convex or its corners
/// in order; `d` is normalised.
pub fn polygon_form_factor_toward(
    p: Vec3,
    n: Vec3,
    corners: &[Vec3],
    d: Vec3,
) -> Result<f64, QuadError> {
    let d_len = d.norm();
    if !(d_len.is_finite() && d_len > 0.0) {
        return Err(QuadError::invalid(
            "d",
            format!("{d:?}"),
            "a finite non-zero direction",
        ));
    }
    lambert(p, n, corners, Some(d / d_len))
}

/// R-H, irradiance per unit radiance from a uniform spherical light that
/// subtends a cone of half-angle `alpha` whose axis makes the angle `omega`
/// with the receiver's normal, `E / L = int_cap max(0, cos theta) d omega`,
/// the cap partly below the horizon included (J. Snyder, "Area light
/// sources for real-time graphics", Microsoft Research MSR-TR-96-11, 1996),
/// given as `cos omega` and `sin alpha`:
///
/// - all above the horizon (`cos omega >= sin alpha`): `pi sin^2 alpha cos omega`;
/// - all below (`cos omega <= -sin alpha`): 0;
/// - across it, with `x = cot alpha`, `y = -x cot omega`:
///   `E / L = (cos omega acos y - x sin omega sqrt(1 - y^2)) sin^2 alpha
///   + atan(sin omega sqrt(1 - y^2) / x)`.
///
/// At `omega = pi/2` (the light centred on the horizon) this is
/// `alpha - sin alpha cos alpha`, half the cap's projected area; at
/// `cos omega = sin alpha` it meets the first case.
pub fn spherical_cap_irradiance(cos_omega: f64, sin_alpha: f64) -> Result<f64, QuadError> {
    if !(cos_omega.is_finite() && (-1.0..=1.0).contains(&cos_omega)) {
        return Err(QuadError::invalid(
            "cos_omega",
            cos_omega,
            "a number in [-1, 1]",
        ));
    }
    if !(sin_alpha.is_finite() && sin_alpha > 0.0 && sin_alpha <= 1.0) {
        return Err(QuadError::invalid(
            "sin_alpha",
            sin_alpha,
            "a number in (0, 1]",
        ));
    }
    let s2 = sin_alpha * sin_alpha;
    if cos_omega >= sin_alpha {
        return Ok(PI * s2 * cos_omega);
    }
    if cos_omega <= -sin_alpha {
        return Ok(0.0);
    }
    let sin_omega = (1.0 - cos_omega * cos_omega).sqrt();
    let x = (1.0 - s2).sqrt() / sin_alpha;
    let y = (-x * cos_omega / sin_omega).clamp(-1.0, 1.0);
    let root = (1.0 - y * y).sqrt();
    let e = (cos_omega * y.acos() - x * sin_omega * root) * s2 + (sin_omega * root).atan2(x);
    Ok(e.max(0.0))
}

/// R-H, directional albedo of the documents' unnormalised Phong lobe at
/// normal incidence: the reflected direction is the normal, so
/// `int_H cos^n(theta) cos(theta) d omega = 2 pi / (n + 2)`.
pub fn phong_albedo_normal(n: f64) -> Result<f64, QuadError> {
    if !(n.is_finite() && n >= 0.0) {
        return Err(QuadError::invalid("n", n, "a finite exponent >= 0"));
    }
    Ok(2.0 * PI / (n + 2.0))
}

/// R-H, the clamped-cosine product over the sphere for two unit axes at the
/// angle `gamma`: `int_S2 max(0, a . w) max(0, b . w) d w = 2/3 [(pi - gamma)
/// cos gamma + sin gamma]` (the Phong lobe of exponent 1 against the cosine
/// of a receiver whose normal is `b`; 2 pi / 3 at `gamma = 0`, 0 at `pi`).
///
/// Derivation: in coordinates where `a` is the pole, the lune where both
/// cosines are positive integrates in closed form over the azimuth; the
/// result depends on `gamma` only.
pub fn clamped_cosine_product(gamma: f64) -> Result<f64, QuadError> {
    if !(gamma.is_finite() && (0.0..=PI).contains(&gamma)) {
        return Err(QuadError::invalid("gamma", gamma, "an angle in [0, pi]"));
    }
    Ok(2.0 / 3.0 * ((PI - gamma) * gamma.cos() + gamma.sin()))
}

/// R-H, the white furnace: a closed Lambertian enclosure of albedo `rho`
/// whose walls emit `le` has the radiance `L = le + rho L`, so `L = le / (1
/// - rho)` everywhere, the sum of the Neumann series `le sum_k rho^k`.
pub fn furnace(le: f64, rho: f64) -> Result<f64, QuadError> {
    if !(le.is_finite() && le >= 0.0) {
        return Err(QuadError::invalid("le", le, "a finite radiance >= 0"));
    }
    if !(rho.is_finite() && (0.0..1.0).contains(&rho)) {
        return Err(QuadError::invalid("rho", rho, "an albedo in [0, 1)"));
    }
    Ok(le / (1.0 - rho))
}

/// R-H, the white furnace truncated after `bounces` bounces:
/// `le sum_{k=0}^{bounces} rho^k = le (1 - rho^(bounces+1)) / (1 - rho)`, and
/// its truncation error `le rho^(bounces+1) / (1 - rho)`.
pub fn furnace_truncated(le: f64, rho: f64, bounces: u32) -> Result<(f64, f64), QuadError> {
    let whole = furnace(le, rho)?;
    let tail = whole * rho.powf(f64::from(bounces) + 1.0);
    Ok((whole - tail, tail))
}
