//! Closed forms of the light two surfaces exchange (R-3P's geometry term
//! integrated over both surfaces, R-A integrated over a receiving surface):
//! the finite-to-finite form factor
//!
//! `F_12 = 1/(pi A_1) int_A1 int_A2 cos theta_1 cos theta_2 / r^2 dA_2 dA_1`,
//!
//! the fraction of the Lambertian emission of surface 1 that reaches
//! surface 2; `A_1 F_12 = A_2 F_21` (reciprocity). Lambertian surface 2 of
//! radiance `L` sends surface 1 the flux `Phi = pi L A_1 F_12`.
//!
//! - [`coaxial_disks`]: two parallel coaxial disks (Howell C-41).
//! - [`polygon_pair`]: any two planar polygons each wholly in front of the
//!   other, by the double contour integral that Stokes' theorem turns the
//!   4-D integral into (its inner integral in closed form).
//!
//! The parallel and perpendicular rectangles of Howell's catalogue
//! (C-11, C-14) are in [`crate::exact::rendering`].
//!
//! ```
//! use lightquad::domain::Vec3;
//! use lightquad::exact::exchange::polygon_pair;
//! use lightquad::exact::rendering::parallel_rectangles;
//!
//! // Two unit squares facing each other at distance 1: the contour form
//! // and Howell C-11 agree.
//! let p = |x: f64, y: f64, z: f64| Vec3::new(x, y, z);
//! let lower = [p(0., 0., 0.), p(1., 0., 0.), p(1., 1., 0.), p(0., 1., 0.)];
//! let upper = [p(0., 0., 1.), p(0., 1., 1.), p(1., 1., 1.), p(1., 0., 1.)];
//! let f = polygon_pair(&lower, &upper)?;
//! assert!((f.value - parallel_rectangles(1.0, 1.0, 1.0)?).abs() < 1e-14);
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use std::f64::consts::PI;

use crate::domain::Vec3;
use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::quadrature::Rule;
use crate::quadrature::gauss_kronrod::GaussKronrod;

/// R-3P over two areas, form factor from a disk of radius `r1` to a
/// parallel coaxial disk of radius `r2` at distance `h`, facing each other
/// (Howell C-41):
///
/// `F_12 = 1/2 [X - sqrt(X^2 - 4 (R_2/R_1)^2)]`, `R_i = r_i / h`,
/// `X = 1 + (1 + R_2^2) / R_1^2`.
///
/// Multiplied through by `r_1^2` and rationalised it is
/// `F_12 = 2 r_2^2 / (S + sqrt((S - 2 r_1 r_2)(S + 2 r_1 r_2)))` with
/// `S = r_1^2 + r_2^2 + h^2` and `S - 2 r_1 r_2 = h^2 + (r_1 - r_2)^2`: no
/// difference of nearly equal terms at any distance (distant disks make `X`
/// and the square root of the printed form agree to many digits). Lengths
/// are taken in units of the largest first, so no square overflows; a
/// length below 1e-154 of the largest underflows to its limit 0.
pub fn coaxial_disks(r1: f64, r2: f64, h: f64) -> Result<f64, QuadError> {
    let positive = |name: &str, x: f64| {
        if x.is_finite() && x > 0.0 {
            Ok(x)
        } else {
            Err(QuadError::invalid(name, x, "a finite number > 0"))
        }
    };
    let (r1, r2, h) = (positive("r1", r1)?, positive("r2", r2)?, positive("h", h)?);
    let unit = r1.max(r2).max(h);
    let (r1, r2, h) = (r1 / unit, r2 / unit, h / unit);
    let s = r1 * r1 + r2 * r2 + h * h;
    let minus = h * h + (r1 - r2) * (r1 - r2);
    let plus = s + 2.0 * r1 * r2;
    Ok(2.0 * r2 * r2 / (s + (minus * plus).sqrt()))
}

/// The relative tolerance to which [`polygon_pair`] integrates each edge
/// pair's outer integral.
pub const CONTOUR_TOL: f64 = 1e-13;

/// Evaluations [`polygon_pair`] may spend on one piece of one edge pair.
const CONTOUR_BUDGET: usize = 15 + 30 * 1000;

