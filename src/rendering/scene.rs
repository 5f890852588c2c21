//! A scene of the rendering family: emitters and occluders, the incident
//! radiance `L_i(x, w)` of R-H (the radiance of the first surface along the
//! ray, or of the lights at infinity when none is hit) and the visibility
//! `V(x, y)` of R-A (no surface strictly between `x` and `y`), the factor of
//! R-3P's geometry term `g(x, x') = V(x, x') / |x - x'|^2`.
//!
//! Finite emitters block light like occluders (a light behind another is
//! hidden by it; the back of a one-sided light is dark and opaque). Lights
//! at infinity block nothing and add up.
//!
//! **Offsets.** A ray from a point on a surface of the scene (a receiver
//! on a floor that is also an occluder) can meet that surface again at a
//! rounding-sized `t`; a shadow ray toward a point `y` on a light can meet
//! the light at `t ~ |y - x|`. Hits count only in `(delta, |y - x| -
//! delta)` with `delta = SHADOW_OFFSET (s + |x|_inf)`, `s` the largest
//! coordinate of any surface of the scene ([`Occluder::extent`]), and the
//! light that `y` lies on is not tested. `SHADOW_OFFSET = 1e-10` covers the
//! rounding of a plane intersection (`~eps s / cos`) down to grazing angles
//! of about `1e-5` rad; the price is that a blocker within `delta` of either
//! end of a shadow ray is not seen.
//!
//! ```
//! use lightquad::domain::Vec3;
//! use lightquad::rendering::emitter::{AnyEmitter, DiskLight};
//! use lightquad::rendering::occluder::Occluder;
//! use lightquad::rendering::scene::Scene;
//!
//! let light = DiskLight::new(Vec3::new(0.0, 0.0, 2.0), -Vec3::z(), 1.0, 3.0)?;
//! let blocker = Occluder::disk(Vec3::new(0.0, 0.0, 1.0), Vec3::z(), 0.1)?;
//! let scene = Scene::new(vec![AnyEmitter::from(light)], vec![blocker]);
//! // Straight up the blocker is in the way; beside it the light is seen.
//! assert_eq!(scene.incident(Vec3::zeros(), Vec3::z()), 0.0);
//! let w = Vec3::new(0.3, 0.0, 1.0).normalize();
//! assert_eq!(scene.incident(Vec3::zeros(), w), 3.0);
//! assert!(!scene.visible(Vec3::zeros(), Vec3::new(0.0, 0.0, 2.0), Some(0)));
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use crate::domain::Vec3;
use crate::rendering::emitter::{AnyEmitter, Emitter};
use crate::rendering::occluder::Occluder;
use crate::value::Value;

/// The relative offset of shadow and incident rays (module documentation).
pub const SHADOW_OFFSET: f64 = 1e-10;

/// What a ray meets first among the finite surfaces.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FirstHit<V: Value> {
    /// Emitter `index` at `distance`, sending `radiance` back along the ray.
    Emitter {
        /// Index in [`Scene::emitters`].
        index: usize,
        /// Distance along the ray.
        distance: f64,
        /// Radiance toward the ray's origin.
        radiance: V,
    },
    /// An occluder at `distance`.
    Occluder {
        /// Distance along the ray.
        distance: f64,
    },
    /// Nothing finite: the ray reaches the lights at infinity.
    Escaped,
}

/// Emitters and occluders.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene<V: Value> {
    emitters: Vec<AnyEmitter<V>>,
    occluders: Vec<Occluder>,
    /// The largest coordinate of any finite surface (for the offsets).
    scale: f64,
}

impl<V: Value> Scene<V> {
    /// The scene of `emitters` and `occluders` (each validated when built).
    pub fn new(emitters: Vec<AnyEmitter<V>>, occluders: Vec<Occluder>) -> Self {
        let scale = emitters
            .iter()
            .filter_map(|e| e.occluder())
            .chain(occluders.iter().copied())
            .fold(0.0_f64, |m, o| m.max(o.extent()));
        Scene {
            emitters,
            occluders,
            scale,
        }
    }

    /// The emitters.
    pub fn emitters(&self) -> &[AnyEmitter<V>] {
        &self.emitters
    }

    /// The occluders.
    pub fn occluders(&self) -> &[Occluder] {
        &self.occluders
    }

    /// The offset `delta` of rays from `x` (and toward `y`).
    fn offset(&self, x: Vec3, y: Vec3) -> f64 {
        SHADOW_OFFSET * (self.scale + x.amax().max(y.amax()))
    }

