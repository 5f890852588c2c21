//! The documents' worked medium: a sphere of constant density `kappa`
//! (docs/EQUATIONS.md, V-tau: `sigma = lambda kappa` inside, 0 outside).
//!
//! ```
//! use lightquad::domain::Vec3;
//! use lightquad::geometry::Ray;
//! use lightquad::volume::{ConstantSphere, Medium};
//!
//! // kappa inside, 0 outside. Along a ray at distance h from the centre the
//! // support is the chord of length 2 sqrt(R^2 - h^2), and the line integral
//! // is kappa times it.
//! let (radius, kappa, h) = (2.0, 0.75, 1.2);
//! let sphere = ConstantSphere::new(Vec3::new(0.0, 0.0, 5.0), radius, kappa)?;
//! assert_eq!(sphere.density(Vec3::new(0.0, 1.0, 5.0)), kappa);
//! assert_eq!(sphere.density(Vec3::zeros()), 0.0);
//! let ray = Ray::new(Vec3::new(-10.0, h, 5.0), Vec3::x())?;
//! let chord = 2.0 * (radius * radius - h * h).sqrt(); // 3.2
//! let support = sphere.support(&ray, 0.0, f64::INFINITY);
//! assert_eq!(support.len(), 1);
//! assert!((support[0].start() - (10.0 - chord / 2.0)).abs() < 1e-14);
//! assert!((support[0].end() - (10.0 + chord / 2.0)).abs() < 1e-14);
//! let depth = sphere.density_integral(&ray, 0.0, 20.0).ok_or("no closed form")?;
//! assert!((depth - kappa * chord).abs() < 1e-14); // tau = exp(-lambda depth)
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use super::medium::Medium;
use crate::domain::{Segment, Vec3};
use crate::error::QuadError;
use crate::geometry::{Ray, Sphere};

/// `v_r = kappa` inside the sphere, 0 outside.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConstantSphere {
    /// The sphere.
    pub sphere: Sphere,
    /// The density inside.
    pub kappa: f64,
}

impl ConstantSphere {
    /// A constant-density sphere; `kappa` finite and >= 0, and 0 or a normal
    /// f64: a subnormal density (1e-320) keeps a few bits, and the closed
    /// form `c (1 - e^(-kappa L)) / kappa` built from it was off by 1.2e-4
    /// while every rule had `c L` exactly.
    pub fn new(centre: Vec3, radius: f64, kappa: f64) -> Result<Self, QuadError> {
        if !(kappa.is_finite() && (kappa == 0.0 || kappa >= f64::MIN_POSITIVE)) {
            return Err(QuadError::invalid(
                "kappa",
                kappa,
                format!(
                    "a finite density >= 0: 0 or at least {:e} (a normal f64; a subnormal one keeps too few digits)",
                    f64::MIN_POSITIVE
                ),
            ));
        }
        Ok(ConstantSphere {
            sphere: Sphere::new(centre, radius)?,
            kappa,
        })
    }
}

impl Medium for ConstantSphere {
    fn name(&self) -> &'static str {
        "constant-sphere"
    }

    fn density(&self, p: Vec3) -> f64 {
        if crate::geometry::norm(p - self.sphere.centre) <= self.sphere.radius {
            self.kappa
        } else {
            0.0
        }
    }

    /// `kappa` on a piece inside the sphere, whatever side of the surface
    /// rounding puts `p` on.
    fn density_on(&self, _p: Vec3, inside: Vec3) -> f64 {
        self.density(inside)
    }

    fn support(&self, ray: &Ray, t_min: f64, t_max: f64) -> Vec<Segment> {
        self.sphere
            .clip(ray, t_min, t_max)
            .and_then(|(a, b)| Segment::new(a, b).ok())
            .into_iter()
            .collect()
    }

    /// None: the density is constant on the chord, it crosses no level
    /// inside it.
    fn level_crossings(
        &self,
        _ray: &Ray,
        _lo: f64,
        _hi: f64,
        _inside: Vec3,
        _level: f64,
    ) -> Option<Vec<f64>> {
        Some(Vec::new())
    }

    fn centre(&self) -> Option<Vec3> {
        Some(self.sphere.centre)
    }

    fn max_density(&self, _ray: &Ray, _t0: f64, _t1: f64) -> f64 {
        self.kappa
    }

    /// `kappa` where `[t0, t1]` lies inside the sphere, else 0.
    fn min_density(&self, ray: &Ray, t0: f64, t1: f64) -> f64 {
        if self.sphere.clip(ray, t0, t1) == Some((t0, t1)) {
            self.kappa
        } else {
            0.0
        }
    }

    /// `kappa` times the chord length inside `[t0, t1]`.
    fn density_integral(&self, ray: &Ray, t0: f64, t1: f64) -> Option<f64> {
        Some(
            self.sphere
                .clip(ray, t0, t1)
                .map_or(0.0, |(a, b)| self.kappa * (b - a)),
        )
    }
}
