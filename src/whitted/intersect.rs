//! Ray–object intersection for Whitted's tracer: spheres, planes and
//! triangles, robust at grazing incidence and against self-intersection.
//!
//! **Self-intersection.** A secondary ray starts where the previous one hit,
//! at a point computed in floating point, hence off the true surface by a
//! rounding error. A fixed epsilon (`t > 1e-4`) is either too large (it
//! misses nearby geometry and contact shadows) or too small (acne at large
//! coordinates). As pbrt-v4 does (Pharr, Jakob, Humphreys, *Physically Based
//! Rendering*, 4th ed., section 6.8), every hit carries a conservative bound
//! `delta_p` (per coordinate) on the error of its point, and a ray leaving
//! the surface starts at
//!
//! `o = p + s d n`, `d = |n| . delta_p` (the bound's extent along `n`),
//! `s = sign(w . n)`,
//!
//! each coordinate then rounded one float further away from `p`: `o` lies
//! strictly on the side of the true surface that `w` points to, so the ray
//! cannot meet that surface again near its origin. The bounds, with
//! `gamma_k = k u / (1 - k u)`, `u = 2^-53`:
//!
//! | shape | the hit point | `delta_p` |
//! |---|---|---|
//! | sphere | `p_l = f + t w` (`f = o - c`) reprojected, `p_l r / |p_l|`, then `c + p_l` | `gamma_5 |p_l| + gamma_1 |p|` |
//! | plane | `o + t w`, reprojected onto the plane: `p - n (n . (p - q))` | `gamma_7 (|p| + |q|)` |
//! | triangle | the barycentric sum `b_0 p_0 + b_1 p_1 + b_2 p_2` | `gamma_7 sum_i |b_i p_i|` |
//!
//! **Grazing rays.** The sphere's roots come from the form of the
//! quadratic that does not cancel (Haines et al., *Ray Tracing Gems* ch. 7):
//! the discriminant as `r^2 - |f - (f . w / w . w) w|^2` (the squared
//! distance of the centre from the line; no difference of two large
//! squares) and the roots as `c / q` and `q / a`, `q = -(b + sign(b)
//! sqrt(disc))`. Triangles use the watertight test of Woop, Benthin and
//! Wald (JCGT 2013): edge functions in a ray-aligned sheared frame, so a ray
//! through a shared edge hits one of the two triangles, never neither, and
//! a hit is accepted only beyond the error bound of its `t`.
//!
//! ```
//! use lightquad::domain::Vec3;
//! use lightquad::whitted::intersect::{Ray, Shape};
//!
//! // A unit sphere at 1e6 from the origin, hit and left again by a reflected
//! // ray: the spawned ray never meets the sphere it starts on.
//! let c = Vec3::new(1e6, 0.0, 0.0);
//! let sphere = Shape::sphere(c, 1.0)?;
//! let ray = Ray::new(Vec3::new(1e6 - 5.0, 0.3, 0.1), Vec3::x());
//! let hit = sphere.intersect(&ray).expect("hits");
//! let w = ray.direction - 2.0 * ray.direction.dot(&hit.normal) * hit.normal;
//! assert!(sphere.intersect(&hit.spawn(w)).is_none());
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use crate::domain::Vec3;
use crate::error::{QuadError, require_positive};
use crate::geometry::{normalize, require_finite_vec};

/// The unit roundoff of f64, `u = 2^-53`.
pub const UNIT_ROUNDOFF: f64 = f64::EPSILON / 2.0;

/// pbrt's `gamma_k = k u / (1 - k u)`: the relative error bound of `k`
/// chained floating-point operations (Higham, *Accuracy and Stability of
/// Numerical Algorithms*, lemma 3.1).
pub fn gamma(k: u32) -> f64 {
    let ku = f64::from(k) * UNIT_ROUNDOFF;
    ku / (1.0 - ku)
}

/// The relative distance short of a point light at which a shadow ray
/// stops (`t_max = 1 - SHADOW_EPSILON` for a ray whose direction is the
/// whole segment): the light is a point in space, not on a surface, so this
/// only keeps a surface exactly through the light from counting.
pub const SHADOW_EPSILON: f64 = 1e-9;

