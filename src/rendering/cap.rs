//! A spherical cap given by its height fraction `k = 1 - cos theta_max`
//! rather than by `cos theta_max`: the visible cap of a sphere light seen
//! from a point (a domain of R-A), and the cone of directions a light
//! subtends (a cap of the unit sphere about the origin, whose points are
//! directions and whose area is solid angle: a domain of R-H).
//!
//! The map is the area-uniform (Archimedes) map of
//! [`crate::domain::SphericalCap`]:
//!
//! `1 - cos theta = u_1 k`, `phi = 2 pi u_2`, `sin theta = sqrt(w (2 - w))`
//! with `w = u_1 k`, `|J| = 2 pi R^2 k`, constant.
//!
//! Why not [`crate::domain::SphericalCap`] itself: it takes `cos theta_max`
//! and forms `k = 1 - cos theta_max`, which for a small cap (a sphere light
//! of radius `R` at distance `d`, `k ~ (R/d)^2 / 2`) keeps only an absolute
//! precision of `eps`: a relative error `eps / k` in the cap's measure and
//! in every node (`2e-10` at `R/d = 1e-3`). Here `k` is computed by the
//! caller without cancellation (`k = s^2 / (1 + sqrt((1 - s)(1 + s)))` from
//! `s = sin theta_max`, see [`one_minus_cos_from_sin`]) and stored.
//!
//! ```
//! use std::f64::consts::PI;
//! use lightquad::domain::{Domain, Vec3, integrate_over};
//! use lightquad::quadrature::GaussLegendre;
//! use lightquad::rendering::cap::{Cap, one_minus_cos_from_sin};
//! use rand::SeedableRng;
//!
//! // The cone of directions a sphere of radius 1e-4 subtends at distance 1:
//! // its solid angle 2 pi (1 - cos alpha) ~ pi 1e-8, to full precision.
//! let k = one_minus_cos_from_sin(1e-4)?;
//! let cone = Cap::directions(Vec3::z(), k)?;
//! let exact = 2.0 * PI * 1e-8 / (1.0 + (1.0 - 1e-8f64).sqrt());
//! assert!((cone.measure() / exact - 1.0).abs() < 1e-15);
//! // int cos theta d omega over the cone = pi sin^2 alpha (Nusselt).
//! let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
//! let e = integrate_over(&GaussLegendre::default(), &cone, 16, &mut rng, |w: Vec3| w.z)?;
//! assert!((e.value / (PI * 1e-8) - 1.0).abs() < 1e-14);
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use std::f64::consts::PI;

use crate::domain::{Domain, Frame, INVERT_TOL, Vec3};
use crate::error::{QuadError, require_positive};

/// `1 - cos theta` for `sin theta = s` in `(0, 1]`, `theta <= pi/2`,
/// without cancellation: `s^2 / (1 + sqrt((1 - s)(1 + s)))`.
pub fn one_minus_cos_from_sin(s: f64) -> Result<f64, QuadError> {
    if !(s.is_finite() && s > 0.0 && s <= 1.0) {
        return Err(QuadError::invalid("sin_alpha", s, "a number in (0, 1]"));
    }
    Ok(s * s / (1.0 + ((1.0 - s) * (1.0 + s)).sqrt()))
}

/// `1 - cos theta` between two unit vectors, `|a - b|^2 / 2`: exact to
/// rounding for small angles, where `1 - a . b` cancels.
pub fn one_minus_cos_between(a: Vec3, b: Vec3) -> f64 {
    (a - b).norm_squared() / 2.0
}

/// The cap `{c + R w : |w| = 1, 1 - w . axis <= k}` of the sphere about `c`
/// of radius `R`, `k = 1 - cos theta_max` in `(0, 2]` (`2` is the whole
/// sphere).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cap {
    centre: Vec3,
    frame: Frame,
    radius: f64,
    k: f64,
}