/// R-3P over two areas, the form factor `F_12` from planar polygon `from`
/// to planar polygon `to` (corners in order; each emits and receives on the
/// side of its right-hand normal, `(v_1 - v_0) x (v_2 - v_0)` for a convex
/// one), each wholly in front of the other (touching allowed: a shared
/// edge), with nothing between them. By Stokes' theorem twice (Sparrow
/// 1963; Howell, *Thermal Radiation Heat Transfer*, the contour-integral
/// method):
///
/// `A_1 F_12 = 1/(2 pi) sum_i sum_j (d_i . d_j) int_(e_i) int_(e_j) ln r dt ds`
///
/// over the edges `e_i` of `from` and `e_j` of `to` (unit directions `d`,
/// both contours counter-clockwise about their normals). The inner integral
/// is closed: with `x` along `e_j` from the foot of `p` and `h` its distance
/// from the line, `int ln sqrt(x^2 + h^2) dx = x ln sqrt(x^2 + h^2) - x + h
/// atan(x / h)`. The outer one is adaptive Gauss–Kronrod to
/// [`CONTOUR_TOL`], split where the two edges come closest and at the feet
/// of the other edge's ends (where the log singularity of touching edges
/// sits). Lengths are taken in units of the pair's size first, so the
/// logarithm's constant (which the closed contours cancel) stays small.
///
/// The error is the sum of the outer integrals' estimates, divided as `F`
/// is. Distant or small polygons (`F` far below 1) lose digits to
/// cancellation between edge pairs of size 1, about `1e-16 / F` relative,
/// and the error says so: a caller wanting 1e-12 checks `error <= 1e-12
/// value`. One polygon in the other's plane gives 0. The polygons must be
/// simple (refused otherwise: an edge of length 0, crossing edges).
pub fn polygon_pair(from: &[Vec3], to: &[Vec3]) -> Result<Estimate<f64>, QuadError> {
    let n1 = polygon_normal("from", from)?;
    let n2 = polygon_normal("to", to)?;
    simple("from", from, n1)?;
    simple("to", to, n2)?;
    in_front("to", to, from[0], n1)?;
    in_front("from", from, to[0], n2)?;
    // One polygon in the other's plane sees it only at grazing angles:
    // cos theta = 0 over it, no light passes (the contour sum of two
    // coplanar polygons is their overlap, not a form factor).
    if in_plane(to, from[0], n1) || in_plane(from, to[0], n2) {
        return Ok(Estimate::zero());
    }
    // Lengths in units of the pair's size.
    let all = from.iter().chain(to);
    let centre = all.clone().sum::<Vec3>() / (from.len() + to.len()) as f64;
    let size = all.map(|p| (p - centre).norm()).fold(0.0, f64::max);
    let scaled = |ps: &[Vec3]| -> Vec<Vec3> { ps.iter().map(|p| (p - centre) / size).collect() };
    let (a, b) = (scaled(from), scaled(to));
    let area1 = polygon_area(&a);
    let mut sum = 0.0;
    let mut error = 0.0;
    let mut evaluations = 0;
    for i in 0..a.len() {
        let (p0, p1) = (a[i], a[(i + 1) % a.len()]);
        for j in 0..b.len() {
            let (q0, q1) = (b[j], b[(j + 1) % b.len()]);
            let e = edge_pair(p0, p1, q0, q1)?;
            sum += e.value;
            error += e.error;
            evaluations += e.evaluations;
        }
    }
    let scale = 1.0 / (2.0 * PI * area1);
    Ok(Estimate {
        value: sum * scale,
        error: error * scale.abs(),
        evaluations,
        ..Estimate::zero()
    })
}