    /// True when some surface can stand between a receiver and emitter
    /// `skip` (`None`: the lights at infinity): an occluder, or a finite
    /// emitter other than `skip`. Without one, R-A's visibility `V` is 1
    /// everywhere for that emitter and needs no shadow ray.
    ///
    /// ```
    /// use lightquad::domain::Vec3;
    /// use lightquad::rendering::emitter::{AnyEmitter, DiskLight, EnvironmentLight};
    /// use lightquad::rendering::scene::Scene;
    ///
    /// let disk = DiskLight::new(Vec3::new(0.0, 0.0, 2.0), -Vec3::z(), 1.0, 1.0)?;
    /// let sky = EnvironmentLight::new(1.0)?;
    /// let alone = Scene::new(vec![AnyEmitter::from(disk)], vec![]);
    /// assert!(!alone.has_blockers(Some(0)));
    /// // The disk shadows the sky, and nothing shadows the disk.
    /// let both = Scene::new(vec![AnyEmitter::from(disk), AnyEmitter::from(sky)], vec![]);
    /// assert!(both.has_blockers(Some(1)) && !both.has_blockers(Some(0)));
    /// # Ok::<(), lightquad::QuadError>(())
    /// ```
    pub fn has_blockers(&self, skip: Option<usize>) -> bool {
        !self.occluders.is_empty()
            || self
                .emitters
                .iter()
                .enumerate()
                .any(|(i, e)| Some(i) != skip && e.occluder().is_some())
    }

    /// The offset `delta` below which a ray from `x` ignores hits (module
    /// documentation).
    pub fn ray_offset(&self, x: Vec3) -> f64 {
        self.offset(x, x)
    }

    /// True when some blocker (every occluder, every finite emitter but
    /// `skip`) meets `x + t w` for `t` in `(t_min, t_max)`.
    pub fn blocked(&self, x: Vec3, w: Vec3, t_min: f64, t_max: f64, skip: Option<usize>) -> bool {
        self.occluders
            .iter()
            .any(|o| o.intersect(x, w, t_min, t_max).is_some())
            || self.emitters.iter().enumerate().any(|(i, e)| {
                Some(i) != skip
                    && e.occluder()
                        .is_some_and(|o| o.intersect(x, w, t_min, t_max).is_some())
            })
    }

    /// R-A's visibility `V(p, q)`: 1 when no occluder and no finite emitter
    /// but `skip` (the one `q` lies on) meets the open segment between them,
    /// shortened by the offset at each end.
    pub fn visible(&self, p: Vec3, q: Vec3, skip: Option<usize>) -> bool {
        let d = q - p;
        let len = d.norm();
        let delta = self.offset(p, q);
        if len <= 2.0 * delta || len.is_nan() {
            return true;
        }
        !self.blocked(p, d / len, delta, len - delta, skip)
    }

    /// Visibility of the lights at infinity from `x` along the unit `w`: no
    /// finite surface beyond the offset.
    pub fn visible_to_infinity(&self, x: Vec3, w: Vec3) -> bool {
        !self.blocked(x, w, self.offset(x, x), f64::INFINITY, None)
    }

    /// The first finite surface along `x + t w`, `t` beyond the offset.
    pub fn first_hit(&self, x: Vec3, w: Vec3) -> FirstHit<V> {
        let t_min = self.offset(x, x);
        let mut best = FirstHit::Escaped;
        let mut nearest = f64::INFINITY;
        for o in &self.occluders {
            if let Some(t) = o.intersect(x, w, t_min, nearest) {
                nearest = t;
                best = FirstHit::Occluder { distance: t };
            }
        }
        for (index, e) in self.emitters.iter().enumerate() {
            if e.at_infinity() {
                continue;
            }
            if let Some(h) = e.hit(x, w, t_min)
                && h.distance < nearest
            {
                nearest = h.distance;
                best = FirstHit::Emitter {
                    index,
                    distance: h.distance,
                    radiance: h.radiance,
                };
            }
        }
        best
    }

    /// The incident radiance `L_i(x, w)` of R-H: the radiance of the first
    /// emitter along the ray, zero at an occluder, the sum of the lights at
    /// infinity that contain `w` when the ray escapes.
    pub fn incident(&self, x: Vec3, w: Vec3) -> V {
        match self.first_hit(x, w) {
            FirstHit::Emitter { radiance, .. } => radiance,
            FirstHit::Occluder { .. } => V::zero(),
            FirstHit::Escaped => self.at_infinity_along(x, w, None),
        }
    }

    /// The part of `L_i(x, w)` that emitter `k` contributes: its radiance
    /// where it is what the ray sees (`L_i = sum_k` of these).
    pub fn incident_from(&self, k: usize, x: Vec3, w: Vec3) -> V {
        match self.first_hit(x, w) {
            FirstHit::Emitter {
                index, radiance, ..
            } if index == k => radiance,
            FirstHit::Escaped => self.at_infinity_along(x, w, Some(k)),
            _ => V::zero(),
        }
    }

    /// The radiance of the lights at infinity along `w` (only light `only`
    /// when given).
    fn at_infinity_along(&self, x: Vec3, w: Vec3, only: Option<usize>) -> V {
        self.emitters
            .iter()
            .enumerate()
            .filter(|(i, e)| e.at_infinity() && only.is_none_or(|k| k == *i))
            .filter_map(|(_, e)| e.hit(x, w, 0.0))
            .fold(V::zero(), |sum, h| sum.zip(h.radiance, |a, b| a + b))
    }
}
