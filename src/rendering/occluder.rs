//! Occluders: opaque spheres, disks, rectangles (parallelograms) and
//! triangles, with ray intersection. They make the visibility `V(x, y)` of
//! R-A and the geometry term `g(x, x') = V(x, x') / |x - x'|^2` of R-3P
//! ([`crate::rendering::scene::Scene::visible`]); emitters are intersected by
//! the same routines.
//!
//! | shape | intersection |
//! |---|---|
//! | sphere | [`crate::geometry::Sphere::line_roots`]: radicand `(R - h)(R + h)` from the distance `h` of the centre to the line, the second root from the product of the roots (Haines et al., Ray Tracing Gems 2019) |
//! | disk | the plane `n . (p - c) = 0`, then `|p - c| <= R` |
//! | rectangle | Möller–Trumbore on the parallelogram `o + a e_1 + b e_2`, `a, b` in `[0, 1]` |
//! | triangle | the watertight test of Woop, Benthin and Wald (JCGT 2(1), 2013): edge functions in a ray-aligned shear frame, so that a ray through a shared edge or vertex of two triangles hits at least one of them |
//!
//! Every routine returns the smallest `t` in the open interval `(t_min,
//! t_max)` along a unit direction, both faces counted, or `None`. A hit
//! counts only where it lies in the interval beyond the rounding of `t`
//! itself ([`plane_t`], [`sphere_rounding`]): `t - err > t_min` and `t + err
//! < t_max`. So a surface through the ray's origin (a receiver on a floor)
//! or through the far end (an occluder in the plane of a light, a shadow
//! ray's end point) is not met by rounding, while a surface `1e-12` in
//! front of the origin, where `t` is known to a few ulps, is. No offset
//! proportional to the scene's size is needed (a fixed `1e-10` of it hid
//! everything within `1e-10` of the receiver, and everything at all where
//! one edge was `1e23` long). The bounds use Higham's `gamma_k = k u / (1 -
//! k u)` ([`crate::whitted::intersect::gamma`]).
//!
//! ```
//! use lightquad::domain::Vec3;
//! use lightquad::rendering::occluder::Occluder;
//!
//! // A unit square at height 2 blocks the ray straight up from the origin at t = 2.
//! let square = Occluder::rectangle(
//!     Vec3::new(-0.5, -0.5, 2.0),
//!     Vec3::new(1.0, 0.0, 0.0),
//!     Vec3::new(0.0, 1.0, 0.0),
//! )?;
//! assert_eq!(square.intersect(Vec3::zeros(), Vec3::z(), 0.0, f64::INFINITY), Some(2.0));
//! // ... but not a ray that stops short of it.
//! assert_eq!(square.intersect(Vec3::zeros(), Vec3::z(), 0.0, 1.5), None);
//! // Degenerate geometry is an error naming the parameter.
//! assert!(Occluder::sphere(Vec3::zeros(), 0.0).is_err());
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use crate::domain::{Disk, Rectangle, Triangle, Vec3};
use crate::error::QuadError;
use crate::geometry::Sphere;
use crate::whitted::intersect::gamma;

/// An opaque surface that blocks light.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Occluder {
    /// A sphere.
    Sphere(Sphere),
    /// A disk.
    Disk(Disk),
    /// A parallelogram `o + a e_1 + b e_2`, `a, b` in `[0, 1]`.
    Rectangle(Rectangle),
    /// A triangle.
    Triangle(Triangle),
}

impl Occluder {
    /// The sphere about `centre` of radius `radius` (finite, `> 0`).
    pub fn sphere(centre: Vec3, radius: f64) -> Result<Self, QuadError> {
        Ok(Occluder::Sphere(Sphere::new(centre, radius)?))
    }

    /// The disk about `centre` perpendicular to `normal`, of radius `radius`.
    pub fn disk(centre: Vec3, normal: Vec3, radius: f64) -> Result<Self, QuadError> {
        Ok(Occluder::Disk(Disk::new(centre, normal, radius)?))
    }

    /// The parallelogram at `origin` spanned by `edge_u` and `edge_v`.
    pub fn rectangle(origin: Vec3, edge_u: Vec3, edge_v: Vec3) -> Result<Self, QuadError> {
        Ok(Occluder::Rectangle(Rectangle::new(origin, edge_u, edge_v)?))
    }

    /// The triangle `abc`.
    pub fn triangle(a: Vec3, b: Vec3, c: Vec3) -> Result<Self, QuadError> {
        Ok(Occluder::Triangle(Triangle::new(a, b, c)?))
    }