/// The unit right-hand normal of a planar polygon (Newell's), or the error
/// naming `name` for fewer than 3 corners, a non-finite one, a degenerate
/// polygon or one whose corners leave its plane.
fn polygon_normal(name: &str, ps: &[Vec3]) -> Result<Vec3, QuadError> {
    if ps.len() < 3 {
        return Err(QuadError::invalid(
            name,
            ps.len(),
            "a polygon of at least 3 corners",
        ));
    }
    if let Some(p) = ps.iter().find(|p| !p.iter().all(|x| x.is_finite())) {
        return Err(QuadError::invalid(name, format!("{p:?}"), "finite corners"));
    }
    let newell = newell(ps);
    let size = ps.iter().map(|p| (p - ps[0]).norm()).fold(0.0, f64::max);
    let len = newell.norm();
    if len.is_nan() || len <= 1e-12 * size * size {
        return Err(QuadError::invalid(
            name,
            format!("{:?}", ps),
            "a polygon of non-zero area",
        ));
    }
    let n = newell / len;
    if let Some(p) = ps
        .iter()
        .find(|p| n.dot(&(*p - ps[0])).abs() > 1e-12 * size)
    {
        return Err(QuadError::invalid(
            name,
            format!("{p:?}"),
            "corners in one plane",
        ));
    }
    Ok(n)
}

/// Whether every corner of `ps` lies in the plane through `p` with unit
/// normal `n`, to rounding.
fn in_plane(ps: &[Vec3], p: Vec3, n: Vec3) -> bool {
    let size = ps.iter().map(|q| (q - p).norm()).fold(0.0, f64::max);
    ps.iter().all(|q| n.dot(&(q - p)).abs() <= 1e-12 * size)
}

/// Refuses a polygon with two equal consecutive corners (an edge of length
/// 0) or two edges that cross or touch other than at their shared corner:
/// the contour integral of a polygon traversed twice, or of a figure eight,
/// is not its area's form factor.
fn simple(name: &str, ps: &[Vec3], n: Vec3) -> Result<(), QuadError> {
    let k = ps.len();
    // Coordinates in the polygon's plane.
    let frame = crate::domain::Frame::from_normal(n)
        .map_err(|_| QuadError::invalid(name, format!("{ps:?}"), "a polygon with a normal"))?;
    let flat: Vec<[f64; 2]> = ps
        .iter()
        .map(|p| {
            let l = frame.to_local(p - ps[0]);
            [l.x, l.y]
        })
        .collect();
    for i in 0..k {
        if ps[i] == ps[(i + 1) % k] {
            return Err(QuadError::invalid(
                name,
                format!("corners {i} and {} both {:?}", (i + 1) % k, ps[i]),
                "a polygon whose consecutive corners differ (edges of non-zero length)",
            ));
        }
    }
    for i in 0..k {
        for j in i + 1..k {
            let adjacent = j == i + 1 || (i == 0 && j == k - 1);
            let (a, b) = (flat[i], flat[(i + 1) % k]);
            let (c, d) = (flat[j], flat[(j + 1) % k]);
            if !adjacent && segments_meet(a, b, c, d) {
                return Err(QuadError::invalid(
                    name,
                    format!("edges {i} and {j} of {ps:?} meet"),
                    "a simple polygon (no edge crossing or touching another but its neighbours)",
                ));
            }
        }
    }
    Ok(())
}

/// Whether the closed segments `ab` and `cd` of the plane meet.
fn segments_meet(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> bool {
    let orient = |p: [f64; 2], q: [f64; 2], r: [f64; 2]| {
        let v = (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]);
        if v > 0.0 {
            1
        } else if v < 0.0 {
            -1
        } else {
            0
        }
    };
    let within = |p: [f64; 2], q: [f64; 2], r: [f64; 2]| {
        r[0] >= p[0].min(q[0])
            && r[0] <= p[0].max(q[0])
            && r[1] >= p[1].min(q[1])
            && r[1] <= p[1].max(q[1])
    };
    let (o1, o2, o3, o4) = (
        orient(a, b, c),
        orient(a, b, d),
        orient(c, d, a),
        orient(c, d, b),
    );
    if o1 != o2 && o3 != o4 && o1 * o2 <= 0 && o3 * o4 <= 0 && (o1 != 0 || o2 != 0) {
        return true;
    }
    (o1 == 0 && within(a, b, c))
        || (o2 == 0 && within(a, b, d))
        || (o3 == 0 && within(c, d, a))
        || (o4 == 0 && within(c, d, b))
}

