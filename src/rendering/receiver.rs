//! The receiving point of R-H and R-A: a point `x` with a unit normal `n`
//! (its shading frame), where irradiance `E(x, n)` and reflected radiance
//! `L_r(x, wo)` are evaluated.
//!
//! ```
//! use lightquad::domain::Vec3;
//! use lightquad::rendering::receiver::Receiver;
//!
//! let r = Receiver::new(Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.0, 0.0, 2.0))?;
//! assert_eq!(r.normal(), Vec3::z());
//! assert!(Receiver::new(Vec3::zeros(), Vec3::zeros()).is_err());
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use crate::domain::{Frame, Hemisphere, HemisphereMap, Vec3};
use crate::error::QuadError;
use crate::geometry::require_finite_vec;

/// A point `x` on a surface with unit normal `n` and the shading frame
/// `(s, t, n)` in which BRDFs are evaluated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Receiver {
    point: Vec3,
    frame: Frame,
}

impl Receiver {
    /// The receiver at `point` (finite) with normal `normal` (finite,
    /// non-zero; normalised).
    pub fn new(point: Vec3, normal: Vec3) -> Result<Self, QuadError> {
        require_finite_vec("point", point)?;
        let frame = Frame::from_normal(normal).map_err(|_| {
            QuadError::invalid(
                "normal",
                format!("{:?}", normal.as_slice()),
                "a finite, non-zero normal",
            )
        })?;
        Ok(Receiver { point, frame })
    }

    /// The point `x`.
    pub fn point(&self) -> Vec3 {
        self.point
    }

    /// The unit normal `n`.
    pub fn normal(&self) -> Vec3 {
        self.frame.n
    }

    /// The shading frame (normal `n`).
    pub fn frame(&self) -> Frame {
        self.frame
    }

    /// The hemisphere of directions above `x` with the parameterisation
    /// `map` (the domain of R-H).
    pub fn hemisphere(&self, map: HemisphereMap) -> Hemisphere {
        Hemisphere {
            frame: self.frame,
            map,
        }
    }

    /// `cos theta = max(0, n . w)` for a unit world direction `w`.
    pub fn cos_theta(&self, w: Vec3) -> f64 {
        self.frame.n.dot(&w).max(0.0)
    }
}

/// A world direction `w` normalised, or the error naming `name` for a
/// zero or non-finite one.
pub fn unit_direction(name: &str, w: Vec3) -> Result<Vec3, QuadError> {
    crate::geometry::normalize(name, w)
}
