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
//! **Offsets.** The receiver `x` is exact (it is given, not computed), so
//! a ray from it needs no offset: the intersection routines count a hit
//! only beyond the rounding bound of its own `t`
//! ([`crate::rendering::occluder`]), so a surface through `x` (a receiver
//! on a floor that is also an occluder) is not met, and one `1e-12` above it
//! is. A shadow ray toward a point `y` on a light (computed, so off the
//! light by its rounding) ends `delta = gamma_8 (|x|_inf + |y|_inf) +
//! gamma_4 |y - x|` short of it, and the light that `y` lies on is not
//! tested. A surface in the plane of a light, over it, is not in front of
//! it: it does not block it in any form (R-A's shadow ray stops short of
//! it; along a ray of R-H the light is what is seen where the two are met
//! at the same `t` within [`TIE`] of it), and the family warns of it.
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
use crate::whitted::intersect::gamma;

/// True when the first hit so far is an occluder.
fn best_is_occluder<V: Value>(best: &FirstHit<V>) -> bool {
    matches!(best, FirstHit::Occluder { .. })
}

/// The relative distance within which an emitter and an occluder met by
/// one ray are at the same place (module documentation): `64 eps` of the
/// distance and of the origin's coordinates, the rounding of two plane
/// intersections at angles down to about `1e-2` rad from grazing.
pub const TIE: f64 = 64.0 * f64::EPSILON;

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
}

impl<V: Value> Scene<V> {
    /// The scene of `emitters` and `occluders` (each validated when built).
    pub fn new(emitters: Vec<AnyEmitter<V>>, occluders: Vec<Occluder>) -> Self {
        Scene {
            emitters,
            occluders,
        }
    }

    /// The same scene with emitter `k`'s radiance set to `radiance` (its
    /// shape, and so what it blocks, unchanged).
    pub fn with_radiance(&self, k: usize, radiance: V) -> Self {
        let mut emitters = self.emitters.clone();
        if let Some(e) = emitters.get_mut(k) {
            *e = e.with_radiance(radiance);
        }
        Scene::new(emitters, self.occluders.clone())
    }

    /// The emitters.
    pub fn emitters(&self) -> &[AnyEmitter<V>] {
        &self.emitters
    }

    /// The occluders.
    pub fn occluders(&self) -> &[Occluder] {
        &self.occluders
    }

    /// The offset `delta = gamma_8 (|x|_inf + |y|_inf) + gamma_4 |y - x|`
    /// at which a shadow ray from `x` stops short of the computed point `y`
    /// (module documentation).
    fn offset(&self, x: Vec3, y: Vec3) -> f64 {
        gamma(8) * (x.amax() + y.amax()) + gamma(4) * (y - x).norm()
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

    /// The offset below which a ray from the exact point `x` ignores hits:
    /// none, for the intersections count only hits beyond their own rounding
    /// (module documentation).
    pub fn ray_offset(&self, _x: Vec3) -> f64 {
        0.0
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

    /// R-A's visibility `V(p, q)` from the receiver `p` (exact): 1 when no
    /// occluder and no finite emitter but `skip` (the one `q` lies on) meets
    /// the open segment between them, shortened by the offset at `q`.
    pub fn visible(&self, p: Vec3, q: Vec3, skip: Option<usize>) -> bool {
        let d = q - p;
        let len = d.norm();
        let delta = self.offset(p, q);
        if len <= delta || len.is_nan() {
            return true;
        }
        // From the exact receiver `p` no offset; short of the computed `q`.
        !self.blocked(p, d / len, 0.0, len - delta, skip)
    }

    /// Visibility of the lights at infinity from `x` along the unit `w`: no
    /// finite surface beyond the offset.
    pub fn visible_to_infinity(&self, x: Vec3, w: Vec3) -> bool {
        !self.blocked(x, w, self.ray_offset(x), f64::INFINITY, None)
    }

    /// The first finite surface along `x + t w`, `t` beyond the offset.
    pub fn first_hit(&self, x: Vec3, w: Vec3) -> FirstHit<V> {
        let t_min = self.ray_offset(x);
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
            // An emitter met where the nearest occluder is (within TIE) is
            // the one seen: an occluder in its plane does not block it.
            let tie = TIE * (nearest + x.amax());
            if let Some(h) = e.hit(x, w, t_min)
                && (h.distance < nearest || h.distance <= nearest + tie && best_is_occluder(&best))
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
