//! Lights at infinity: [`EnvironmentLight`] (uniform radiance from every
//! direction) and [`CapLight`] (uniform radiance from a cone of directions:
//! a distant sphere, the sun).

use crate::domain::Vec3;
use crate::error::QuadError;
use crate::geometry::normalize;
use crate::rendering::cap::{Cap, one_minus_cos_between, one_minus_cos_from_sin};
use crate::rendering::occluder::Occluder;
use crate::rendering::receiver::Receiver;
use crate::value::Value;

use super::{Emitter, EmitterHit, LightDomain, RIM_TOL, check_radiance};

/// A uniform environment: radiance `L_e` arrives from every direction that
/// no surface of the scene blocks. Over an unblocked hemisphere `E = pi L_e`.
///
/// Its domain for R-A and its cone are the receiver's hemisphere of
/// directions (uniform map; the lower hemisphere adds nothing to R-H).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnvironmentLight<V: Value> {
    radiance: V,
}

impl<V: Value> EnvironmentLight<V> {
    /// The same light with radiance `radiance` (for the converged
    /// reference, which evaluates each light at radiance 1 and scales: `E`
    /// is linear in `L_e`).
    pub(crate) fn with_radiance(self, radiance: V) -> Self {
        Self { radiance }
    }

    /// The environment of radiance `radiance` (finite, `>= 0`).
    pub fn new(radiance: V) -> Result<Self, QuadError> {
        Ok(EnvironmentLight {
            radiance: check_radiance("radiance", radiance)?,
        })
    }
}

impl<V: Value> Emitter<V> for EnvironmentLight<V> {
    fn radiance(&self) -> V {
        self.radiance
    }

    fn at_infinity(&self) -> bool {
        true
    }

    fn hit(&self, _: Vec3, _: Vec3, _: f64) -> Option<EmitterHit<V>> {
        Some(EmitterHit {
            distance: f64::INFINITY,
            radiance: self.radiance,
        })
    }

    /// The hemisphere about the receiver's normal, `|J| = 2 pi`.
    fn surface(&self, receiver: &Receiver) -> Result<LightDomain, QuadError> {
        Ok(LightDomain::Cap(self.cone(receiver)?))
    }

    fn normal_at(&self, y: Vec3) -> Vec3 {
        -y
    }

    fn cone(&self, receiver: &Receiver) -> Result<Cap, QuadError> {
        Cap::directions(receiver.normal(), 1.0)
    }

    fn occluder(&self) -> Option<Occluder> {
        None
    }
}

/// A spherical-cap light: uniform radiance `L_e` from the directions
/// within `alpha` of `axis`, at infinity (a distant sphere light of angular
/// radius `alpha`). `E / L_e = int_cap max(0, cos theta) d omega`, `pi sin^2
/// alpha cos omega` when the cap is above the horizon, Snyder's formula when
/// it crosses it ([`crate::exact::rendering::spherical_cap_irradiance`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CapLight<V: Value> {
    cone: Cap,
    radiance: V,
}

impl<V: Value> CapLight<V> {
    /// The same light with radiance `radiance` (for the converged
    /// reference, which evaluates each light at radiance 1 and scales: `E`
    /// is linear in `L_e`).
    pub(crate) fn with_radiance(self, radiance: V) -> Self {
        Self { radiance, ..self }
    }

    /// The light of half-angle `half_angle` in `(0, pi]` about `axis`
    /// (finite, non-zero), `1 - cos alpha = 2 sin^2(alpha / 2)` without
    /// cancellation.
    pub fn new(axis: Vec3, half_angle: f64, radiance: V) -> Result<Self, QuadError> {
        if !(half_angle.is_finite() && half_angle > 0.0 && half_angle <= std::f64::consts::PI) {
            return Err(QuadError::invalid(
                "half_angle",
                half_angle,
                "an angle in (0, pi]",
            ));
        }
        let s = (half_angle / 2.0).sin();
        let axis = normalize("axis", axis)?;
        Ok(CapLight {
            cone: Cap::directions(axis, 2.0 * s * s)?,
            radiance: check_radiance("radiance", radiance)?,
        })
    }

    /// The light a sphere of radius `radius` at distance `distance` (`>
    /// radius`) along `axis` subtends: `sin alpha = radius / distance`.
    pub fn subtended(
        axis: Vec3,
        radius: f64,
        distance: f64,
        radiance: V,
    ) -> Result<Self, QuadError> {
        crate::error::require_positive("radius", radius)?;
        crate::error::require_positive("distance", distance)?;
        if distance <= radius {
            return Err(QuadError::invalid(
                "distance",
                distance,
                format!("a distance > radius = {radius}"),
            ));
        }
        let axis = normalize("axis", axis)?;
        Ok(CapLight {
            cone: Cap::directions(axis, one_minus_cos_from_sin(radius / distance)?)?,
            radiance: check_radiance("radiance", radiance)?,
        })
    }

    /// The cone of directions.
    pub fn cap(&self) -> &Cap {
        &self.cone
    }
}

impl<V: Value> Emitter<V> for CapLight<V> {
    fn radiance(&self) -> V {
        self.radiance
    }

    fn at_infinity(&self) -> bool {
        true
    }

    /// `w` within the cone, `1 - w . axis <= (1 + RIM_TOL) k`.
    fn hit(&self, _: Vec3, w: Vec3, _: f64) -> Option<EmitterHit<V>> {
        let k = self.cone.one_minus_cos() * (1.0 + RIM_TOL);
        (one_minus_cos_between(w, self.cone.axis()) <= k).then_some(EmitterHit {
            distance: f64::INFINITY,
            radiance: self.radiance,
        })
    }

    /// The cone of directions, uniform in solid angle.
    fn surface(&self, _: &Receiver) -> Result<LightDomain, QuadError> {
        Ok(LightDomain::Cap(self.cone))
    }

    fn normal_at(&self, y: Vec3) -> Vec3 {
        -y
    }

    fn cone(&self, _: &Receiver) -> Result<Cap, QuadError> {
        Ok(self.cone)
    }

    fn occluder(&self) -> Option<Occluder> {
        None
    }
}
