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
//!
//! Where every blocker stands wholly in front of the light or wholly
//! behind it ([`crate::rendering::order`]), the hidden part is integrated
//! between exact outlines instead ([`hidden_by_arcs`]): in polar directions
//! about each blocker, every spoke is cut where the blocker's, the light's,
//! the horizon's, the lobe clamp's and the earlier blockers' outlines cross
//! it ([`crate::rendering::arcs`]), so no piece holds a jump and no
//! visibility test is made. Checked against an independent contour
//! integral (Stokes on the sphere of directions, tests/it/rendering_contour.rs)
//! to 3e-13: a sphere light hiding part of a rectangle light, where the
//! evaluation over the blocker's cone with a visibility test was 7.3e-5
//! off while its change between budgets said 5.6e-8.

use std::cell::Cell;
use std::f64::consts::PI;

use crate::domain::{Frame, Vec3};
use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::quadrature::Rule;
use crate::quadrature::gauss_kronrod::GaussKronrod;
use crate::quadrature::product::WithError;
use crate::rendering::arcs::{self, Fan, Outline, Pieces, Spoke};
use crate::rendering::cap::Cap;
use crate::rendering::emitter::{AnyEmitter, Emitter, LightDomain, bounding_cone};
use crate::rendering::forms::{Kernel, emitter_at};
use crate::rendering::occluder::Occluder;
use crate::rendering::order;
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

/// The directions of an emitter's light from `x`, as [`Spoke`] pieces take
/// them.
#[derive(Debug, Clone, Copy)]
enum Seen {
    /// Every direction (the environment).
    All,
    /// The directions within an angle of a unit axis (a cap light).
    Cone(Vec3, f64),
    /// The directions that meet a shape (a sphere light from outside, a
    /// planar light from its emitting side).
    Shape(Occluder),
    /// None: `x` behind a planar light or in its plane.
    Dark,
}

impl Seen {
    /// What `e` covers from `x`; `None` for `x` inside a sphere light.
    fn of(e: &AnyEmitter<f64>, x: Vec3) -> Option<Seen> {
        Some(match e {
            AnyEmitter::Environment(_) => Seen::All,
            AnyEmitter::Cap(c) => Seen::Cone(c.cap().axis(), half_angle(c.cap().one_minus_cos())),
            AnyEmitter::Sphere(s) => {
                let shape = s.shape();
                if (shape.centre - x).norm() <= shape.radius {
                    return None;
                }
                Seen::Shape(Occluder::Sphere(*shape))
            }
            AnyEmitter::Rectangle(_) | AnyEmitter::Triangle(_) | AnyEmitter::Disk(_) => {
                let shape = e.occluder()?;
                let (p, _) = shape.bounding_sphere();
                if e.normal_at(p).dot(&(x - p)) > 0.0 {
                    Seen::Shape(shape)
                } else {
                    Seen::Dark
                }
            }
        })
    }

    fn pieces(&self, spoke: &Spoke) -> Pieces {
        match self {
            Seen::All => spoke.all(),
            Seen::Cone(c, beta) => spoke.cone(*c, *beta),
            Seen::Shape(o) => spoke.shape(o),
            Seen::Dark => Vec::new(),
        }
    }

    fn outlines(&self, x: Vec3) -> Vec<Outline> {
        match self {
            Seen::Cone(c, beta) => vec![Outline::Circle(*c, beta.cos())],
            Seen::Shape(o) => Outline::of(o, x),
            Seen::All | Seen::Dark => Vec::new(),
        }
    }

    fn breaks(&self, fan: &Fan) -> Vec<f64> {
        match self {
            Seen::Cone(c, beta) => fan.cone_breaks(*c, *beta),
            Seen::Shape(o) => fan.breaks(o),
            Seen::All | Seen::Dark => Vec::new(),
        }
    }
}

/// The half-angle `2 asin(sqrt(k/2))` of a cone with `1 - cos = k`.
fn half_angle(one_minus_cos: f64) -> f64 {
    2.0 * (one_minus_cos / 2.0).sqrt().min(1.0).asin()
}