/// A ray `o + t w` for `t` in `(0, t_max)`; `w` need not be a unit vector
/// (a shadow ray's `w` spans the segment to the light, `t_max < 1`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    /// `o`.
    pub origin: Vec3,
    /// `w`.
    pub direction: Vec3,
    /// The far end of the segment (infinite for an unbounded ray).
    pub t_max: f64,
}

impl Ray {
    /// The unbounded ray from `origin` along `direction`.
    pub fn new(origin: Vec3, direction: Vec3) -> Self {
        Ray {
            origin,
            direction,
            t_max: f64::INFINITY,
        }
    }

    /// `o + t w`.
    pub fn at(&self, t: f64) -> Vec3 {
        self.origin + self.direction * t
    }
}

/// A surface of the scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// The sphere of `centre` and `radius`.
    Sphere {
        /// `c`.
        centre: Vec3,
        /// `r > 0`.
        radius: f64,
    },
    /// The plane through `point` with unit `normal`; its back (`-normal`)
    /// side is the inside of a transparent half-space.
    Plane {
        /// `q`, a point of the plane.
        point: Vec3,
        /// `n`, unit.
        normal: Vec3,
    },
    /// The triangle `a b c`, its normal `(b - a) x (c - a)` normalised.
    Triangle {
        /// The vertices.
        vertices: [Vec3; 3],
        /// The unit normal.
        normal: Vec3,
    },
}

/// Where a ray meets a shape.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// The ray parameter.
    pub t: f64,
    /// The hit point `p`.
    pub point: Vec3,
    /// `delta_p`: a bound on the error of each coordinate of `p`.
    pub error: Vec3,
    /// The shape's unit normal at `p` (outward for a sphere, the shape's
    /// own for a plane or triangle), whichever side the ray came from.
    pub normal: Vec3,
}

impl Hit {
    /// pbrt's offset origin: `p + s d n`, `d = |n| . delta_p`, `s = sign(w .
    /// n)`, every coordinate rounded one float away from `p` (module
    /// documentation). `w` is the direction of the ray that leaves.
    pub fn offset_origin(&self, w: Vec3) -> Vec3 {
        let n = self.normal;
        let d = n.abs().dot(&self.error);
        let offset = if w.dot(&n) < 0.0 { -d * n } else { d * n };
        let mut o = self.point + offset;
        for i in 0..3 {
            if offset[i] > 0.0 {
                o[i] = o[i].next_up();
            } else if offset[i] < 0.0 {
                o[i] = o[i].next_down();
            }
        }
        o
    }

    /// The unbounded ray leaving the hit along `w`.
    pub fn spawn(&self, w: Vec3) -> Ray {
        Ray::new(self.offset_origin(w), w)
    }

    /// The shadow ray from the hit toward the point `target`: `w = target -
    /// o` and `t_max = 1 - SHADOW_EPSILON`.
    pub fn spawn_to(&self, target: Vec3) -> Ray {
        let o = self.offset_origin(target - self.point);
        Ray {
            origin: o,
            direction: target - o,
            t_max: 1.0 - SHADOW_EPSILON,
        }
    }
}

impl Shape {
    /// The sphere of `centre` and `radius` (finite, `radius > 0`).
    pub fn sphere(centre: Vec3, radius: f64) -> Result<Self, QuadError> {
        require_finite_vec("centre", centre)?;
        require_positive("radius", radius)?;
        Ok(Shape::Sphere { centre, radius })
    }

    /// The plane through `point` with normal `normal` (normalised).
    pub fn plane(point: Vec3, normal: Vec3) -> Result<Self, QuadError> {
        require_finite_vec("point", point)?;
        Ok(Shape::Plane {
            point,
            normal: normalize("normal", normal)?,
        })
    }

