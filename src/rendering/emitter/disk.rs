//! [`DiskLight`]: a Lambertian disk light.

use crate::domain::{Disk, Vec3};
use crate::error::QuadError;
use crate::rendering::cap::Cap;
use crate::rendering::occluder::{Occluder, intersect_disk};
use crate::rendering::receiver::Receiver;
use crate::value::Value;

use super::{Emitter, EmitterHit, LightDomain, RIM_TOL, bounding_cone, check_radiance, one_sided};

/// A Lambertian disk light emitting `L_e` on the side of its normal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiskLight<V: Value> {
    shape: Disk,
    /// The disk grown by `RIM_TOL` for [`Emitter::hit`].
    rim: Disk,
    radiance: V,
}

impl<V: Value> DiskLight<V> {
    /// The same light with radiance `radiance` (for the converged
    /// reference, which evaluates each light at radiance 1 and scales: `E`
    /// is linear in `L_e`).
    pub(crate) fn with_radiance(self, radiance: V) -> Self {
        Self { radiance, ..self }
    }

    /// The disk about `centre` with normal `normal` (the emitting side) and
    /// radius `radius`, of radiance `radiance` (finite, `>= 0`).
    pub fn new(centre: Vec3, normal: Vec3, radius: f64, radiance: V) -> Result<Self, QuadError> {
        let shape = Disk::new(centre, normal, radius)?;
        Ok(DiskLight {
            shape,
            rim: Disk::new(centre, normal, radius * (1.0 + RIM_TOL))?,
            radiance: check_radiance("radiance", radiance)?,
        })
    }

    /// The disk.
    pub fn shape(&self) -> &Disk {
        &self.shape
    }
}

impl<V: Value> Emitter<V> for DiskLight<V> {
    fn radiance(&self) -> V {
        self.radiance
    }

    /// The plane hit within `(1 + RIM_TOL) R` of the centre.
    fn hit(&self, x: Vec3, w: Vec3, t_min: f64) -> Option<EmitterHit<V>> {
        let t = intersect_disk(&self.rim, x, w, t_min, f64::INFINITY)?;
        Some(EmitterHit {
            distance: t,
            radiance: one_sided(self.radiance, self.shape.frame().n, w),
        })
    }

    /// The polar map `r = R u_1`, `|J| = 2 pi R^2 u_1` ([`Disk`]).
    fn surface(&self, _: &Receiver) -> Result<LightDomain, QuadError> {
        Ok(LightDomain::Disk(self.shape))
    }

    fn normal_at(&self, _: Vec3) -> Vec3 {
        self.shape.frame().n
    }

    /// Seen from a point on its axis at height `h` (lateral offset at most
    /// `1e-14 (|h| + R)`), the disk is exactly the circular cone `tan alpha =
    /// R / |h|`, `1 - cos alpha = R^2 / (l (l + |h|))`, `l = sqrt(h^2 + R^2)`;
    /// elsewhere the cone of the sphere about its centre of radius `R`.
    fn cone(&self, receiver: &Receiver) -> Result<Cap, QuadError> {
        let (c, radius) = (self.shape.centre(), self.shape.radius());
        let local = self.shape.frame().to_local(receiver.point() - c);
        let (h, lateral) = (local.z.abs(), local.x.hypot(local.y));
        if h > 0.0 && lateral <= 1e-14 * (h + radius) {
            let l = h.hypot(radius);
            let axis = self.shape.frame().n * (-local.z.signum());
            return Cap::directions(axis, radius * radius / (l * (l + h)));
        }
        bounding_cone(receiver.point(), c, radius)
    }

    fn occluder(&self) -> Option<Occluder> {
        Some(Occluder::Disk(self.shape))
    }
}
