//! [`SphereLight`]: a Lambertian sphere light, seen as the cap of it
//! visible from the receiver.

use crate::domain::Vec3;
use crate::error::QuadError;
use crate::geometry::Sphere;
use crate::rendering::cap::{Cap, one_minus_cos_from_sin};
use crate::rendering::occluder::Occluder;
use crate::rendering::receiver::Receiver;
use crate::value::Value;

use super::{Emitter, EmitterHit, LightDomain, RIM_TOL, check_radiance};

/// A Lambertian sphere light: every point of the sphere emits `L_e`
/// outward.
///
/// Seen from `x` at distance `d > R` from the centre, the sphere's visible
/// part is the cap about the axis toward `x` with `cos theta_max = R / d`
/// (the points whose tangent plane separates them from `x`), and it covers
/// the cone of directions `sin alpha = R / d`. A fully visible sphere
/// (above the receiver's horizon, `cos omega >= sin alpha`) gives the
/// irradiance `E = pi L (R/d)^2 cos omega`
/// ([`crate::exact::rendering::spherical_cap_irradiance`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphereLight<V: Value> {
    shape: Sphere,
    radiance: V,
}

impl<V: Value> SphereLight<V> {
    /// The same light with radiance `radiance` (for the converged
    /// reference, which evaluates each light at radiance 1 and scales: `E`
    /// is linear in `L_e`).
    pub(crate) fn with_radiance(self, radiance: V) -> Self {
        Self { radiance, ..self }
    }

    /// The sphere about `centre` (finite) of radius `radius` (finite, `> 0`)
    /// of radiance `radiance`.
    pub fn new(centre: Vec3, radius: f64, radiance: V) -> Result<Self, QuadError> {
        Ok(SphereLight {
            shape: Sphere::new(centre, radius)?,
            radiance: check_radiance("radiance", radiance)?,
        })
    }

    /// The sphere.
    pub fn shape(&self) -> &Sphere {
        &self.shape
    }

    /// The distance `d` from `x` to the centre and the unit axis from the
    /// centre toward `x`; an error naming `point` for `x` inside or on the
    /// sphere (the sphere emits outward only).
    fn outside(&self, x: Vec3) -> Result<(f64, Vec3), QuadError> {
        let from_centre = x - self.shape.centre;
        let d = from_centre.norm();
        if d <= self.shape.radius || d.is_nan() {
            return Err(QuadError::invalid(
                "point",
                format!("{:?}", x.as_slice()),
                format!(
                    "a receiver outside the sphere light (centre {:?}, radius {})",
                    self.shape.centre.as_slice(),
                    self.shape.radius
                ),
            ));
        }
        Ok((d, from_centre / d))
    }
}

impl<V: Value> Emitter<V> for SphereLight<V> {
    fn radiance(&self) -> V {
        self.radiance
    }

    /// The nearer root of the robust ray–sphere roots beyond `t_min`: `L_e`
    /// when it is the entering root (`x` outside), zero from inside. A ray
    /// that misses by at most `RIM_TOL R + 16 eps d` (`d = |c - x|`: the
    /// rounding of a unit direction, `~eps` rad, moves the ray by `eps d` at
    /// the sphere) touches the sphere at the foot of the perpendicular from
    /// the centre, `t = (c - x) . w`.
    fn hit(&self, x: Vec3, w: Vec3, t_min: f64) -> Option<EmitterHit<V>> {
        let Some((t0, t1)) = self.shape.line_roots(x, w) else {
            let to_centre = self.shape.centre - x;
            let t = to_centre.dot(&w);
            let h = (to_centre - w * t).norm();
            let slack = self.shape.radius * RIM_TOL + 16.0 * f64::EPSILON * to_centre.norm();
            return (h <= self.shape.radius + slack && t > t_min).then_some(EmitterHit {
                distance: t,
                radiance: self.radiance,
            });
        };
        if t0 > t_min {
            Some(EmitterHit {
                distance: t0,
                radiance: self.radiance,
            })
        } else if t1 > t_min {
            Some(EmitterHit {
                distance: t1,
                radiance: V::zero(),
            })
        } else {
            None
        }
    }

    /// The cap visible from `x`: axis `(x - c)/d`, `1 - cos theta_max = (d -
    /// R)/d`, uniform in area, `|J| = 2 pi R^2 (d - R)/d`.
    fn surface(&self, receiver: &Receiver) -> Result<LightDomain, QuadError> {
        let (d, axis) = self.outside(receiver.point())?;
        let k = (d - self.shape.radius) / d;
        Ok(LightDomain::Cap(Cap::new(
            self.shape.centre,
            axis,
            self.shape.radius,
            k,
        )?))
    }

    fn normal_at(&self, y: Vec3) -> Vec3 {
        (y - self.shape.centre) / self.shape.radius
    }

    /// `sin alpha = R / d`, `1 - cos alpha = s^2 / (1 + sqrt((1 - s)(1 +
    /// s)))`, about the axis toward the centre.
    fn cone(&self, receiver: &Receiver) -> Result<Cap, QuadError> {
        let (d, axis) = self.outside(receiver.point())?;
        Cap::directions(-axis, one_minus_cos_from_sin(self.shape.radius / d)?)
    }

    fn occluder(&self) -> Option<Occluder> {
        Some(Occluder::Sphere(self.shape))
    }
}
