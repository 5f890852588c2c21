//! [`RectangleLight`]: a Lambertian parallelogram light.

use crate::domain::{Rectangle, Vec3};
use crate::error::QuadError;
use crate::rendering::cap::Cap;
use crate::rendering::occluder::{Occluder, intersect_parallelogram};
use crate::rendering::receiver::Receiver;
use crate::value::Value;

use super::{Emitter, EmitterHit, LightDomain, bounding_cone, check_radiance, one_sided};

/// A Lambertian parallelogram light `o + a e_1 + b e_2` emitting `L_e` on the
/// side of `e_1 x e_2`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RectangleLight<V: Value> {
    shape: Rectangle,
    radiance: V,
}

impl<V: Value> RectangleLight<V> {
    /// The same light with radiance `radiance` (for the converged
    /// reference, which evaluates each light at radiance 1 and scales: `E`
    /// is linear in `L_e`).
    pub(crate) fn with_radiance(self, radiance: V) -> Self {
        Self { radiance, ..self }
    }

    /// The light at `origin` spanned by `edge_u`, `edge_v` (finite, not
    /// parallel) of radiance `radiance` (finite, `>= 0`).
    pub fn new(origin: Vec3, edge_u: Vec3, edge_v: Vec3, radiance: V) -> Result<Self, QuadError> {
        Ok(RectangleLight {
            shape: Rectangle::new(origin, edge_u, edge_v)?,
            radiance: check_radiance("radiance", radiance)?,
        })
    }

    /// The parallelogram.
    pub fn shape(&self) -> &Rectangle {
        &self.shape
    }
}

impl<V: Value> Emitter<V> for RectangleLight<V> {
    fn radiance(&self) -> V {
        self.radiance
    }

    fn hit(&self, x: Vec3, w: Vec3, t_min: f64) -> Option<EmitterHit<V>> {
        let t = intersect_parallelogram(&self.shape, x, w, t_min, f64::INFINITY)?;
        Some(EmitterHit {
            distance: t,
            radiance: one_sided(self.radiance, self.shape.normal(), w),
        })
    }

    /// The parallelogram, `|J| = |e_1 x e_2|` (uniform in area).
    fn surface(&self, _: &Receiver) -> Result<LightDomain, QuadError> {
        Ok(LightDomain::Rectangle(self.shape))
    }

    fn normal_at(&self, _: Vec3) -> Vec3 {
        self.shape.normal()
    }

    /// The cone of the circumscribed sphere (centre `o + (e_1 + e_2)/2`,
    /// radius the half of the longer diagonal).
    fn cone(&self, receiver: &Receiver) -> Result<Cap, QuadError> {
        let (e1, e2) = (self.shape.edge_u(), self.shape.edge_v());
        let centre = self.shape.origin() + (e1 + e2) * 0.5;
        let radius = 0.5 * (e1 + e2).norm().max((e1 - e2).norm());
        bounding_cone(receiver.point(), centre, radius)
    }

    fn occluder(&self) -> Option<Occluder> {
        Some(Occluder::Rectangle(self.shape))
    }
}
