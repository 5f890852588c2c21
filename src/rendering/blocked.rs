//! An emitter's light at the receiver as what it would give with nothing in
//! the way, less what each blocker hides of it: the split the family's
//! converged reference uses where blockers can stand between the receiver
//! and a light and their shadow boundaries are not computed.
//!
//! An adaptive rule over a light's whole domain can miss a blocker that
//! covers a small part of it: Genz–Malik over the hemisphere of a sky
//! (radiance 0.25) with a sphere occluder of 0.04 sr in it returned pi/4
//! with an error estimate of 1e-17, where the sky it sees is 0.7566 (Mitsuba
//! 3: 0.7567). Every direction a blocker `j` hides is a direction to a point
//! of `j`, so
//!
//! `int_k = int_k^unblocked - sum_j int_(S_j) K(w) cos theta L_k(w) [j is the
//! first surface along w, and k lies behind it] |cos theta_j| / r^2 dA`
//!
//! over each blocker's own surface `S_j` (R-A's change of variables `d w =
//! |cos theta_j| dA / r^2`; for a sphere its cone of directions, which it
//! fills) counts each hidden direction exactly once (the first surface along
//! a ray is one surface). The unblocked integral has no visibility jump, and
//! over `S_j` the indicator is 1 but where another blocker or `k`'s outline
//! crosses it: a sky behind a lone blocker is smooth there. (Over the
//! blocker's bounding cone instead, Genz–Malik converged to 0.0750 for a
//! triangle hiding 0.0795 of a sky: its corners, in boxes whose nodes all
//! missed them, were lost.)

use crate::domain::Vec3;
use crate::error::QuadError;
use crate::rendering::emitter::{AnyEmitter, Emitter, LightDomain, bounding_cone};
use crate::rendering::forms::{Kernel, emitter_at};
use crate::rendering::occluder::Occluder;
use crate::rendering::receiver::Receiver;
use crate::rendering::scene::Scene;

/// The surfaces that can hide emitter `k`: every occluder and every finite
/// emitter but `k`, as occluder shapes.
pub fn blockers(scene: &Scene<f64>, k: usize) -> Vec<Occluder> {
    scene
        .occluders()
        .iter()
        .copied()
        .chain(
            scene
                .emitters()
                .iter()
                .enumerate()
                .filter(|(i, _)| *i != k)
                .filter_map(|(_, e)| e.occluder()),
        )
        .collect()
}

/// The domain of blocker `o` seen from `x`: its surface (a parallelogram,
/// a disk through its polar map, a triangle through the Duffy map; measure
/// area), or for a sphere its cone of directions from `x` (measure solid
/// angle; the whole sphere of directions for `x` inside it).
pub fn domain(o: &Occluder, x: Vec3) -> Result<LightDomain, QuadError> {
    Ok(match o {
        Occluder::Rectangle(r) => LightDomain::Rectangle(*r),
        Occluder::Disk(d) => LightDomain::Disk(*d),
        Occluder::Triangle(t) => LightDomain::Triangle(*t),
        Occluder::Sphere(s) => LightDomain::Cap(bounding_cone(x, s.centre, s.radius)?),
    })
}

/// True when what blocker `j` hides of emitter `k` is smooth over the
/// blocker's domain, so that the converged evaluation's error estimate can
/// be trusted: `k` is the environment (behind every direction, the same
/// radiance), and `j`'s cone from `x` lies wholly above the horizon and
/// apart from every other blocker's cone. Otherwise `k`'s outline, the
/// horizon or another blocker cuts the domain: a sliver 0.15 degrees wide at
/// the edge of a sphere light's cone, where it hid a rectangle light, was
/// missed at every budget while the change between budgets said 7e-8.
pub fn smooth(scene: &Scene<f64>, receiver: &Receiver, k: usize, j: usize) -> bool {
    if !matches!(scene.emitters().get(k), Some(AnyEmitter::Environment(_))) {
        return false;
    }
    let x = receiver.point();
    let cones: Vec<Option<(Vec3, f64)>> = blockers(scene, k)
        .iter()
        .map(|o| {
            let (centre, radius) = o.bounding_sphere();
            let cap = bounding_cone(x, centre, radius).ok()?;
            let omc = cap.one_minus_cos();
            (omc < 1.0).then(|| (cap.axis(), (1.0 - omc).acos()))
        })
        .collect();
    let Some(Some((axis, half))) = cones.get(j).copied() else {
        return false;
    };
    let above = receiver.normal().dot(&axis) > half.sin();
    let apart = cones.iter().enumerate().all(|(i, c)| {
        i == j || c.is_some_and(|(a, h)| a.dot(&axis).clamp(-1.0, 1.0).acos() > half + h)
    });
    above && apart
}