    /// The triangle `a b c` (not degenerate).
    pub fn triangle(a: Vec3, b: Vec3, c: Vec3) -> Result<Self, QuadError> {
        for (name, v) in [("a", a), ("b", b), ("c", c)] {
            require_finite_vec(name, v)?;
        }
        // The vertex at fault: `b` where it is `a`, `c` where it is `a` or
        // `b`, and otherwise `c`, which lies on the line through the others.
        let at_fault = if b == a {
            (
                "b",
                b,
                "a vertex other than a (a triangle of non-zero area)",
            )
        } else if c == a || c == b {
            (
                "c",
                c,
                "a vertex other than a and b (a triangle of non-zero area)",
            )
        } else {
            (
                "c",
                c,
                "a vertex off the line through a and b (a triangle of non-zero area)",
            )
        };
        let normal = normalize("c", (b - a).cross(&(c - a))).map_err(|_| {
            let (name, v, accepted) = at_fault;
            QuadError::invalid(name, format!("{:?}", v.as_slice()), accepted)
        })?;
        Ok(Shape::Triangle {
            vertices: [a, b, c],
            normal,
        })
    }

    /// The largest absolute coordinate the shape reaches (a plane: its point).
    pub fn extent(&self) -> f64 {
        match self {
            Shape::Sphere { centre, radius } => centre.amax() + radius,
            Shape::Plane { point, .. } => point.amax(),
            Shape::Triangle { vertices, .. } => {
                vertices.iter().fold(0.0_f64, |m, v| m.max(v.amax()))
            }
        }
    }

    /// Its size: a sphere's radius, a triangle's longest edge; `None` for a
    /// plane.
    pub fn size(&self) -> Option<f64> {
        match self {
            Shape::Sphere { radius, .. } => Some(*radius),
            Shape::Plane { .. } => None,
            Shape::Triangle { vertices, .. } => Some((0..3).fold(0.0_f64, |m, i| {
                m.max((vertices[(i + 1) % 3] - vertices[i]).norm())
            })),
        }
    }

    /// Its size beside its distance from `eye`: a sphere's radius and a
    /// triangle's longest edge over the distance to its nearest point (the
    /// centre, a vertex); `None` for a plane, which has no size.
    pub fn size_over_distance(&self, eye: Vec3) -> Option<f64> {
        match self {
            Shape::Sphere { centre, radius } => Some(radius / ((centre - eye).norm() - radius)),
            Shape::Plane { .. } => None,
            Shape::Triangle { vertices, .. } => {
                let near = vertices
                    .iter()
                    .fold(f64::INFINITY, |m, v| m.min((v - eye).norm()));
                self.size().map(|edge| edge / near)
            }
        }
    }

    /// The first hit with `t` in `(0, ray.t_max)`.
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        match *self {
            Shape::Sphere { centre, radius } => sphere_hit(centre, radius, ray),
            Shape::Plane { point, normal } => plane_hit(point, normal, ray),
            Shape::Triangle { vertices, normal } => triangle_hit(&vertices, normal, ray),
        }
    }
}

/// The sphere's roots of `a t^2 + 2 b t + c = 0` (`a = w . w`, `b = f . w`,
/// `c = |f|^2 - r^2`, `f = o - c_s`) in the form that does not cancel:
/// `b^2 - a c = a (r^2 - |f - (b / a) w|^2)`, `q = -(b + sign(b) sqrt(b^2 -
/// a c))`, roots `c / q` and `q / a`.
fn sphere_hit(centre: Vec3, radius: f64, ray: &Ray) -> Option<Hit> {
    let w = ray.direction;
    let f = ray.origin - centre;
    let a = w.dot(&w);
    let b = f.dot(&w);
    let off_line = f - w * (b / a);
    let disc = a * (radius * radius - off_line.dot(&off_line));
    if disc.is_nan() || disc < 0.0 {
        return None;
    }
    let root = disc.sqrt();
    let q = -(b + if b >= 0.0 { root } else { -root });
    let c = f.dot(&f) - radius * radius;
    let (mut t0, mut t1) = (c / q, q / a);
    if q == 0.0 {
        // The origin at the centre with a zero direction component: no root.
        return None;
    }
    if t0 > t1 {
        std::mem::swap(&mut t0, &mut t1);
    }
    let t = if t0 > 0.0 && t0 < ray.t_max {
        t0
    } else if t1 > 0.0 && t1 < ray.t_max {
        t1
    } else {
        return None;
    };
    // Reprojected onto the sphere (pbrt-v4): error gamma_5 |p_l|.
    let raw = f + w * t;
    let local = raw * (radius / raw.norm());
    let point = centre + local;
    let error = local.abs() * gamma(5) + point.abs() * gamma(1);
    Some(Hit {
        t,
        point,
        error,
        normal: local / radius,
    })
}

