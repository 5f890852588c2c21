//! A spherical cap `{p : |p - c| = R, angle(p - c, axis) <= theta_max}`, the
//! whole sphere when `cos theta_max = -1`: sphere lights, the cone of
//! directions a sphere subtends.
//!
//! The area-uniform (Archimedes) map, in the [`Frame`] `(s, t, n)` of the axis:
//!
//! `cos theta = 1 - u_1 (1 - cos theta_max)`, `phi = 2 pi u_2`,
//! `p(u) = c + R (sin theta cos phi s + sin theta sin phi t + cos theta n)`,
//! `|J| = R^2 sin theta |d theta/du_1| 2 pi = 2 pi R^2 (1 - cos theta_max)`,
//! constant, since `dA = R^2 d(cos theta) d phi`.
//!
//! The height `R cos theta` is linear in `u_1`, so polynomials in the axial
//! coordinate are integrated exactly by Gauss–Legendre; the transverse
//! coordinates carry `sin theta = sqrt((1 - cos theta)(1 + cos theta))`, smooth
//! inside the square but with a square-root singularity at the pole `u_1 = 0`
//! (and at the antipode `u_1 = 1` for the whole sphere).
//!
//! ```
//! use std::f64::consts::PI;
//! use lightquad::domain::{Domain, SphericalCap, Vec3, integrate_over};
//! use lightquad::quadrature::GaussLegendre;
//! use rand::SeedableRng;
//!
//! let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
//! let (c, r) = (Vec3::new(1.0, 2.0, 3.0), 0.5);
//! // A sphere light: int (z - c_z)^2 dA = 4 pi R^4 / 3; the height is linear
//! // in u_1 under the Archimedes map, so 4 x 4 nodes are exact.
//! let sphere = SphericalCap::sphere(c, r)?;
//! let est = integrate_over(&GaussLegendre::default(), &sphere, 16, &mut rng, |p: Vec3| {
//!     (p.z - c.z).powi(2)
//! })?;
//! assert!((est.value - 4.0 * PI * r.powi(4) / 3.0).abs() < 1e-14);
//! // The cap within 60 degrees of +z: area 2 pi R^2 (1 - cos 60°) = pi R^2.
//! let cap = SphericalCap::new(c, Vec3::z(), r, 0.5)?;
//! assert!((cap.measure() - PI * r * r).abs() < 1e-15);
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use super::{
    Domain, Frame, Vec3, azimuth_fraction, frame_around, invert_slack, require_finite_vec3,
    snap_unit, within,
};
use crate::error::{QuadError, require_positive};
use std::f64::consts::PI;

/// A cap of the sphere of radius `R` about `c`, around the axis `n`, of half
/// angle `theta_max` (`cos theta_max` in `[-1, 1)`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphericalCap {
    centre: Vec3,
    frame: Frame,
    radius: f64,
    cos_max: f64,
}

impl SphericalCap {
    /// The cap of the sphere about `centre` of radius `radius` around `axis`
    /// (normalised), with `cos theta_max = cos_max`: `centre` finite, `axis`
    /// finite and non-zero, `radius > 0` finite, `cos_max` in `[-1, 1)`
    /// (`-1` is the whole sphere, `1` an empty cap).
    pub fn new(centre: Vec3, axis: Vec3, radius: f64, cos_max: f64) -> Result<Self, QuadError> {
        require_finite_vec3("centre", centre)?;
        let frame = frame_around("axis", axis)?;
        require_positive("radius", radius)?;
        if !((-1.0..1.0).contains(&cos_max)) {
            return Err(QuadError::invalid(
                "cos_max",
                cos_max,
                "a number in [-1, 1) (-1 is the whole sphere; 1 would be an empty cap)",
            ));
        }
        Ok(SphericalCap {
            centre,
            frame,
            radius,
            cos_max,
        })
    }

    /// The whole sphere about `centre` of radius `radius` (axis `+z`).
    pub fn sphere(centre: Vec3, radius: f64) -> Result<Self, QuadError> {
        Self::new(centre, Vec3::z(), radius, -1.0)
    }

    /// The centre `c`.
    pub fn centre(&self) -> Vec3 {
        self.centre
    }

    /// The frame whose `n` is the cap's axis.
    pub fn frame(&self) -> Frame {
        self.frame
    }

    /// The radius `R`.
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// `cos theta_max`.
    pub fn cos_max(&self) -> f64 {
        self.cos_max
    }

    /// True when the cap is the whole sphere (`cos theta_max = -1`).
    pub fn is_sphere(&self) -> bool {
        self.cos_max == -1.0
    }
}

impl Domain<2> for SphericalCap {
    type Point = Vec3;

    /// `cos theta = 1 - u_1 (1 - cos theta_max)`, `phi = 2 pi u_2`,
    /// `|J| = 2 pi R^2 (1 - cos theta_max)`. With `w = 1 - cos theta`,
    /// `sin theta = sqrt(w (2 - w))`, free of cancellation near the pole.
    fn map(&self, u: [f64; 2]) -> (Vec3, f64) {
        let k = 1.0 - self.cos_max;
        let w = u[0] * k;
        let cos_theta = 1.0 - w;
        let sin_theta = (w * (2.0 - w)).max(0.0).sqrt();
        let (sin_phi, cos_phi) = (2.0 * PI * u[1]).sin_cos();
        let local = Vec3::new(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta);
        (
            self.centre + self.frame.to_world(local) * self.radius,
            2.0 * PI * self.radius * self.radius * k,
        )
    }

    /// With `l = (p - c) / R` in the local frame: `u_1 = (1 - l_z / |l|) /
    /// (1 - cos theta_max)`, `u_2 = atan2(l_y, l_x) / (2 pi)` in `[0, 1)`
    /// (`0` on the axis, where the azimuth is undefined); `None` when `p` is off
    /// the sphere or outside the cap by more than the tolerance.
    fn invert(&self, p: &Vec3) -> Option<[f64; 2]> {
        let slack = invert_slack(self.radius, self.centre.norm() + p.norm());
        let l = self.frame.to_local(p - self.centre) / self.radius;
        let r = l.norm();
        if !within(r - 1.0, slack) {
            return None;
        }
        let rho2 = l.x * l.x + l.y * l.y;
        // 1 - cos theta, without cancellation in the upper half.
        let w = if l.z >= 0.0 {
            rho2 / (r * (r + l.z))
        } else {
            (r - l.z) / r
        };
        let u1 = snap_unit(w / (1.0 - self.cos_max), slack)?;
        let u2 = if rho2 > 0.0 {
            azimuth_fraction(l.y, l.x)
        } else {
            0.0
        };
        Some([u1, u2])
    }

    fn measure(&self) -> f64 {
        2.0 * PI * self.radius * self.radius * (1.0 - self.cos_max)
    }
}
