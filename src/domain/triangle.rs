//! A triangle `abc`: mesh faces, triangle lights.
//!
//! The collapsed-square (Duffy) map: the edge `u_1 = 0` of the square collapses
//! onto the vertex `a`, and each segment `u_1 = const` runs parallel to `bc`:
//!
//! `p(u) = a + u_1 (b - a) + u_1 u_2 (c - b)`,
//! `dp/du_1 = (b - a) + u_2 (c - b)`, `dp/du_2 = u_1 (c - b)`,
//! `|J| = u_1 |(b - a) x (c - b)| = 2 A u_1`, `A` the area.
//!
//! The map is polynomial (bilinear), so a polynomial integrand of degree `k` in
//! `p` becomes a polynomial of degree `k + 1` in `u_1` and `k` in `u_2`, which
//! Gauss–Legendre with `m >= (k + 2) / 2` nodes per axis integrates exactly; a
//! smooth integrand stays smooth, with no singularity at the collapsed vertex.
//!
//! ```
//! use lightquad::domain::{Domain, Triangle, Vec3, integrate_over};
//! use lightquad::quadrature::GaussLegendre;
//! use rand::SeedableRng;
//!
//! // The right triangle (0,0), (2,0), (0,1): area 1, centroid x = 2/3, so
//! // int x dA = 2/3; after the Duffy map it is a polynomial of degree 2 in u_1.
//! let tri = Triangle::new(Vec3::zeros(), Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0))?;
//! assert!((tri.area() - 1.0).abs() < 1e-15);
//! let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
//! let est = integrate_over(&GaussLegendre::default(), &tri, 4, &mut rng, |p: Vec3| p.x)?;
//! assert!((est.value - 2.0 / 3.0).abs() < 1e-15);
//! // map and invert are inverses.
//! let (p, _jacobian) = tri.map([0.5, 0.25]);
//! let u = tri.invert(&p).ok_or("off the triangle")?;
//! assert!((u[0] - 0.5).abs() < 1e-12 && (u[1] - 0.25).abs() < 1e-12);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use super::{Domain, Vec3, invert_slack, require_finite_vec3, snap_unit, within};
use crate::error::QuadError;

/// Relative area below which a triangle counts as degenerate:
/// `|(b - a) x (c - b)|` must exceed `DEGENERATE_SIN |b - a| |c - b|`.
const DEGENERATE_SIN: f64 = 1e-12;

/// The triangle with vertices `a`, `b`, `c`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Triangle {
    a: Vec3,
    b: Vec3,
    c: Vec3,
    /// `(b - a) x (c - b)`, cached.
    cross: Vec3,
    /// `|(b - a) x (c - b)|`, twice the area, cached.
    double_area: f64,
}

impl Triangle {
    /// The triangle `abc`; vertices finite, `b != a`, and `c` not on the line
    /// through `a` and `b` (non-zero area).
    pub fn new(a: Vec3, b: Vec3, c: Vec3) -> Result<Self, QuadError> {
        require_finite_vec3("a", a)?;
        require_finite_vec3("b", b)?;
        require_finite_vec3("c", c)?;
        let (ab, bc) = (b - a, c - b);
        // Lengths scaled first: nalgebra's norm of [1e200, 0, 0] overflows.
        let norm = crate::geometry::norm;
        let (len_ab, len_bc) = (norm(ab), norm(bc));
        let cross = ab.cross(&bc);
        let double_area = norm(cross);
        if !(len_ab.is_finite() && len_bc.is_finite() && double_area.is_finite()) {
            return Err(QuadError::invalid(
                "c",
                format!("{:?}", c.as_slice()),
                format!(
                    "vertices whose edges and area are finite in f64 (below about 1.8e308) with \
                     a = {:?} and b = {:?}",
                    a.as_slice(),
                    b.as_slice()
                ),
            ));
        }
        if len_ab == 0.0 {
            return Err(QuadError::invalid(
                "b",
                format!("{:?}", b.as_slice()),
                format!(
                    "a point distinct from a = {:?} (the triangle has zero area)",
                    a.as_slice()
                ),
            ));
        }
        // The sine of the angle at b, divided in turn (the product of two
        // lengths near 1e300 overflows).
        if len_bc == 0.0 || double_area / len_ab / len_bc <= DEGENERATE_SIN {
            return Err(QuadError::invalid(
                "c",
                format!("{:?}", c.as_slice()),
                format!(
                    "a point off the line through a = {:?} and b = {:?} (the triangle has zero area)",
                    a.as_slice(),
                    b.as_slice()
                ),
            ));
        }
        Ok(Triangle {
            a,
            b,
            c,
            cross,
            double_area,
        })
    }

    /// The vertices `[a, b, c]`.
    pub fn vertices(&self) -> [Vec3; 3] {
        [self.a, self.b, self.c]
    }

    /// The unit normal `(b - a) x (c - a) / |(b - a) x (c - a)|`.
    pub fn normal(&self) -> Vec3 {
        self.cross / self.double_area
    }

    /// The area `|(b - a) x (c - a)| / 2`.
    pub fn area(&self) -> f64 {
        0.5 * self.double_area
    }
}

impl Domain<2> for Triangle {
    type Point = Vec3;

    /// `p = a + u_1 (b - a) + u_1 u_2 (c - b)`, `|J| = u_1 |(b - a) x (c - b)|`.
    fn map(&self, u: [f64; 2]) -> (Vec3, f64) {
        let p = self.a + (self.b - self.a) * u[0] + (self.c - self.b) * (u[0] * u[1]);
        (p, u[0] * self.double_area)
    }

    /// With `d = p - a`, `n = (b - a) x (c - b)`, write `d = s (b - a) + t (c - b)`:
    /// `s = ((d x (c - b)) . n) / |n|^2`, `t = (((b - a) x d) . n) / |n|^2`;
    /// then `u_1 = s`, `u_2 = t / s` (`0` at the vertex `a`, where it is
    /// undefined). `None` when `p` is off the plane or outside `0 <= t <= s <= 1`
    /// by more than the tolerance.
    fn invert(&self, p: &Vec3) -> Option<[f64; 2]> {
        let (ab, bc) = (self.b - self.a, self.c - self.b);
        let edges = [ab.norm(), bc.norm(), (self.a - self.c).norm()];
        let size = edges.iter().fold(0.0_f64, |m, &e| m.max(e));
        let shortest = edges.iter().fold(f64::INFINITY, |m, &e| m.min(e));
        let slack = invert_slack(shortest, self.a.norm() + p.norm());
        let d = p - self.a;
        let height = d.dot(&self.cross) / self.double_area;
        if !within(height, slack * size) {
            return None;
        }
        let n2 = self.double_area * self.double_area;
        let s = d.cross(&bc).dot(&self.cross) / n2;
        let t = ab.cross(&d).dot(&self.cross) / n2;
        if !(-slack <= t && t <= s + slack) {
            return None;
        }
        let u1 = snap_unit(s, slack)?;
        let u2 = if u1 > 0.0 {
            (t / u1).clamp(0.0, 1.0)
        } else {
            0.0
        };
        Some([u1, u2])
    }

    fn measure(&self) -> f64 {
        0.5 * self.double_area
    }
}
