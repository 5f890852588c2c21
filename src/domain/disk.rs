//! A disk of radius `R` about a centre, in the plane through it perpendicular
//! to a normal: disk lights, apertures.
//!
//! The smooth polar map, in the [`Frame`] `(s, t, n)` of the normal:
//!
//! `r = R u_1`, `phi = 2 pi u_2`, `p(u) = c + r (cos phi s + sin phi t)`,
//! `|J| = |dp/du_1 x dp/du_2| = R * 2 pi R u_1 = 2 pi R^2 u_1`.
//!
//! Why this map and not an area-preserving one: a polynomial integrand in the
//! disk's coordinates `(x, y) = r (cos phi, sin phi)` becomes, with the
//! Jacobian, a polynomial in `u_1` times a trigonometric polynomial in `u_2`.
//! Gauss–Legendre with `m` nodes per axis is exact in `u_1` up to degree
//! `2m - 1`, and the `u_2` factor is entire, so the error there falls faster
//! than any power of `m` (to rounding error for modest `m`); rotationally
//! symmetric polynomials (the area, moments of `r^2`) are integrated exactly.
//! The area-uniform map `r = R sqrt(u_1)` puts odd powers of `sqrt(u_1)` into
//! the integrand (unbounded derivative at `u_1 = 0`), and the concentric map of
//! Shirley and Chiu is only piecewise smooth (kinks on the diagonals): both cut
//! Gauss–Legendre down to algebraic convergence. Monte Carlo rules, which do
//! not care, pay for the non-uniform density with a larger variance.
//!
//! ```
//! use std::f64::consts::PI;
//! use lightquad::domain::{Disk, Domain, Vec3, integrate_over};
//! use lightquad::quadrature::GaussLegendre;
//! use rand::SeedableRng;
//!
//! // A disk light of radius 2 at height 1, facing down. Its area pi R^2 is the
//! // integral of the Jacobian 2 pi R^2 u_1, and the second moment
//! // int r^2 dA = pi R^4 / 2 is a polynomial in u_1: 8 x 8 nodes are exact.
//! let (c, radius) = (Vec3::new(0.0, 0.0, 1.0), 2.0);
//! let disk = Disk::new(c, -Vec3::z(), radius)?;
//! let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
//! let gl = GaussLegendre::default();
//! let area = integrate_over(&gl, &disk, 64, &mut rng, |_p: Vec3| 1.0)?;
//! let moment = integrate_over(&gl, &disk, 64, &mut rng, |p: Vec3| (p - c).norm_squared())?;
//! assert!((area.value - PI * radius * radius).abs() < 1e-13);
//! assert!((area.value - disk.measure()).abs() < 1e-13);
//! assert!((moment.value - PI * radius.powi(4) / 2.0).abs() < 1e-12);
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use super::{
    Domain, Frame, Vec3, azimuth_fraction, frame_around, invert_slack, require_finite_vec3,
    snap_unit, within,
};
use crate::error::{QuadError, require_positive};
use std::f64::consts::PI;

/// The disk `{c + x s + y t : x^2 + y^2 <= R^2}` about the normal `n`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Disk {
    centre: Vec3,
    frame: Frame,
    radius: f64,
}

impl Disk {
    /// The disk about `centre` perpendicular to `normal` (normalised); the
    /// centre finite, the normal finite and non-zero, `radius > 0` finite.
    pub fn new(centre: Vec3, normal: Vec3, radius: f64) -> Result<Self, QuadError> {
        require_finite_vec3("centre", centre)?;
        let frame = frame_around("normal", normal)?;
        require_positive("radius", radius)?;
        // Its area is a factor of every integral over it.
        if !(std::f64::consts::PI * radius * radius).is_finite() {
            return Err(QuadError::invalid(
                "radius",
                radius,
                "a radius whose area pi R^2 is finite in f64 (R below about 7.5e153)",
            ));
        }
        Ok(Disk {
            centre,
            frame,
            radius,
        })
    }

    /// The centre `c`.
    pub fn centre(&self) -> Vec3 {
        self.centre
    }

    /// The frame whose `n` is the disk's unit normal.
    pub fn frame(&self) -> Frame {
        self.frame
    }

    /// The radius `R`.
    pub fn radius(&self) -> f64 {
        self.radius
    }
}

impl Domain<2> for Disk {
    type Point = Vec3;

    /// `r = R u_1`, `phi = 2 pi u_2`, `p = c + r (cos phi s + sin phi t)`,
    /// `|J| = 2 pi R^2 u_1`.
    fn map(&self, u: [f64; 2]) -> (Vec3, f64) {
        let r = self.radius * u[0];
        let (sin_phi, cos_phi) = (2.0 * PI * u[1]).sin_cos();
        let p = self.centre + self.frame.s * (r * cos_phi) + self.frame.t * (r * sin_phi);
        (p, 2.0 * PI * self.radius * self.radius * u[0])
    }

    /// `u_1 = sqrt(x^2 + y^2) / R`, `u_2 = atan2(y, x) / (2 pi)` in `[0, 1)`
    /// (`0` at the centre, where the azimuth is undefined); `None` when `p` is
    /// off the plane or outside the disk by more than the tolerance.
    fn invert(&self, p: &Vec3) -> Option<[f64; 2]> {
        let slack = invert_slack(self.radius, self.centre.norm() + p.norm());
        let local = self.frame.to_local(p - self.centre);
        if !within(local.z, slack * self.radius) {
            return None;
        }
        let rho = local.x.hypot(local.y);
        let u1 = snap_unit(rho / self.radius, slack)?;
        let u2 = if rho > 0.0 {
            azimuth_fraction(local.y, local.x)
        } else {
            0.0
        };
        Some([u1, u2])
    }

    fn measure(&self) -> f64 {
        PI * self.radius * self.radius
    }
}
