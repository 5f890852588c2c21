//! The exact pieces of a great half-circle of directions that a shape, a
//! cone of directions or a half-space covers, seen from a point: what makes
//! an integrand with visibility jumps smooth piece by piece.
//!
//! A spoke is the half-circle `w(rho) = cos rho a + sin rho b` (`a`, `b`
//! orthonormal) for `rho` in `[0, reach]`: the directions of a polar map
//! about `a`. Its full circle lies in the plane through `x` with normal `m =
//! a x b`, and each outline meets it where that plane does:
//!
//! - a convex planar shape (rectangle, triangle, disk): the plane cuts the
//!   shape's plane in a line and the shape in a segment, found where the
//!   edges (the rim) change side of the plane; the directions to the
//!   segment are one arc, shorter than `pi`, between its ends;
//! - the cone of directions within `beta` of unit `c` (a sphere from
//!   outside, a cap light, `beta = pi/2` a half-space: the horizon, a lobe's
//!   clamp): with `gamma` the angle of `c` from the plane (`sin gamma = c .
//!   m`), the circle comes no nearer `c` than `|gamma|` and no farther than
//!   `pi - |gamma|`; between, the arc about `c`'s projection has half-width
//!   `delta`, `cos beta = cos gamma cos delta` (the right spherical
//!   triangle), taken without cancellation for small angles as
//!   `sin^2(delta/2) = sin((beta + gamma)/2) sin((beta - gamma)/2) / cos
//!   gamma`.
//!
//! Every angle is measured from `a` toward `b`, so an arc's ends are exact
//! to the rounding of the geometry, and pieces are combined as sorted lists
//! of intervals ([`intersect`], [`subtract`]).

use std::f64::consts::PI;

use crate::domain::{Disk, Frame, Vec3};
use crate::error::QuadError;
use crate::rendering::occluder::Occluder;

/// Sorted, disjoint closed intervals of the angle `rho` along a spoke.
pub type Pieces = Vec<(f64, f64)>;

/// The great half-circle of unit directions `cos rho a + sin rho b` from
/// `x`, `rho` in `[0, reach]` (module text).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spoke {
    /// The apex.
    pub x: Vec3,
    /// The direction at `rho = 0` (unit).
    pub a: Vec3,
    /// The direction at `rho = pi/2` (unit, orthogonal to `a`).
    pub b: Vec3,
    /// The largest `rho`, at most `pi`.
    pub reach: f64,
}

impl Spoke {
    /// The direction at angle `rho` from `a`.
    pub fn direction(&self, rho: f64) -> Vec3 {
        self.a * rho.cos() + self.b * rho.sin()
    }

    /// The whole spoke.
    pub fn all(&self) -> Pieces {
        vec![(0.0, self.reach)]
    }

    /// `m = a x b`, the normal of the spoke's plane.
    fn normal(&self) -> Vec3 {
        self.a.cross(&self.b)
    }

    /// The angle of `w` (in the spoke's plane) from `a` toward `b`, in
    /// `(-pi, pi]`.
    fn angle_of(&self, w: Vec3) -> f64 {
        w.dot(&self.b).atan2(w.dot(&self.a))
    }

    /// The part in `[0, reach]` of the arc of the full circle from angle
    /// `start` (in `[-2 pi, 2 pi]`) through `len` (in `[0, 2 pi]`).
    fn window(&self, start: f64, len: f64) -> Pieces {
        if len >= 2.0 * PI {
            return self.all();
        }
        let mut out: Pieces = [-4.0 * PI, -2.0 * PI, 0.0, 2.0 * PI, 4.0 * PI]
            .iter()
            .map(|shift| {
                (
                    (start + shift).max(0.0),
                    (start + shift + len).min(self.reach),
                )
            })
            .filter(|(lo, hi)| lo < hi)
            .collect();
        out.sort_by(|p, q| p.0.total_cmp(&q.0));
        merge(out)
    }

    /// The directions within angle `beta` (in `[0, pi]`) of unit `c`
    /// (module text).
    pub fn cone(&self, c: Vec3, beta: f64) -> Pieces {
        let g = c.dot(&self.normal()).abs().min(1.0).asin();
        if beta <= g {
            return Vec::new();
        }
        if beta >= PI - g {
            return self.all();
        }
        let ratio = ((beta + g) / 2.0).sin() * ((beta - g) / 2.0).sin() / g.cos();
        let delta = 2.0 * ratio.clamp(0.0, 1.0).sqrt().asin();
        let psi = self.angle_of(c);
        self.window(psi - delta, 2.0 * delta)
    }

