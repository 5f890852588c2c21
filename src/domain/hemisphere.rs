//! The hemisphere of directions around a normal, measured in solid angle (or,
//! with [`HemisphereMap::Projected`], in projected solid angle `cos theta d omega`).
//!
//! ```
//! use std::f64::consts::PI;
//! use lightquad::domain::{Domain, Hemisphere, Vec3, integrate_over};
//! use lightquad::quadrature::GaussLegendre;
//! use rand::SeedableRng;
//!
//! let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
//! let gl = GaussLegendre::default();
//! // Uniform map: int cos^2 theta d omega = 2 pi / 3 (cos theta = u_1, a polynomial).
//! let uniform = Hemisphere::uniform();
//! assert!((uniform.measure() - 2.0 * PI).abs() < 1e-15);
//! let est = integrate_over(&gl, &uniform, 16, &mut rng, |w: Vec3| w.z * w.z)?;
//! assert!((est.value - 2.0 * PI / 3.0).abs() < 1e-13);
//! // Projected solid angle: the irradiance of a uniform sky of radiance L,
//! // E = int L cos theta d omega = pi L, with the cosine in the measure.
//! let radiance = 0.7;
//! let irradiance = integrate_over(&gl, &Hemisphere::projected(), 4, &mut rng, |_w: Vec3| radiance)?;
//! assert!((irradiance.value - PI * radiance).abs() < 1e-14);
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use super::{Domain, Frame, Vec3};
use std::f64::consts::PI;

/// How `[0, 1]^2` is mapped onto the hemisphere.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HemisphereMap {
    /// `cos theta = u_1`, `phi = 2 pi u_2`: uniform in solid angle, `|J| = 2 pi`.
    Uniform,
    /// Malley's map: `sin theta = sqrt(u_1)`, `phi = 2 pi u_2`; density
    /// `cos theta / pi`, so `|J| = pi / cos theta`. A cosine-weighted integrand
    /// `g(w) cos theta` becomes `pi g(w)` in `u`. The Jacobian is infinite on
    /// the rim (`u_1 = 1`): rules with a node there (the trapezoid rule) get an
    /// infinite integrand unless `g` carries the `cos theta`; use `Projected`.
    Cosine,
    /// Malley's map measured in projected solid angle `cos theta d omega`:
    /// `|J| = pi`, constant, so `int g(w) cos theta d omega` is integrated as
    /// `int g(w) d omega_perp` with `g` free of the cosine, and rules with
    /// nodes on the rim are safe. `measure()` is `pi`.
    Projected,
}

/// The hemisphere `{w : w . n >= 0}` of unit directions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hemisphere {
    /// Frame whose `n` is the pole.
    pub frame: Frame,
    /// The parameterisation.
    pub map: HemisphereMap,
}

impl Hemisphere {
    /// The upper hemisphere about `+z`, uniform map.
    pub fn uniform() -> Self {
        Hemisphere {
            frame: Frame::identity(),
            map: HemisphereMap::Uniform,
        }
    }

    /// The upper hemisphere about `+z` in projected solid angle (Malley's map,
    /// constant Jacobian `pi`).
    pub fn projected() -> Self {
        Hemisphere {
            frame: Frame::identity(),
            map: HemisphereMap::Projected,
        }
    }

    /// The upper hemisphere about `+z`, cosine-weighted map.
    pub fn cosine() -> Self {
        Hemisphere {
            frame: Frame::identity(),
            map: HemisphereMap::Cosine,
        }
    }
}

impl Domain<2> for Hemisphere {
    type Point = Vec3;

    /// `w = sin theta cos phi s + sin theta sin phi t + cos theta n`,
    /// `phi = 2 pi u_2`, `theta` and `|J|` as [`HemisphereMap`] says.
    fn map(&self, u: [f64; 2]) -> (Vec3, f64) {
        let phi = 2.0 * PI * u[1];
        let (sin_phi, cos_phi) = phi.sin_cos();
        let (sin_theta, cos_theta, jacobian) = match self.map {
            HemisphereMap::Uniform => {
                let z = u[0];
                // sin = sqrt((1 - z)(1 + z)), no cancellation for z near 1.
                ((1.0 - z).max(0.0).sqrt() * (1.0 + z).sqrt(), z, 2.0 * PI)
            }
            HemisphereMap::Cosine => {
                let z = (1.0 - u[0]).max(0.0).sqrt();
                (u[0].sqrt(), z, PI / z)
            }
            HemisphereMap::Projected => {
                let z = (1.0 - u[0]).max(0.0).sqrt();
                (u[0].sqrt(), z, PI)
            }
        };
        let local = Vec3::new(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta);
        (self.frame.to_world(local), jacobian)
    }

    /// `u_1 = cos theta` (uniform) or `sin^2 theta` (cosine), `u_2 = atan2(w_t,
    /// w_s) / (2 pi)` in `[0, 1)`; `None` below the horizon or off the unit
    /// sphere by more than [`INVERT_TOL`](super::INVERT_TOL).
    fn invert(&self, w: &Vec3) -> Option<[f64; 2]> {
        let l = self.frame.to_local(*w);
        if !(l.z >= 0.0 && super::within(l.norm() - 1.0, super::INVERT_TOL)) {
            return None;
        }
        // Rounding can put `cos theta` or `sin^2 theta` a few ulps above 1.
        let u1 = match self.map {
            HemisphereMap::Uniform => l.z,
            HemisphereMap::Cosine | HemisphereMap::Projected => l.x * l.x + l.y * l.y,
        }
        .min(1.0);
        Some([u1, super::azimuth_fraction(l.y, l.x)])
    }

    fn measure(&self) -> f64 {
        match self.map {
            HemisphereMap::Projected => PI,
            _ => 2.0 * PI,
        }
    }
}
