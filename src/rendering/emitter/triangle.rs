//! [`TriangleLight`]: a Lambertian triangle light.

use crate::domain::{Triangle, Vec3};
use crate::error::QuadError;
use crate::rendering::cap::Cap;
use crate::rendering::occluder::{Occluder, intersect_triangle};
use crate::rendering::receiver::Receiver;
use crate::value::Value;

use super::{Emitter, EmitterHit, LightDomain, bounding_cone, check_radiance, one_sided};

/// A Lambertian triangle light `abc` emitting `L_e` on the side of `(b - a)
/// x (c - b)` (counter-clockwise seen from the lit side).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriangleLight<V: Value> {
    shape: Triangle,
    radiance: V,
}

impl<V: Value> TriangleLight<V> {
    /// The same light with radiance `radiance` (for the converged
    /// reference, which evaluates each light at radiance 1 and scales: `E`
    /// is linear in `L_e`).
    pub(crate) fn with_radiance(self, radiance: V) -> Self {
        Self { radiance, ..self }
    }

    /// The triangle `abc` (finite, non-degenerate) of radiance `radiance`.
    pub fn new(a: Vec3, b: Vec3, c: Vec3, radiance: V) -> Result<Self, QuadError> {
        Ok(TriangleLight {
            shape: Triangle::new(a, b, c)?,
            radiance: check_radiance("radiance", radiance)?,
        })
    }

    /// The triangle.
    pub fn shape(&self) -> &Triangle {
        &self.shape
    }
}

impl<V: Value> Emitter<V> for TriangleLight<V> {
    fn radiance(&self) -> V {
        self.radiance
    }

    fn hit(&self, x: Vec3, w: Vec3, t_min: f64) -> Option<EmitterHit<V>> {
        let t = intersect_triangle(&self.shape, x, w, t_min, f64::INFINITY)?;
        Some(EmitterHit {
            distance: t,
            radiance: one_sided(self.radiance, self.shape.normal(), w),
        })
    }

    /// The Duffy map `p = a + u_1 (b - a) + u_1 u_2 (c - b)`, `|J| = 2 A u_1`.
    fn surface(&self, _: &Receiver) -> Result<LightDomain, QuadError> {
        Ok(LightDomain::Triangle(self.shape))
    }

    fn normal_at(&self, _: Vec3) -> Vec3 {
        self.shape.normal()
    }

    /// The cone of the sphere about the centroid through the farthest vertex.
    fn cone(&self, receiver: &Receiver) -> Result<Cap, QuadError> {
        let v = self.shape.vertices();
        let centroid = (v[0] + v[1] + v[2]) / 3.0;
        let radius = v.iter().fold(0.0_f64, |m, p| m.max((p - centroid).norm()));
        bounding_cone(receiver.point(), centroid, radius)
    }

    fn occluder(&self) -> Option<Occluder> {
        Some(Occluder::Triangle(self.shape))
    }
}
