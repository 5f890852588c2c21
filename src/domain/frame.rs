//! An orthonormal frame: local coordinates with `z` along a given normal.
//!
//! ```
//! use lightquad::domain::{Frame, Vec3};
//!
//! // A shading frame around a normal: z along it, x and y tangent to the surface.
//! let normal = Vec3::new(1.0, 2.0, 2.0); // length 3
//! let f = Frame::from_normal(normal)?;
//! assert!((f.n - normal / 3.0).norm() < 1e-15);
//! assert!(f.s.dot(&f.t).abs() < 1e-15 && f.s.dot(&f.n).abs() < 1e-15);
//! assert!((f.s.cross(&f.t) - f.n).norm() < 1e-15); // right-handed
//! // The normal has local coordinates (0, 0, |normal|), and to_world undoes to_local.
//! assert!((f.to_local(normal) - Vec3::new(0.0, 0.0, 3.0)).norm() < 1e-14);
//! let w = Vec3::new(-0.3, 0.4, 5.0);
//! assert!((f.to_world(f.to_local(w)) - w).norm() < 1e-14);
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use super::Vec3;
use crate::error::QuadError;

/// Orthonormal basis `(s, t, n)`; local `(x, y, z)` maps to `x s + y t + z n`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// First tangent.
    pub s: Vec3,
    /// Second tangent.
    pub t: Vec3,
    /// Normal.
    pub n: Vec3,
}

impl Frame {
    /// The frame with `n = +z`.
    pub fn identity() -> Self {
        Frame {
            s: Vec3::x(),
            t: Vec3::y(),
            n: Vec3::z(),
        }
    }

    /// A frame around `normal` (normalised), tangents by the branch-free method
    /// of Duff et al., "Building an orthonormal basis, revisited" (JCGT 2017).
    pub fn from_normal(normal: Vec3) -> Result<Self, QuadError> {
        // Scale by the largest component first, so that neither huge nor tiny
        // (finite, non-zero) normals overflow or underflow in the norm.
        let largest = normal.amax();
        if !(normal.iter().all(|x| x.is_finite()) && largest > 0.0) {
            return Err(QuadError::invalid(
                "normal",
                format!("{:?}", normal.as_slice()),
                "a finite, non-zero vector",
            ));
        }
        let scaled = normal / largest;
        let n = scaled / scaled.norm();
        let sign = 1.0_f64.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let s = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = Vec3::new(b, sign + n.y * n.y * a, -n.y);
        Ok(Frame { s, t, n })
    }

    /// World vector from local coordinates.
    pub fn to_world(&self, local: Vec3) -> Vec3 {
        self.s * local.x + self.t * local.y + self.n * local.z
    }

    /// Local coordinates of a world vector.
    pub fn to_local(&self, world: Vec3) -> Vec3 {
        Vec3::new(world.dot(&self.s), world.dot(&self.t), world.dot(&self.n))
    }
}