    /// The smallest `t` in `(t_min, t_max)` at which `origin + t dir` (unit
    /// `dir`) meets the surface, either face, or `None`.
    pub fn intersect(&self, origin: Vec3, dir: Vec3, t_min: f64, t_max: f64) -> Option<f64> {
        match self {
            Occluder::Sphere(s) => intersect_sphere(s, origin, dir, t_min, t_max),
            Occluder::Disk(d) => intersect_disk(d, origin, dir, t_min, t_max),
            Occluder::Rectangle(r) => intersect_parallelogram(r, origin, dir, t_min, t_max),
            Occluder::Triangle(t) => intersect_triangle(t, origin, dir, t_min, t_max),
        }
    }

    /// The unit normal at a point `y` of the shape (either orientation: an
    /// occluder blocks on both sides).
    pub fn normal_at(&self, y: Vec3) -> Vec3 {
        match self {
            Occluder::Sphere(s) => (y - s.centre) / s.radius,
            Occluder::Disk(d) => d.frame().n,
            Occluder::Rectangle(r) => r.normal(),
            Occluder::Triangle(t) => t.normal(),
        }
    }

    /// A sphere containing the shape: `(centre, radius)` (the sphere itself,
    /// the disk's circle; a parallelogram's or triangle's centre with its
    /// farthest corner).
    pub fn bounding_sphere(&self) -> (Vec3, f64) {
        let around = |centre: Vec3, corners: &[Vec3]| {
            let r = corners
                .iter()
                .fold(0.0_f64, |m, p| m.max((p - centre).norm()));
            (centre, r)
        };
        match self {
            Occluder::Sphere(s) => (s.centre, s.radius),
            Occluder::Disk(d) => (d.centre(), d.radius()),
            Occluder::Rectangle(r) => {
                let (o, a, b) = (r.origin(), r.edge_u(), r.edge_v());
                around(o + (a + b) / 2.0, &[o, o + a, o + b, o + a + b])
            }
            Occluder::Triangle(t) => {
                let v = t.vertices();
                around((v[0] + v[1] + v[2]) / 3.0, &v)
            }
        }
    }

    /// A bound on the size of the coordinates of the shape's points
    /// (`|centre|_inf + radius`, or the largest corner coordinate): the
    /// scale of the rounding of its intersections, for the offsets of
    /// [`crate::rendering::scene::Scene`].
    pub fn extent(&self) -> f64 {
        match self {
            Occluder::Sphere(s) => s.centre.amax() + s.radius,
            Occluder::Disk(d) => d.centre().amax() + d.radius(),
            Occluder::Rectangle(r) => [
                r.origin(),
                r.origin() + r.edge_u(),
                r.origin() + r.edge_v(),
                r.origin() + r.edge_u() + r.edge_v(),
            ]
            .iter()
            .fold(0.0, |m: f64, p| m.max(p.amax())),
            Occluder::Triangle(t) => t.vertices().iter().fold(0.0, |m: f64, p| m.max(p.amax())),
        }
    }
}

/// `t` if it lies in `(t_min, t_max)` beyond its rounding bound `err`.
fn certain(t: f64, err: f64, t_min: f64, t_max: f64) -> Option<f64> {
    (t - err > t_min && t + err < t_max).then_some(t)
}

/// Where `o + t d` meets the plane through `p0` with unit normal `n`, with
/// a bound on the rounding of `t`:
///
/// `t = n . (p0 - o) / (n . d)`,
/// `err = (gamma_8 |n| . |p0 - o| + gamma_6 |t| |n| . |d|) / |n . d|`
///
/// (the difference, the dot products and the normal's own rounding in the
/// numerator, the denominator's relative error carried to `t`). `None` for
/// a ray parallel to the plane or a non-finite `t`.
pub fn plane_t(n: Vec3, p0: Vec3, o: Vec3, d: Vec3) -> Option<(f64, f64)> {
    let denom = n.dot(&d);
    let to_plane = p0 - o;
    let t = n.dot(&to_plane) / denom;
    if denom == 0.0 || !t.is_finite() {
        return None;
    }
    let (an, ad) = (n.abs(), d.abs());
    let err = (gamma(8) * an.dot(&to_plane.abs()) + gamma(6) * t.abs() * an.dot(&ad)) / denom.abs();
    Some((t, err))
}