/// Budgets of [`hidden_by_arcs`] per blocker: Gauss–Kronrod over the
/// azimuth between its breaks (bisecting at each kink left, where an
/// outline enters or leaves the spokes) and along each piece of a spoke
/// (smooth: 15 to 45 evaluations but for a peaked lobe).
const AZIMUTH_BUDGET: usize = 60_015;
const PIECE_BUDGET: usize = 3_015;

/// What the blockers hide of emitter `k`, integrated piece by piece where
/// the integrand is smooth: `sum_j int_0^(2 pi) int_(I_j(phi)) K(w) cos
/// theta L_k sin rho d rho d phi` in polar directions `w(rho, phi)` about
/// the direction to blocker `j`'s bounding sphere ([`Fan`]), `I_j(phi)` the
/// exact arcs ([`arcs`]) of the spoke at azimuth `phi` that meet `j` and
/// the light, lie above the horizon (and inside the lobe's clamp,
/// [`Kernel::clamp`]), and meet no blocker `i < j`: every hidden direction
/// counted once. On them `L_k` is the light's uniform radiance: no ray is
/// cast, and no outline cuts a piece. The azimuth is split where the
/// pieces can jump or kink ([`Fan::breaks`]). Nested adaptive
/// Gauss–Kronrod; the error is the outer estimates plus the pieces'
/// integrated with the value.
///
/// This holds where every blocker is wholly in front of the light or
/// wholly behind it along the rays that meet both ([`order`]), so that a
/// direction is hidden exactly when it meets a blocker in front. `Ok(None)`
/// where that is not known (a blocker straddling a planar light's plane,
/// one interpenetrating a sphere light) or `x` is inside a sphere light:
/// the caller falls back on [`hidden`].
pub fn hidden_by_arcs<K: Kernel>(
    scene: &Scene<f64>,
    receiver: &Receiver,
    kernel: &K,
    k: usize,
) -> Result<Option<Estimate<f64>>, QuadError> {
    let emitter = emitter_at(scene, k)?;
    let x = receiver.point();
    let zero = Ok(Some(Estimate::deterministic(0.0, 0.0, 0)));
    let light = match Seen::of(emitter, x) {
        None => return Ok(None),
        Some(Seen::Dark) => return zero,
        Some(seen) => seen,
    };
    // The blockers in front of the light where both are seen.
    let mut front = Vec::new();
    for o in blockers(scene, k) {
        let Some(body) = emitter.occluder() else {
            front.push(o);
            continue;
        };
        match order::first(&o, &body, x) {
            Some(true) => front.push(o),
            Some(false) => {}
            None if order::apart(&o, &body, x) => {}
            None => return Ok(None),
        }
    }
    let mut total = Estimate::zero();
    for (j, blocker) in front.iter().enumerate() {
        let part = hidden_by(receiver, kernel, emitter, &light, blocker, &front[..j])?;
        total = total.combine(part);
    }
    Ok(Some(total))
}

/// True when the receiver `x` is strictly inside a sphere occluder that
/// emitter `e` lies wholly outside of (or `e` is at infinity): every ray
/// from `x` toward `e` leaves through the sphere first, so `e` adds exactly
/// 0. Strictly: `R - |x - c| > gamma_8 (R + |x - c|)`, and for a finite
/// emitter `max(|c_e - c| - r_e, d_plane) > R` with `(c_e, r_e)` its
/// bounding sphere and `d_plane` the distance of `c` from a planar light's
/// plane.
pub fn enclosed(scene: &Scene<f64>, x: Vec3, e: &AnyEmitter<f64>) -> bool {
    // A lower bound on the distance of the light from `c`: its bounding
    // sphere's gap, and for a planar light the distance to its plane.
    let outside = |c: Vec3, r: f64| match e.occluder() {
        None => true,
        Some(body) => {
            let (ce, re) = body.bounding_sphere();
            let plane = match body {
                Occluder::Sphere(_) => 0.0,
                _ => body.normal_at(ce).dot(&(ce - c)).abs(),
            };
            ((ce - c).norm() - re).max(plane) > r
        }
    };
    scene.occluders().iter().any(|o| match o {
        Occluder::Sphere(s) => {
            let d = (x - s.centre).norm();
            s.radius - d > crate::whitted::intersect::gamma(8) * (s.radius + d)
                && outside(s.centre, s.radius)
        }
        _ => false,
    })
}

