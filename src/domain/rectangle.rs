//! A parallelogram patch (a rectangle when its edges are perpendicular): area
//! lights, quads of a scene.
//!
//! `p(u) = o + u_1 e_1 + u_2 e_2`, `|J| = |e_1 x e_2|` (constant: the map is
//! affine, so a rule sees the integrand itself, and Gauss–Legendre integrates
//! polynomials in `p` exactly).
//!
//! ```
//! use lightquad::domain::{Rectangle, Vec3, integrate_over};
//! use lightquad::quadrature::GaussLegendre;
//! use rand::SeedableRng;
//!
//! // The quad [0, 2] x [0, 3] at z = 1: area 6, normal +z, and
//! // int x y dA = (2^2 / 2) (3^2 / 2) = 9, exact with 2 x 2 nodes (affine map).
//! let quad = Rectangle::new(Vec3::z(), Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 3.0, 0.0))?;
//! assert_eq!(quad.area(), 6.0);
//! assert_eq!(quad.normal(), Vec3::z());
//! let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
//! let est = integrate_over(&GaussLegendre::default(), &quad, 4, &mut rng, |p: Vec3| p.x * p.y)?;
//! assert!((est.value - 9.0).abs() < 1e-14);
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use super::{Domain, Vec3, invert_slack, require_finite_vec3, snap_unit, within};
use crate::error::QuadError;

/// Relative area below which two edges count as parallel: `|e_1 x e_2|` must
/// exceed `DEGENERATE_SIN |e_1| |e_2|` (the sine of the angle between them).
const DEGENERATE_SIN: f64 = 1e-12;

/// The parallelogram `{o + u_1 e_1 + u_2 e_2 : u in [0, 1]^2}`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rectangle {
    origin: Vec3,
    edge_u: Vec3,
    edge_v: Vec3,
    /// `e_1 x e_2`, cached.
    cross: Vec3,
    /// `|e_1 x e_2|`, cached.
    area: f64,
}

impl Rectangle {
    /// The parallelogram at `origin` spanned by `edge_u` and `edge_v`; all
    /// finite, the edges non-zero and not parallel (non-zero area).
    pub fn new(origin: Vec3, edge_u: Vec3, edge_v: Vec3) -> Result<Self, QuadError> {
        require_finite_vec3("origin", origin)?;
        require_finite_vec3("edge_u", edge_u)?;
        require_finite_vec3("edge_v", edge_v)?;
        // Lengths scaled first: nalgebra's norm of [1e200, 0, 0] overflows.
        let norm = crate::geometry::norm;
        let (len_u, len_v) = (norm(edge_u), norm(edge_v));
        if !(len_u > 0.0 && len_u.is_finite()) {
            return Err(QuadError::invalid(
                "edge_u",
                format!("{:?}", edge_u.as_slice()),
                if len_u > 0.0 {
                    "a vector whose length is finite in f64 (below about 1.8e308)"
                } else {
                    "a non-zero vector"
                },
            ));
        }
        if !(len_v > 0.0 && len_v.is_finite()) {
            return Err(QuadError::invalid(
                "edge_v",
                format!("{:?}", edge_v.as_slice()),
                if len_v > 0.0 {
                    "a vector whose length is finite in f64 (below about 1.8e308)"
                } else {
                    "a non-zero vector"
                },
            ));
        }
        let cross = edge_u.cross(&edge_v);
        let area = norm(cross);
        if !area.is_finite() {
            return Err(QuadError::invalid(
                "edge_v",
                format!("{:?}", edge_v.as_slice()),
                "edges whose area |edge_u x edge_v| is finite in f64 (below about 1.8e308)",
            ));
        }
        // The sine of the angle between the edges, divided in turn (the
        // product of two lengths near 1e300 overflows).
        if area / len_u / len_v <= DEGENERATE_SIN {
            return Err(QuadError::invalid(
                "edge_v",
                format!("{:?}", edge_v.as_slice()),
                format!(
                    "a vector not parallel to edge_u = {:?} (the patch has zero area)",
                    edge_u.as_slice()
                ),
            ));
        }
        Ok(Rectangle {
            origin,
            edge_u,
            edge_v,
            cross,
            area,
        })
    }

    /// The corner `p(0, 0)`.
    pub fn origin(&self) -> Vec3 {
        self.origin
    }

    /// The edge `e_1` (direction of `u_1`).
    pub fn edge_u(&self) -> Vec3 {
        self.edge_u
    }

    /// The edge `e_2` (direction of `u_2`).
    pub fn edge_v(&self) -> Vec3 {
        self.edge_v
    }

    /// The unit normal `e_1 x e_2 / |e_1 x e_2|`.
    pub fn normal(&self) -> Vec3 {
        self.cross / self.area
    }

    /// The area `|e_1 x e_2|`.
    pub fn area(&self) -> f64 {
        self.area
    }
}

impl Domain<2> for Rectangle {
    type Point = Vec3;

    /// `p = o + u_1 e_1 + u_2 e_2`, `|J| = |e_1 x e_2|`.
    fn map(&self, u: [f64; 2]) -> (Vec3, f64) {
        (
            self.origin + self.edge_u * u[0] + self.edge_v * u[1],
            self.area,
        )
    }

    /// With `d = p - o` and `n = e_1 x e_2`: `u_1 = ((d x e_2) . n) / |n|^2`,
    /// `u_2 = ((e_1 x d) . n) / |n|^2`; `None` when `p` is farther than the
    /// tolerance from the plane or outside the patch.
    fn invert(&self, p: &Vec3) -> Option<[f64; 2]> {
        let (len_u, len_v) = (self.edge_u.norm(), self.edge_v.norm());
        let size = len_u.max(len_v);
        // Rounding of the coordinates counts against the shorter edge.
        let slack = invert_slack(len_u.min(len_v), self.origin.norm() + p.norm());
        let d = p - self.origin;
        let n2 = self.area * self.area;
        let height = d.dot(&self.cross) / self.area;
        if !within(height, slack * size) {
            return None;
        }
        let u1 = d.cross(&self.edge_v).dot(&self.cross) / n2;
        let u2 = self.edge_u.cross(&d).dot(&self.cross) / n2;
        Some([snap_unit(u1, slack)?, snap_unit(u2, slack)?])
    }

    fn measure(&self) -> f64 {
        self.area
    }
}