    /// The directions on the side of the plane through `x` that unit `n`
    /// points to: `w . n >= 0`.
    pub fn half_space(&self, n: Vec3) -> Pieces {
        self.cone(n, PI / 2.0)
    }

    /// The directions from `x` that meet the occluder shape `o`.
    pub fn shape(&self, o: &Occluder) -> Pieces {
        match o {
            Occluder::Sphere(s) => match sphere_seen(s.centre - self.x, s.radius) {
                SphereSeen::Around => self.all(),
                SphereSeen::From(c, beta) => self.cone(c, beta),
            },
            Occluder::Disk(d) => self.disk(d),
            Occluder::Rectangle(r) => {
                let (o, e1, e2) = (r.origin(), r.edge_u(), r.edge_v());
                self.polygon(&[o, o + e1, o + e1 + e2, o + e2], r.normal())
            }
            Occluder::Triangle(t) => self.polygon(&t.vertices(), t.normal()),
        }
    }

    /// True when `x` lies in the plane through `p` with unit normal `n` to
    /// the rounding of their distance (`gamma_8 |n| . |p - x|`, as the
    /// occluders' intersections bound it): the shape is seen edge on and
    /// covers no solid angle. (A fixed 1e-14 of the shape's size took a
    /// disk 1e-15 above the receiver for edge on, and the reference let
    /// the light through it.)
    fn edge_on(&self, p: Vec3, n: Vec3) -> bool {
        let to = p - self.x;
        n.dot(&to).abs() <= crate::whitted::intersect::gamma(8) * n.abs().dot(&to.abs())
    }

    /// The directions to a convex planar polygon (vertices in order, unit
    /// normal `n`): the segment where the spoke's plane cuts it, through the
    /// points where its edges change side.
    fn polygon(&self, vertices: &[Vec3], n: Vec3) -> Pieces {
        if self.edge_on(vertices[0], n) {
            return Vec::new();
        }
        let m = self.normal();
        let side: Vec<f64> = vertices.iter().map(|v| m.dot(&(v - self.x))).collect();
        let mut points = Vec::with_capacity(4);
        for i in 0..vertices.len() {
            let j = (i + 1) % vertices.len();
            if side[i] == 0.0 {
                points.push(vertices[i]);
            }
            if side[i] * side[j] < 0.0 {
                let t = side[i] / (side[i] - side[j]);
                points.push(vertices[i] + (vertices[j] - vertices[i]) * t);
            }
        }
        self.segment(&points)
    }

    /// The directions to a disk: the chord between the two rim points
    /// `c + R (cos t s + sin t t)` in the spoke's plane, `m . (c - x) + R
    /// k cos(t - tau) = 0`.
    fn disk(&self, d: &Disk) -> Pieces {
        let (c, f, r) = (d.centre(), d.frame(), d.radius());
        if self.edge_on(c, f.n) {
            return Vec::new();
        }
        let m = self.normal();
        let offset = m.dot(&(c - self.x));
        let (p, q) = (m.dot(&f.s), m.dot(&f.t));
        let k = p.hypot(q) * r;
        if k <= offset.abs() {
            return Vec::new();
        }
        let tau = q.atan2(p);
        let h = (-offset / k).acos();
        let rim = |t: f64| c + (f.s * t.cos() + f.t * t.sin()) * r;
        self.segment(&[rim(tau - h), rim(tau + h)])
    }

    /// The arc of directions from `x` to the segment spanned by `points`
    /// (on a line in the spoke's plane not through `x`): from the smallest
    /// to the largest angle relative to the first point.
    fn segment(&self, points: &[Vec3]) -> Pieces {
        let Some(first) = points.first() else {
            return Vec::new();
        };
        let m = self.normal();
        let w0 = first - self.x;
        let (mut lo, mut hi) = (0.0_f64, 0.0_f64);
        for p in &points[1..] {
            let w = p - self.x;
            let rel = w0.cross(&w).dot(&m).atan2(w0.dot(&w));
            lo = lo.min(rel);
            hi = hi.max(rel);
        }
        if hi <= lo {
            return Vec::new();
        }
        self.window(self.angle_of(w0) + lo, hi - lo)
    }
}