/// [`hidden_by_arcs`]' term of `blocker`, less the directions of `before`.
fn hidden_by<K: Kernel>(
    receiver: &Receiver,
    kernel: &K,
    emitter: &AnyEmitter<f64>,
    light: &Seen,
    blocker: &Occluder,
    before: &[Occluder],
) -> Result<Estimate<f64>, QuadError> {
    let x = receiver.point();
    let fan = Fan::about(blocker, x, receiver.normal())?;
    let mut breaks = fan.breaks(blocker);
    let mut outlines = Outline::of(blocker, x);
    for o in before {
        breaks.extend(fan.breaks(o));
        outlines.extend(Outline::of(o, x));
    }
    let on = |sp: &Spoke| -> Pieces {
        let mut set = sp.shape(blocker);
        for o in before {
            set = arcs::subtract(&set, &sp.shape(o));
        }
        set
    };
    over_fan(
        receiver,
        kernel,
        emitter,
        light,
        &fan,
        (breaks, outlines),
        on,
    )
}

/// An emitter's light with nothing in the way over its exact cone of
/// directions `cone` (a sphere's, a cap light's, the environment's
/// hemisphere, a disk's from its axis), `int K(w) cos theta L d w` above the
/// horizon (and inside the lobe's clamp), by `over_fan` about the cone's
/// axis out to its half-angle: exact pieces, where a rule over the cone
/// ends at one box for a flat kernel (the integrand is a low polynomial in
/// the cone's map) and cannot vouch for it.
pub fn over_cone<K: Kernel>(
    receiver: &Receiver,
    kernel: &K,
    emitter: &AnyEmitter<f64>,
    cone: &Cap,
) -> Result<Estimate<f64>, QuadError> {
    let fan = Fan {
        x: receiver.point(),
        frame: Frame::from_normal(cone.axis())?,
        reach: half_angle(cone.one_minus_cos()),
    };
    over_fan(
        receiver,
        kernel,
        emitter,
        &Seen::All,
        &fan,
        (
            Vec::new(),
            vec![Outline::Circle(cone.axis(), fan.reach.cos())],
        ),
        |sp: &Spoke| sp.all(),
    )
}

/// A planar or sphere light's light with nothing in the way, `int K(w) cos
/// theta L d w` over the directions that meet it above the horizon (and
/// inside the lobe's clamp), by `over_fan` about the direction to its
/// bounding sphere: exact pieces where the horizon or the clamp cuts the
/// light (over its surface the integrand kinks there: a rectangle across
/// the horizon was 3.1e-8 off by adaptive Genz–Malik). `None` for lights at
/// infinity and for `x` inside a sphere light.
pub fn over_shape<K: Kernel>(
    receiver: &Receiver,
    kernel: &K,
    emitter: &AnyEmitter<f64>,
) -> Result<Option<Estimate<f64>>, QuadError> {
    let x = receiver.point();
    let shape = match Seen::of(emitter, x) {
        Some(Seen::Shape(o)) => o,
        Some(Seen::Dark) => return Ok(Some(Estimate::deterministic(0.0, 0.0, 0))),
        _ => return Ok(None),
    };
    let fan = Fan::about(&shape, x, receiver.normal())?;
    let (breaks, outlines) = (fan.breaks(&shape), Outline::of(&shape, x));
    over_fan(
        receiver,
        kernel,
        emitter,
        &Seen::All,
        &fan,
        (breaks, outlines),
        |sp: &Spoke| sp.shape(&shape),
    )
    .map(Some)
}