/// Refuses polygon `name` where a corner lies behind the plane through `p`
/// with normal `n` (beyond rounding): the contour form needs each polygon
/// wholly in front of the other.
fn in_front(name: &str, ps: &[Vec3], p: Vec3, n: Vec3) -> Result<(), QuadError> {
    let size = ps.iter().map(|q| (q - p).norm()).fold(0.0, f64::max);
    match ps.iter().find(|q| n.dot(&(*q - p)) < -1e-12 * size) {
        Some(q) => Err(QuadError::invalid(
            name,
            format!("{q:?}"),
            "corners on or in front of the other polygon's plane (the contour form has no \
             horizon to clip at)",
        )),
        None => Ok(()),
    }
}

/// Newell's vector of a polygon: twice its area along its normal.
fn newell(ps: &[Vec3]) -> Vec3 {
    (0..ps.len())
        .map(|i| ps[i].cross(&ps[(i + 1) % ps.len()]))
        .sum()
}

/// The area of a planar polygon: half the length of Newell's vector.
fn polygon_area(ps: &[Vec3]) -> f64 {
    0.5 * newell(ps).norm()
}

/// `int_0^x 1/2 ln(t^2 + h^2) dt`'s antiderivative at `x`:
/// `x ln sqrt(x^2 + h^2) - x + h atan(x / h)` (`x ln |x| - x` at `h = 0`).
fn log_antiderivative(x: f64, h: f64) -> f64 {
    let log = if x == 0.0 {
        0.0
    } else {
        0.5 * x * (x.mul_add(x, h * h)).ln()
    };
    let arc = if h > 0.0 { h * (x / h).atan() } else { 0.0 };
    log - x + arc
}

/// `int_(q0)^(q1) ln |p - q| dq` along the segment: closed.
fn inner(p: Vec3, q0: Vec3, d: Vec3, len: f64) -> f64 {
    let w = p - q0;
    let x0 = w.dot(&d);
    let h = (w - d * x0).norm();
    log_antiderivative(len - x0, h) - log_antiderivative(-x0, h)
}

/// One edge pair's term `(d_i . d_j) int int ln r`, the outer integral by
/// adaptive Gauss–Kronrod on pieces split where it may be singular.
fn edge_pair(p0: Vec3, p1: Vec3, q0: Vec3, q1: Vec3) -> Result<Estimate<f64>, QuadError> {
    let (lp, lq) = ((p1 - p0).norm(), (q1 - q0).norm());
    let (dp, dq) = ((p1 - p0) / lp, (q1 - q0) / lq);
    let cos = dp.dot(&dq);
    if cos == 0.0 {
        return Ok(Estimate::zero());
    }
    let mut cuts = vec![0.0, 1.0];
    // The feet of q's ends on p's edge, and where the lines come closest.
    for q in [q0, q1] {
        cuts.push((q - p0).dot(&dp) / lp);
    }
    let cross = dp.cross(&dq);
    let c2 = cross.norm_squared();
    if c2 > 1e-24 {
        let w = q0 - p0;
        cuts.push(w.cross(&dq).dot(&cross) / c2 / lp);
    }
    cuts.retain(|s| s.is_finite() && (0.0..=1.0).contains(s));
    cuts.sort_by(f64::total_cmp);
    cuts.dedup_by(|a, b| (*a - *b).abs() < 1e-15);
    let rule = GaussKronrod {
        abs_tol: 0.0,
        rel_tol: CONTOUR_TOL,
    };
    let mut rng = <rand_pcg::Pcg64 as rand::SeedableRng>::seed_from_u64(0);
    let mut total = Estimate::zero();
    for w in cuts.windows(2) {
        let (s0, s1) = (w[0], w[1]);
        let width = s1 - s0;
        let piece = rule.integrate(CONTOUR_BUDGET, &mut rng, |[t]: [f64; 1]| {
            let p = p0 + dp * (lp * (s0 + width * t));
            inner(p, q0, dq, lq) * lp * width
        })?;
        total = total.combine(piece);
    }
    Ok(total.scaled(cos))
}