/// The spokes about a unit axis: the polar map `w(rho, phi) = cos rho a +
/// sin rho (cos phi s + sin phi t)` of the directions from `x` out to
/// `reach`, with the frame `(s, t, a)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fan {
    /// The apex.
    pub x: Vec3,
    /// `s`, `t` and the axis `a` as `n`.
    pub frame: Frame,
    /// The largest `rho`, at most `pi`.
    pub reach: f64,
}

impl Fan {
    /// The fan from `x` about the direction to `o`'s bounding sphere, out to
    /// the sphere's cone (all around, `pi`, for `x` inside it); about
    /// `fallback` (unit) for `x` at its centre.
    pub fn about(o: &Occluder, x: Vec3, fallback: Vec3) -> Result<Fan, QuadError> {
        let (centre, radius) = o.bounding_sphere();
        let to = centre - x;
        let d = to.norm();
        Ok(Fan {
            x,
            frame: Frame::from_normal(if d > 0.0 { to / d } else { fallback })?,
            reach: if d > radius {
                (radius / d).min(1.0).asin()
            } else {
                PI
            },
        })
    }

    /// The spoke at azimuth `phi`.
    pub fn spoke(&self, phi: f64) -> Spoke {
        let f = self.frame;
        Spoke {
            x: self.x,
            a: f.n,
            b: f.s * phi.cos() + f.t * phi.sin(),
            reach: self.reach,
        }
    }

    /// The azimuths in `[0, 2 pi)` where a spoke's pieces of the shape `o`
    /// change how they vary: the corners of a polygon (where an edge lies in
    /// a plane through the axis, the pieces jump there), the spokes tangent
    /// to a sphere's cone. Elsewhere they vary smoothly, but for tangents to
    /// a disk's rim, which bisection finds.
    pub fn breaks(&self, o: &Occluder) -> Vec<f64> {
        match o {
            Occluder::Sphere(s) => match sphere_seen(s.centre - self.x, s.radius) {
                SphereSeen::Around => Vec::new(),
                SphereSeen::From(c, beta) => self.cone_breaks(c, beta),
            },
            Occluder::Disk(_) => Vec::new(),
            Occluder::Rectangle(r) => {
                let (o, e1, e2) = (r.origin(), r.edge_u(), r.edge_v());
                self.azimuths(&[o, o + e1, o + e1 + e2, o + e2])
            }
            Occluder::Triangle(t) => self.azimuths(&t.vertices()),
        }
    }

    /// The azimuths of the directions where any two of `outlines` cross:
    /// kinks of the azimuthal integrand where an outline takes over from
    /// another at the end of a piece (a triangle light's edge crossing the
    /// horizon was 1.7e-11 off, 170 times the estimate, without them).
    pub fn crossing_breaks(&self, outlines: &[Outline]) -> Vec<f64> {
        let mut points = Vec::new();
        // Only crossings within the fan's reach cut its spokes.
        let within = self.reach.cos() - 1e-12;
        for (i, a) in outlines.iter().enumerate() {
            for b in &outlines[i + 1..] {
                points.extend(
                    a.crossings(b)
                        .into_iter()
                        .filter(|w| w.dot(&self.frame.n) >= within)
                        .map(|w| self.x + w),
                );
            }
        }
        self.azimuths(&points)
    }

    /// The azimuths of the points `p` (seen from `x`), those on the axis
    /// left out.
    fn azimuths(&self, points: &[Vec3]) -> Vec<f64> {
        points
            .iter()
            .filter_map(|p| {
                let w = p - self.x;
                let (u, v) = (w.dot(&self.frame.s), w.dot(&self.frame.t));
                (u != 0.0 || v != 0.0).then(|| v.atan2(u).rem_euclid(2.0 * PI))
            })
            .collect()
    }

    /// The azimuths of the spokes whose great circles are tangent to the
    /// cone of half-angle `beta` about unit `c` (`|c . m| = sin beta` with
    /// `c . m(phi) = K cos(phi - tau)`, `K = |c x a|`), and `tau`, `tau +
    /// pi` (where a half-space's plane holds the axis, its boundary is the
    /// spoke there and the pieces jump).
    pub fn cone_breaks(&self, c: Vec3, beta: f64) -> Vec<f64> {
        let q = c.cross(&self.frame.n);
        let k = q.norm();
        if k == 0.0 {
            return Vec::new();
        }
        let tau = q.dot(&self.frame.t).atan2(q.dot(&self.frame.s));
        let mut out = vec![tau, tau + PI];
        let sb = beta.sin();
        if sb < k {
            let h = (sb / k).acos();
            out.extend([tau + h, tau - h, tau + PI + h, tau + PI - h]);
        }
        out.into_iter().map(|p| p.rem_euclid(2.0 * PI)).collect()
    }
}