/// `int_0^(2 pi) int_(I(phi)) K(w) cos theta L sin rho d rho d phi` over
/// `fan`, `I(phi)` the pieces `on` gives of the spoke at `phi` met with the
/// light's, the horizon's and the lobe clamp's; the azimuth split at
/// `breaks` and wherever the light's, the horizon's and the clamp's
/// outlines make the pieces jump or kink, and where any two of those and
/// `outlines` (the outlines `on` cuts at) cross.
fn over_fan<K: Kernel>(
    receiver: &Receiver,
    kernel: &K,
    emitter: &AnyEmitter<f64>,
    light: &Seen,
    fan: &Fan,
    (mut breaks, mut outlines): (Vec<f64>, Vec<Outline>),
    on: impl Fn(&Spoke) -> Pieces,
) -> Result<Estimate<f64>, QuadError> {
    let (normal, clamp, radiance) = (receiver.normal(), kernel.clamp(), emitter.radiance());
    let on = |sp: &Spoke| -> Pieces {
        let mut set = arcs::intersect(&on(sp), &sp.half_space(normal));
        set = arcs::intersect(&set, &light.pieces(sp));
        if let Some(r) = clamp {
            set = arcs::intersect(&set, &sp.half_space(r));
        }
        set
    };
    // The azimuths where the pieces jump or kink, as the ends of panels.
    breaks.extend(light.breaks(fan));
    breaks.extend(fan.cone_breaks(normal, PI / 2.0));
    if let Some(r) = clamp {
        breaks.extend(fan.cone_breaks(r, PI / 2.0));
        outlines.push(Outline::Circle(r, 0.0));
    }
    outlines.extend(light.outlines(fan.x));
    outlines.push(Outline::Circle(normal, 0.0));
    breaks.extend(fan.crossing_breaks(&outlines));
    breaks.push(0.0);
    breaks.sort_by(f64::total_cmp);
    breaks.dedup();
    breaks.push(2.0 * PI);
    let panels: Vec<(f64, f64)> = breaks
        .windows(2)
        .map(|w| (w[0], w[1]))
        .filter(|(a, b)| b > a)
        .collect();
    let mut rng = <rand_pcg::Pcg64 as rand::SeedableRng>::seed_from_u64(0);
    let mut inner_rng = <rand_pcg::Pcg64 as rand::SeedableRng>::seed_from_u64(1);
    let (evaluations, reliable) = (Cell::new(0_u64), Cell::new(true));
    let along = GaussKronrod {
        abs_tol: 0.0,
        rel_tol: 2e-14,
    };
    // g(phi) on a panel, with the pieces' error estimates.
    let mut g = |lo: f64, hi: f64, u: f64| -> Result<WithError<f64>, QuadError> {
        let sp = fan.spoke(lo + (hi - lo) * u);
        let (mut value, mut error) = (0.0, 0.0);
        for (a, b) in on(&sp) {
            let piece = along.try_integrate::<1, f64, _, _>(PIECE_BUDGET, &mut inner_rng, |v| {
                let rho = a + (b - a) * v[0];
                let w = sp.direction(rho);
                let cos = receiver.cos_theta(w);
                Ok(if cos > 0.0 {
                    kernel.weight(w) * cos * radiance * rho.sin() * (b - a)
                } else {
                    0.0
                })
            })?;
            evaluations.set(evaluations.get() + piece.evaluations);
            reliable.set(reliable.get() && piece.reliable);
            value += piece.value * (hi - lo);
            error += piece.error * (hi - lo);
        }
        Ok(WithError { value, error })
    };
    // A pilot of one Kronrod panel each sets the absolute tolerance, so that
    // a panel where nothing is seen stops at once.
    let pilot = GaussKronrod::default();
    let mut scale = 0.0;
    for &(lo, hi) in &panels {
        let p =
            pilot.try_integrate::<1, WithError<f64>, _, _>(15, &mut rng, |u| g(lo, hi, u[0]))?;
        scale += p.value.value.abs();
    }
    let around = GaussKronrod {
        abs_tol: 1e-15 * scale / panels.len() as f64,
        rel_tol: 1e-13,
    };
    let per = (AZIMUTH_BUDGET / panels.len()).max(255);
    let mut total = Estimate::zero();
    for &(lo, hi) in &panels {
        let p =
            around.try_integrate::<1, WithError<f64>, _, _>(per, &mut rng, |u| g(lo, hi, u[0]))?;
        total = total.combine(Estimate {
            value: p.value.value,
            error: p.error.value + p.value.error.abs(),
            evaluations: 0,
            kind: p.kind,
            reliable: p.reliable,
            alike: false,
        });
    }
    Ok(Estimate {
        evaluations: evaluations.get(),
        reliable: total.reliable && reliable.get(),
        ..total
    })
}