/// `t = n . (q - o) / (n . w)`; the hit reprojected onto the plane.
fn plane_hit(q: Vec3, n: Vec3, ray: &Ray) -> Option<Hit> {
    let denom = n.dot(&ray.direction);
    if denom == 0.0 {
        return None;
    }
    let t = n.dot(&(q - ray.origin)) / denom;
    if !(t > 0.0 && t < ray.t_max) {
        return None;
    }
    let raw = ray.at(t);
    let point = raw - n * n.dot(&(raw - q));
    if !point.iter().all(|c| c.is_finite()) {
        return None;
    }
    let error = (point.abs() + q.abs()) * gamma(7);
    Some(Hit {
        t,
        point,
        error,
        normal: n,
    })
}

/// Woop, Benthin and Wald's watertight ray–triangle test, with pbrt-v4's
/// conservative bound on the error of `t` (a hit closer than its own
/// error bound is refused).
fn triangle_hit(p: &[Vec3; 3], normal: Vec3, ray: &Ray) -> Option<Hit> {
    let w = ray.direction;
    // The vertices relative to the origin, the axis of largest |w| last.
    let kz = w.iamax();
    let kx = (kz + 1) % 3;
    let ky = (kx + 1) % 3;
    let permute = |v: Vec3| Vec3::new(v[kx], v[ky], v[kz]);
    let d = permute(w);
    let (sx, sy, sz) = (-d.x / d.z, -d.y / d.z, 1.0 / d.z);
    let mut v = [
        permute(p[0] - ray.origin),
        permute(p[1] - ray.origin),
        permute(p[2] - ray.origin),
    ];
    for v in &mut v {
        v.x += sx * v.z;
        v.y += sy * v.z;
    }
    // Edge functions: the signed areas seen along the ray.
    let e0 = v[1].x * v[2].y - v[1].y * v[2].x;
    let e1 = v[2].x * v[0].y - v[2].y * v[0].x;
    let e2 = v[0].x * v[1].y - v[0].y * v[1].x;
    if (e0 < 0.0 || e1 < 0.0 || e2 < 0.0) && (e0 > 0.0 || e1 > 0.0 || e2 > 0.0) {
        return None;
    }
    let det = e0 + e1 + e2;
    if det == 0.0 {
        return None;
    }
    for v in &mut v {
        v.z *= sz;
    }
    let t_scaled = e0 * v[0].z + e1 * v[1].z + e2 * v[2].z;
    let t_max = ray.t_max;
    if det < 0.0 && (t_scaled >= 0.0 || t_scaled < t_max * det) {
        return None;
    }
    if det > 0.0 && (t_scaled <= 0.0 || t_scaled > t_max * det) {
        return None;
    }
    let inv = 1.0 / det;
    let (b0, b1, b2) = (e0 * inv, e1 * inv, e2 * inv);
    let t = t_scaled * inv;
    // The error bound of t (pbrt-v4, section 6.8.7), accepted beyond it.
    let max_z = v.iter().fold(0.0_f64, |m, v| m.max(v.z.abs()));
    let max_x = v.iter().fold(0.0_f64, |m, v| m.max(v.x.abs()));
    let max_y = v.iter().fold(0.0_f64, |m, v| m.max(v.y.abs()));
    let delta_z = gamma(3) * max_z;
    let delta_x = gamma(5) * (max_x + max_z);
    let delta_y = gamma(5) * (max_y + max_z);
    let delta_e = 2.0 * (gamma(2) * max_x * max_y + delta_y * max_x + delta_x * max_y);
    let max_e = e0.abs().max(e1.abs()).max(e2.abs());
    let delta_t = 3.0 * (gamma(3) * max_e * max_z + delta_e * max_z + delta_z * max_e) * inv.abs();
    if t.is_nan() || t <= delta_t {
        return None;
    }
    let point = p[0] * b0 + p[1] * b1 + p[2] * b2;
    let error = ((p[0] * b0).abs() + (p[1] * b1).abs() + (p[2] * b2).abs()) * gamma(7);
    Some(Hit {
        t,
        point,
        error,
        normal,
    })
}