/// Emitter `k`'s light with nothing in the way, along unit `w`: `K(w) cos
/// theta L_k(w)`, `L_k(w)` the radiance of `k`'s first point along the ray
/// (its back is dark), zero below the horizon. No shadow ray.
pub fn unblocked<'a, K: Kernel>(
    emitter: &'a AnyEmitter<f64>,
    receiver: &'a Receiver,
    kernel: &'a K,
) -> impl Fn(Vec3) -> f64 + 'a {
    let x = receiver.point();
    move |w: Vec3| {
        let cos = receiver.cos_theta(w);
        if cos <= 0.0 {
            return 0.0;
        }
        let weight = kernel.weight(w);
        if weight == 0.0 {
            return 0.0;
        }
        emitter
            .hit(x, w, 0.0)
            .map_or(0.0, |h| h.radiance * weight * cos)
    }
}

/// What blocker `j` of [`blockers`] hides of emitter `k` (module text).
struct Hidden<'a, K: Kernel> {
    emitter: &'a AnyEmitter<f64>,
    receiver: &'a Receiver,
    kernel: &'a K,
    blockers: Vec<Occluder>,
    j: usize,
    t_min: f64,
}

impl<'a, K: Kernel> Hidden<'a, K> {
    fn new(
        scene: &'a Scene<f64>,
        receiver: &'a Receiver,
        kernel: &'a K,
        k: usize,
        j: usize,
    ) -> Result<Self, QuadError> {
        let emitter = emitter_at(scene, k)?;
        let blockers = blockers(scene, k);
        if j >= blockers.len() {
            return Err(QuadError::invalid(
                "j",
                j,
                format!(
                    "a blocker index below {}, emitter {k}'s blockers",
                    blockers.len()
                ),
            ));
        }
        Ok(Hidden {
            emitter,
            receiver,
            kernel,
            blockers,
            j,
            t_min: scene.ray_offset(receiver.point()),
        })
    }

    /// `K(w) cos theta L_k(w)` where the blocker, at distance `t` along unit
    /// `w`, is the first surface and `k` lies behind it; else 0.
    fn along(&self, w: Vec3, t: f64) -> f64 {
        let seen = unblocked(self.emitter, self.receiver, self.kernel)(w);
        if seen == 0.0 {
            return 0.0;
        }
        let x = self.receiver.point();
        // k behind the blocker (a light at infinity is behind everything).
        let behind = self.emitter.at_infinity()
            || self.emitter.hit(x, w, 0.0).is_some_and(|h| h.distance > t);
        // Nothing else first: every other blocker clear of (t_min, t).
        let first = self
            .blockers
            .iter()
            .enumerate()
            .all(|(i, o)| i == self.j || o.intersect(x, w, self.t_min, t).is_none());
        if behind && first { seen } else { 0.0 }
    }

    /// [`Hidden::along`] at the unit direction `w`, where the ray meets the
    /// blocker.
    fn direction(&self, w: Vec3) -> f64 {
        let blocker = self.blockers[self.j];
        blocker
            .intersect(self.receiver.point(), w, self.t_min, f64::INFINITY)
            .map_or(0.0, |t| self.along(w, t))
    }

    /// [`Hidden::along`] toward the point `y` of the blocker's surface, times
    /// `|cos theta_j| / r^2` (solid angle per area).
    fn point(&self, y: Vec3) -> f64 {
        let d = y - self.receiver.point();
        let r = d.norm();
        if r.is_nan() || r <= self.t_min {
            return 0.0;
        }
        let w = d / r;
        let jacobian = self.blockers[self.j].normal_at(y).dot(&w).abs() / (r * r);
        if jacobian == 0.0 {
            return 0.0;
        }
        self.along(w, r) * jacobian
    }
}

/// What blocker `j` of [`blockers`] hides of emitter `k`, as the integrand
/// over [`domain`]: at a point `y` of the blocker's surface `K(w) cos theta
/// L_k(w) |cos theta_j| / r^2` (`w = (y - x)/r`), at a direction `w` of a
/// sphere's cone `K(w) cos theta L_k(w)`, where `j` is the first surface of
/// the scene along `w` and `k` lies behind it; zero elsewhere. Indices past
/// the emitters or the blockers are errors naming them.
pub fn hidden<'a, K: Kernel>(
    scene: &'a Scene<f64>,
    receiver: &'a Receiver,
    kernel: &'a K,
    k: usize,
    j: usize,
) -> Result<impl Fn(Vec3) -> f64 + 'a, QuadError> {
    let h = Hidden::new(scene, receiver, kernel, k, j)?;
    let directions = matches!(h.blockers[j], Occluder::Sphere(_));
    Ok(move |p: Vec3| {
        if directions {
            h.direction(p)
        } else {
            h.point(p)
        }
    })
}

/// The same as [`hidden`] as an integrand over unit directions (for a
/// BRDF's own map): `K(w) cos theta L_k(w)` where `j` is the first surface
/// along `w` and `k` lies behind it.
pub fn hidden_along<'a, K: Kernel>(
    scene: &'a Scene<f64>,
    receiver: &'a Receiver,
    kernel: &'a K,
    k: usize,
    j: usize,
) -> Result<impl Fn(Vec3) -> f64 + 'a, QuadError> {
    let h = Hidden::new(scene, receiver, kernel, k, j)?;
    Ok(move |w: Vec3| h.direction(w))
}