/// An outline on the sphere of directions from a point: the circle `w . c
/// = cos beta` (a great circle for `cos beta = 0`: the horizon, a lobe's
/// clamp) or the great arc from unit `p` to unit `q` (a polygon's edge,
/// shorter than `pi`). Where two outlines cross, the pieces of the spokes
/// through the crossing change which outline ends them: a kink of the
/// azimuthal integrand ([`Fan::crossing_breaks`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Outline {
    /// Unit centre `c` and `cos beta`.
    Circle(Vec3, f64),
    /// Unit ends `p`, `q`.
    Arc(Vec3, Vec3),
}

impl Outline {
    /// The outlines of a shape seen from `x`: a sphere's silhouette circle,
    /// a polygon's edges; none for a disk (its rim is no circle of
    /// directions) or a sphere around `x`.
    pub fn of(o: &Occluder, x: Vec3) -> Vec<Outline> {
        let arcs = |v: &[Vec3]| -> Vec<Outline> {
            (0..v.len())
                .filter_map(|i| {
                    let (p, q) = (v[i] - x, v[(i + 1) % v.len()] - x);
                    let (np, nq) = (p.norm(), q.norm());
                    (np > 0.0 && nq > 0.0).then(|| Outline::Arc(p / np, q / nq))
                })
                .collect()
        };
        match o {
            Occluder::Sphere(s) => match sphere_seen(s.centre - x, s.radius) {
                SphereSeen::Around => Vec::new(),
                SphereSeen::From(c, beta) => vec![Outline::Circle(c, beta.cos())],
            },
            Occluder::Disk(_) => Vec::new(),
            Occluder::Rectangle(r) => {
                let (o, e1, e2) = (r.origin(), r.edge_u(), r.edge_v());
                arcs(&[o, o + e1, o + e1 + e2, o + e2])
            }
            Occluder::Triangle(t) => arcs(&t.vertices()),
        }
    }

    /// The circle this outline lies on: centre and `cos beta`.
    fn circle(&self) -> (Vec3, f64) {
        match *self {
            Outline::Circle(c, k) => (c, k),
            Outline::Arc(p, q) => (p.cross(&q).normalize(), 0.0),
        }
    }

    /// Whether unit `w` on this outline's circle lies on the outline.
    fn holds(&self, w: Vec3) -> bool {
        match *self {
            Outline::Circle(..) => true,
            Outline::Arc(p, q) => {
                let m = p.cross(&q);
                p.cross(&w).dot(&m) >= 0.0 && w.cross(&q).dot(&m) >= 0.0
            }
        }
    }

    /// The directions where two outlines cross: the circles' common points
    /// `w = a c_1 + b c_2 + t (c_1 x c_2)` with `w . c_i = cos beta_i`,
    /// kept where they lie on both outlines.
    pub fn crossings(&self, other: &Outline) -> Vec<Vec3> {
        let ((c1, k1), (c2, k2)) = (self.circle(), other.circle());
        let g = c1.dot(&c2);
        let axis = c1.cross(&c2);
        let s2 = axis.norm_squared();
        // Parallel circles (or a NaN) have no crossing worth a break.
        if s2.is_nan() || s2 <= 1e-24 {
            return Vec::new();
        }
        let a = (k1 - g * k2) / s2;
        let b = (k2 - g * k1) / s2;
        let base = c1 * a + c2 * b;
        let left = 1.0 - base.norm_squared();
        if left.is_nan() || left < 0.0 {
            return Vec::new();
        }
        let t = (left / s2).sqrt();
        [base + axis * t, base - axis * t]
            .into_iter()
            .filter(|w| self.holds(*w) && other.holds(*w))
            .collect()
    }
}

/// How a sphere is seen from a point: all around it (inside), or as the
/// cone about unit `c` of half-angle `beta` (`sin beta = R / d` outside;
/// `beta = pi/2` on the surface, to 1e-12 of `R`, where the sphere fills
/// the half-space under its tangent plane: a receiver resting on a ball).
enum SphereSeen {
    Around,
    From(Vec3, f64),
}