impl Cap {
    /// The cap of the sphere about `centre` of radius `radius` around `axis`
    /// (normalised) with `1 - cos theta_max = one_minus_cos` in `(0, 2]`.
    pub fn new(
        centre: Vec3,
        axis: Vec3,
        radius: f64,
        one_minus_cos: f64,
    ) -> Result<Self, QuadError> {
        crate::geometry::require_finite_vec("centre", centre)?;
        let frame = Frame::from_normal(axis).map_err(|_| {
            QuadError::invalid(
                "axis",
                format!("{:?}", axis.as_slice()),
                "a finite, non-zero vector",
            )
        })?;
        require_positive("radius", radius)?;
        if !(one_minus_cos.is_finite() && one_minus_cos > 0.0 && one_minus_cos <= 2.0) {
            return Err(QuadError::invalid(
                "one_minus_cos",
                one_minus_cos,
                "1 - cos theta_max in (0, 2] (2 is the whole sphere)",
            ));
        }
        Ok(Cap {
            centre,
            frame,
            radius,
            k: one_minus_cos,
        })
    }

    /// The cone of directions within `theta_max` of `axis`, `1 - cos
    /// theta_max = one_minus_cos`: the cap of the unit sphere about the
    /// origin, whose points are unit directions and whose measure is solid
    /// angle.
    pub fn directions(axis: Vec3, one_minus_cos: f64) -> Result<Self, QuadError> {
        Self::new(Vec3::zeros(), axis, 1.0, one_minus_cos)
    }

    /// The centre of the sphere.
    pub fn centre(&self) -> Vec3 {
        self.centre
    }

    /// The unit axis.
    pub fn axis(&self) -> Vec3 {
        self.frame.n
    }

    /// The frame whose `n` is the axis.
    pub fn frame(&self) -> Frame {
        self.frame
    }

    /// The radius `R`.
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// `k = 1 - cos theta_max`.
    pub fn one_minus_cos(&self) -> f64 {
        self.k
    }

    /// True when the unit direction `w` lies in the cone of directions of
    /// this cap (`1 - w . axis <= k`, in the cancellation-free form).
    pub fn contains_direction(&self, w: Vec3) -> bool {
        one_minus_cos_between(w, self.frame.n) <= self.k
    }
}

impl Domain<2> for Cap {
    type Point = Vec3;

    /// `w = u_1 k`, `cos theta = 1 - w`, `sin theta = sqrt(w (2 - w))`,
    /// `phi = 2 pi u_2`, `p = c + R (sin theta cos phi s + sin theta sin phi
    /// t + cos theta n)`, `|J| = 2 pi R^2 k`.
    fn map(&self, u: [f64; 2]) -> (Vec3, f64) {
        let w = u[0] * self.k;
        let cos_theta = 1.0 - w;
        let sin_theta = (w * (2.0 - w)).max(0.0).sqrt();
        let (sin_phi, cos_phi) = (2.0 * PI * u[1]).sin_cos();
        let local = Vec3::new(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta);
        (
            self.centre + self.frame.to_world(local) * self.radius,
            2.0 * PI * self.radius * self.radius * self.k,
        )
    }

    /// `u_1 = (1 - cos theta) / k` with `1 - cos theta = rho^2 / (r (r +
    /// l_z))` in the upper half (no cancellation near the pole), `u_2 =
    /// atan2(l_y, l_x) / (2 pi)`; `None` off the sphere or outside the cap
    /// by more than [`INVERT_TOL`] (relative).
    fn invert(&self, p: &Vec3) -> Option<[f64; 2]> {
        let l = self.frame.to_local(p - self.centre) / self.radius;
        let r = l.norm();
        let slack =
            INVERT_TOL + 64.0 * f64::EPSILON * (self.centre.norm() + p.norm()) / self.radius;
        if (r - 1.0).abs() > slack || r.is_nan() {
            return None;
        }
        let rho2 = l.x * l.x + l.y * l.y;
        let w = if l.z >= 0.0 {
            rho2 / (r * (r + l.z))
        } else {
            (r - l.z) / r
        };
        let u1 = w / self.k;
        // A point `delta R` beyond the rim at angle theta_max ~ sqrt(2 k) has
        // u_1 ~ 1 + delta sqrt(2 / k).
        if u1 > 1.0 + slack * (2.0 / self.k).sqrt().max(1.0) || u1.is_nan() {
            return None;
        }
        let phi = l.y.atan2(l.x);
        let u2 = if rho2 > 0.0 {
            (if phi < 0.0 { phi + 2.0 * PI } else { phi }) / (2.0 * PI)
        } else {
            0.0
        };
        Some([u1.clamp(0.0, 1.0), u2.clamp(0.0, 1.0)])
    }

    /// `2 pi R^2 k`.
    fn measure(&self) -> f64 {
        2.0 * PI * self.radius * self.radius * self.k
    }
}