/// The rounding bound of [`Sphere::line_roots`]'s roots for a line from
/// `o`: `gamma_16 (|o - c| + R)`.
pub fn sphere_rounding(s: &Sphere, o: Vec3) -> f64 {
    gamma(16) * ((o - s.centre).norm() + s.radius)
}

/// The nearer of the two roots of [`Sphere::line_roots`] in `(t_min, t_max)`
/// beyond their rounding ([`sphere_rounding`]).
pub fn intersect_sphere(
    s: &Sphere,
    origin: Vec3,
    dir: Vec3,
    t_min: f64,
    t_max: f64,
) -> Option<f64> {
    let (t0, t1) = s.line_roots(origin, dir)?;
    let err = sphere_rounding(s, origin);
    certain(t0, err, t_min, t_max).or_else(|| certain(t1, err, t_min, t_max))
}

/// The plane's `t` ([`plane_t`]), then `|o + t d - c|^2 <= R^2`.
pub fn intersect_disk(d: &Disk, origin: Vec3, dir: Vec3, t_min: f64, t_max: f64) -> Option<f64> {
    let (t, err) = plane_t(d.frame().n, d.centre(), origin, dir)?;
    let t = certain(t, err, t_min, t_max)?;
    let q = dir * t - (d.centre() - origin);
    (q.norm_squared() <= d.radius() * d.radius()).then_some(t)
}

/// Möller–Trumbore's coordinates on a parallelogram: with `P = d x e_2`,
/// `det = e_1 . P`, `T = o - origin_of_patch`, `Q = T x e_1`: `a = T . P /
/// det`, `b = d . Q / det`, a hit when `a, b` are in `[0, 1]`; `t` from the
/// plane with its rounding bound ([`plane_t`]).
pub fn intersect_parallelogram(
    r: &Rectangle,
    origin: Vec3,
    dir: Vec3,
    t_min: f64,
    t_max: f64,
) -> Option<f64> {
    let (e1, e2) = (r.edge_u(), r.edge_v());
    let p = dir.cross(&e2);
    let det = e1.dot(&p);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv = 1.0 / det;
    let tv = origin - r.origin();
    let a = tv.dot(&p) * inv;
    if !(0.0..=1.0).contains(&a) {
        return None;
    }
    let q = tv.cross(&e1);
    let b = dir.dot(&q) * inv;
    if !(0.0..=1.0).contains(&b) {
        return None;
    }
    let (t, err) = plane_t(r.normal(), r.origin(), origin, dir)?;
    certain(t, err, t_min, t_max)
}

/// The watertight ray–triangle test (Woop, Benthin, Wald, "Watertight
/// ray/triangle intersection", JCGT 2(1), 2013): the vertices relative to
/// the origin are sheared so that the ray is the `+z` axis (`k_z` the
/// largest component of `d`, `S = (d_x/d_z, d_y/d_z, 1/d_z)`); the edge
/// functions `U = C_x B_y - C_y B_x`, `V = A_x C_y - A_y C_x`, `W = B_x A_y
/// - B_y A_x` of the sheared 2-D vertices decide the hit (all of one sign;
/// an edge exactly through the ray counts for both triangles sharing it);
/// `t` from the triangle's plane with its rounding bound ([`plane_t`]).
pub fn intersect_triangle(
    tri: &Triangle,
    origin: Vec3,
    dir: Vec3,
    t_min: f64,
    t_max: f64,
) -> Option<f64> {
    // The axis of the largest |d| becomes z; x, y keep the winding.
    let kz = dir.iamax();
    let mut kx = (kz + 1) % 3;
    let mut ky = (kx + 1) % 3;
    if dir[kz] < 0.0 {
        std::mem::swap(&mut kx, &mut ky);
    }
    let sx = dir[kx] / dir[kz];
    let sy = dir[ky] / dir[kz];
    let [a, b, c] = tri.vertices().map(|v| v - origin);
    let shear = |v: Vec3| (v[kx] - sx * v[kz], v[ky] - sy * v[kz]);
    let (ax, ay) = shear(a);
    let (bx, by) = shear(b);
    let (cx, cy) = shear(c);
    let u = cx * by - cy * bx;
    let v = ax * cy - ay * cx;
    let w = bx * ay - by * ax;
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return None;
    }
    let det = u + v + w;
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let (t, err) = plane_t(tri.normal(), tri.vertices()[0], origin, dir)?;
    certain(t, err, t_min, t_max)
}