/// [`SphereSeen`] of the sphere of radius `r` whose centre is `to` from
/// the point.
fn sphere_seen(to: Vec3, r: f64) -> SphereSeen {
    let d = to.norm();
    if d < r * (1.0 - 1e-12) || d == 0.0 {
        SphereSeen::Around
    } else if d <= r * (1.0 + 1e-12) {
        SphereSeen::From(to / d, PI / 2.0)
    } else {
        SphereSeen::From(to / d, (r / d).min(1.0).asin())
    }
}

/// Sorted intervals with overlapping or touching ones joined.
fn merge(sorted: Pieces) -> Pieces {
    let mut out: Pieces = Vec::with_capacity(sorted.len());
    for (lo, hi) in sorted {
        match out.last_mut() {
            Some(last) if lo <= last.1 => last.1 = last.1.max(hi),
            _ => out.push((lo, hi)),
        }
    }
    out
}

/// The intervals in both `a` and `b` (each sorted and disjoint).
pub fn intersect(a: &[(f64, f64)], b: &[(f64, f64)]) -> Pieces {
    let mut out = Vec::new();
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        let lo = a[i].0.max(b[j].0);
        let hi = a[i].1.min(b[j].1);
        if lo < hi {
            out.push((lo, hi));
        }
        if a[i].1 < b[j].1 {
            i += 1;
        } else {
            j += 1;
        }
    }
    out
}

/// The intervals of `a` outside `b` (each sorted and disjoint).
pub fn subtract(a: &[(f64, f64)], b: &[(f64, f64)]) -> Pieces {
    let mut out = Vec::new();
    for &(lo, hi) in a {
        let mut start = lo;
        for &(blo, bhi) in b {
            if bhi <= start || blo >= hi {
                continue;
            }
            if blo > start {
                out.push((start, blo));
            }
            start = start.max(bhi);
        }
        if start < hi {
            out.push((start, hi));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::QuadError;

    /// A spoke about `a` at azimuth `phi` in the frame of `a`.
    fn spoke(a: Vec3, phi: f64, reach: f64) -> Result<Spoke, QuadError> {
        let f = crate::domain::Frame::from_normal(a)?;
        Ok(Spoke {
            x: Vec3::new(0.3, -0.2, 0.1),
            a: f.n,
            b: f.s * phi.cos() + f.t * phi.sin(),
            reach,
        })
    }

    /// Whether `rho` lies in `pieces`, more than `margin` from their ends
    /// (`Some`) or too near an end to say (`None`).
    fn inside(pieces: &Pieces, rho: f64, margin: f64) -> Option<bool> {
        if pieces
            .iter()
            .any(|&(lo, hi)| (rho - lo).abs() < margin || (rho - hi).abs() < margin)
        {
            return None;
        }
        Some(pieces.iter().any(|&(lo, hi)| lo < rho && rho < hi))
    }

    /// Every shape's pieces agree with its own ray test at 2000 angles of
    /// 40 spokes each, away from the pieces' ends: the exact arcs are the
    /// directions the ray intersection routines say meet the shape.
    #[test]
    fn pieces_are_the_directions_that_meet_the_shape() -> Result<(), QuadError> {
        let shapes = [
            Occluder::sphere(Vec3::new(1.0, 0.5, 2.0), 0.7)?,
            Occluder::disk(Vec3::new(0.5, 0.0, 1.5), Vec3::new(0.3, 0.1, -1.0), 0.9)?,
            Occluder::rectangle(
                Vec3::new(-0.5, -0.4, 1.0),
                Vec3::new(1.2, 0.3, 0.2),
                Vec3::new(-0.1, 0.9, 0.4),
            )?,
            Occluder::triangle(
                Vec3::new(-1.0, 0.0, 0.5),
                Vec3::new(1.5, 0.2, 0.8),
                Vec3::new(0.1, 1.3, 1.9),
            )?,
        ];
        let mut seen = 0;
        for o in &shapes {
            let (centre, _) = o.bounding_sphere();
            let x = Vec3::new(0.3, -0.2, 0.1);
            let a = (centre - x).normalize();
            for s in 0..40 {
                let sp = spoke(a, s as f64 * 0.157 + 0.01, PI)?;
                let pieces = sp.shape(o);
                for i in 0..2000 {
                    let rho = PI * (i as f64 + 0.5) / 2000.0;
                    let hit = o
                        .intersect(x, sp.direction(rho), 0.0, f64::INFINITY)
                        .is_some();
                    if let Some(expected) = inside(&pieces, rho, 1e-9) {
                        assert_eq!(expected, hit, "{o:?} spoke {s} rho {rho}: {pieces:?}");
                        seen += usize::from(hit);
                    }
                }
            }
        }
        assert!(seen > 10_000, "only {seen} hits");
        Ok(())
    }

    /// A cone's pieces agree with the angle test, for cones narrow, wide,
    /// past a right angle and tiny, and the half-space with `w . n >= 0`.
    #[test]
    fn cone_pieces_are_the_directions_within_the_angle() -> Result<(), QuadError> {
        let c = Vec3::new(0.2, -0.7, 0.4).normalize();
        for beta in [1e-6, 0.3, 1.2, PI / 2.0, 2.5] {
            for s in 0..60 {
                let a = Vec3::new(0.1, -0.5, 0.6).normalize();
                let sp = spoke(a, s as f64 * 0.105, 2.9)?;
                let pieces = sp.cone(c, beta);
                for i in 0..5000 {
                    let rho = 2.9 * (i as f64 + 0.5) / 5000.0;
                    let angle = sp.direction(rho).dot(&c).clamp(-1.0, 1.0).acos();
                    if let Some(expected) = inside(&pieces, rho, 1e-9)
                        && (angle - beta).abs() > 1e-9
                    {
                        assert_eq!(expected, angle < beta, "beta {beta} spoke {s} rho {rho}");
                    }
                }
            }
        }
        Ok(())
    }

    /// A spoke through the middle of a tiny cone meets it over its whole
    /// width `2 beta`, to the rounding of the angles (1e-16 absolute).
    #[test]
    fn a_tiny_cone_has_its_width() -> Result<(), QuadError> {
        let c = Vec3::new(0.0, 0.6, 0.8);
        let beta = 1e-9;
        let sp = Spoke {
            x: Vec3::zeros(),
            a: Vec3::z(),
            b: Vec3::y(),
            reach: PI,
        };
        let pieces = sp.cone(c, beta);
        assert_eq!(pieces.len(), 1);
        let (lo, hi) = pieces[0];
        assert!((hi - lo - 2.0 * beta).abs() < 1e-15, "{pieces:?}");
        assert!(((lo + hi) / 2.0 - 0.6_f64.atan2(0.8)).abs() < 1e-15);
        Ok(())
    }

    /// Crossings lie on both outlines: a cap's circle with the horizon
    /// (two points), a polygon edge with the horizon (one, where the edge
    /// dips below it), and none for an edge wholly above it.
    #[test]
    fn crossings_lie_on_both_outlines() {
        let horizon = Outline::Circle(Vec3::z(), 0.0);
        let c = Vec3::new(0.6, 0.0, 0.1).normalize();
        let cap = Outline::Circle(c, 0.3_f64.cos());
        let points = cap.crossings(&horizon);
        assert_eq!(points.len(), 2);
        for w in &points {
            assert!((w.norm() - 1.0).abs() < 1e-15 && w.z.abs() < 1e-15, "{w:?}");
            assert!((w.dot(&c) - 0.3_f64.cos()).abs() < 1e-15, "{w:?}");
        }
        let edge = Outline::Arc(
            Vec3::new(1.0, 0.2, 0.5).normalize(),
            Vec3::new(1.0, -0.4, -0.3).normalize(),
        );
        let points = edge.crossings(&horizon);
        assert_eq!(points.len(), 1);
        let w = points[0];
        assert!(w.z.abs() < 1e-15 && w.x > 0.0, "{w:?}");
        let m = Vec3::new(1.0, 0.2, 0.5).cross(&Vec3::new(1.0, -0.4, -0.3));
        assert!(w.dot(&m).abs() < 1e-15, "{w:?}");
        let above = Outline::Arc(
            Vec3::new(1.0, 0.2, 0.5).normalize(),
            Vec3::new(1.0, -0.4, 0.3).normalize(),
        );
        assert!(above.crossings(&horizon).is_empty());
    }

    #[test]
    fn intersect_and_subtract_are_set_operations() {
        let a = vec![(0.0, 1.0), (2.0, 3.0)];
        let b = vec![(0.5, 2.5)];
        assert_eq!(intersect(&a, &b), vec![(0.5, 1.0), (2.0, 2.5)]);
        assert_eq!(subtract(&a, &b), vec![(0.0, 0.5), (2.5, 3.0)]);
        assert_eq!(subtract(&b, &a), vec![(1.0, 2.0)]);
        assert_eq!(subtract(&a, &[]), a);
        assert!(intersect(&a, &[]).is_empty());
    }
}
