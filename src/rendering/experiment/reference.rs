//! The rendering family's references: closed forms where the scene has one
//! ([`crate::exact::rendering`]) and the converged evaluation otherwise
//! (adaptive Genz–Malik on each emitter's smoothest form, or between exact
//! outlines where the integrand would kink inside one).

use std::f64::consts::PI;

use crate::domain::{Triangle, Vec3, integrate_over};
use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::exact::rendering as exact;
use crate::quadrature::{GenzMalik, Rule};
use crate::rendering::blocked;
use crate::rendering::clipped;
use crate::rendering::emitter::{AnyEmitter, CapLight, DiskLight, Emitter};
use crate::rendering::forms::{self, BrdfSampled, Irradiance, Kernel, Reflected};
use crate::rendering::occluder::Occluder;
use crate::rendering::order;
use crate::rendering::receiver::Receiver;
use crate::rendering::scene::Scene;

use super::evaluate::reflected_kernel;
use super::{AnyBrdf, Built, RenderingQuantity};

/// True when the emitter's cone from the receiver is exactly the emitter
/// ([`Emitter::cone`]): a sphere, a cap light, the environment's
/// hemisphere, a disk seen from its axis.
pub(super) fn exact_cone(e: &AnyEmitter<f64>, receiver: &Receiver) -> bool {
    match e {
        AnyEmitter::Sphere(_) | AnyEmitter::Cap(_) | AnyEmitter::Environment(_) => true,
        AnyEmitter::Disk(d) => coaxial(d, receiver.point()).is_some(),
        AnyEmitter::Rectangle(_) | AnyEmitter::Triangle(_) => false,
    }
}

/// True when the receiver's horizon or the kernel's lobe clamp
/// ([`Kernel::clamp`]) cuts a finite emitter: the plane through the
/// receiver has points of the light strictly on both sides.
fn crosses<K: Kernel>(e: &AnyEmitter<f64>, receiver: &Receiver, kernel: &K) -> bool {
    let x = receiver.point();
    e.occluder().is_some_and(|o| {
        order::straddles(&o, x, receiver.normal())
            || kernel.clamp().is_some_and(|r| order::straddles(&o, x, r))
    })
}

/// The height of `x` above the plane of a disk light (signed: positive on
/// its emitting side), when `x` is on the disk's axis (lateral offset at
/// most `1e-14 (|h| + R)`, as [`DiskLight`]'s cone takes it) and off its
/// plane.
fn coaxial(d: &DiskLight<f64>, x: Vec3) -> Option<f64> {
    let shape = d.shape();
    let local = shape.frame().to_local(x - shape.centre());
    let (h, lateral) = (local.z, local.x.hypot(local.y));
    (h != 0.0 && lateral <= 1e-14 * (h.abs() + shape.radius())).then_some(h)
}

/// The converged method's rule: adaptive Genz–Malik to a relative
/// tolerance of 1e-14.
pub(super) const CONVERGED_RULE: GenzMalik = GenzMalik {
    abs_tol: 0.0,
    rel_tol: 1e-14,
};

/// The value of irradiance (or reflected radiance) by the converged method:
/// adaptive Genz–Malik on each emitter's smoothest form.
pub(super) fn converged_value(
    built: &Built,
    reflected: bool,
    budget: usize,
) -> Result<Estimate<f64>, QuadError> {
    if !reflected {
        return converged_by_emitter(built, &Irradiance, None, budget);
    }
    let kernel = reflected_kernel(built)?;
    // A Lambertian lobe is flat: the cone is as smooth as the BRDF map.
    let lobe = match built.brdf {
        Some(AnyBrdf::Lambert(_)) => None,
        _ => Some(&kernel),
    };
    converged_by_emitter(built, &kernel, lobe, budget)
}

fn converged_by_emitter<K: Kernel>(
    built: &Built,
    kernel: &K,
    lobe: Option<&Reflected<'_, AnyBrdf>>,
    budget: usize,
) -> Result<Estimate<f64>, QuadError> {
    let rule = CONVERGED_RULE;
    let mut rng = <rand_pcg::Pcg64 as rand::SeedableRng>::seed_from_u64(0);
    let (scene, receiver) = (&built.scene, &built.receiver);
    let mut total = Estimate::zero();
    for (k, e) in scene.emitters().iter().enumerate() {
        // A dark light adds exactly nothing, nor does one the receiver is
        // shut off from; the others are evaluated at radiance 1 and scaled
        // (E is linear in L_e), so that the relative tolerance is never
        // relative to a subnormal value that rounding cannot meet (a sky
        // of radiance 1e-320 kept the rule refining for over 300 s).
        let radiance = e.radiance();
        if radiance == 0.0 || blocked::enclosed(scene, receiver.point(), e) {
            continue;
        }
        let unit = Built {
            scene: scene.with_radiance(k, 1.0),
            ..built.clone()
        };
        let part = emitter_term(&unit, kernel, lobe, budget, k, &rule, &mut rng)?;
        total = total.combine(Estimate {
            value: part.value * radiance,
            error: part.error * radiance,
            ..part
        });
    }
    Ok(total)
}

/// Emitter `k`'s term of the converged value, in `built`'s scene (module
/// documentation).
fn emitter_term<K: Kernel>(
    built: &Built,
    kernel: &K,
    lobe: Option<&Reflected<'_, AnyBrdf>>,
    budget: usize,
    k: usize,
    rule: &GenzMalik,
    rng: &mut rand_pcg::Pcg64,
) -> Result<Estimate<f64>, QuadError> {
    let (scene, receiver) = (&built.scene, &built.receiver);
    let Some(e) = scene.emitters().get(k) else {
        return Ok(Estimate::zero());
    };
    // Under a peaked lobe the lit polygons' area integrand holds the
    // lobe's peak where the lobe is narrower than them; the blockers'
    // exact arcs with adaptive pieces resolve it instead.
    let lit = match lobe {
        None => lit_triangles(scene, receiver.point(), k),
        Some(_) => None,
    };
    // Where something can stand in the way and the shadow boundaries are
    // not computed, the light is taken with nothing in the way, and what
    // each blocker hides is subtracted over the blocker's own cone (an
    // adaptive rule over the light's domain can miss a small blocker:
    // crate::rendering::blocked).
    let split = lit.is_none() && scene.has_blockers(Some(k));
    let along = || {
        let free = blocked::unblocked(e, receiver, kernel);
        let seen = forms::cone_integrand(scene, receiver, kernel, k);
        move |w: Vec3| if split { free(w) } else { seen(w) }
    };
    let by_lobe = |lobe: &Reflected<'_, AnyBrdf>, rng: &mut rand_pcg::Pcg64| {
        integrate_over(rule, &BrdfSampled::new(*lobe), budget, rng, along())
    };
    let part = match (e, lobe) {
        // Under a peaked lobe the environment's integrand is the lobe:
        // smooth in the BRDF's own map, but for the horizon where it
        // cuts the lobe; a Phong lobe is split there (clipped.rs), the
        // two checked against each other.
        (AnyEmitter::Environment(_), Some(lobe)) => match phong_cone(built)? {
            Some(pieces) => {
                let mut sum = Estimate::zero();
                for piece in &pieces {
                    sum = sum.combine(integrate_over(rule, piece, budget, rng, along())?);
                }
                cross_checked(sum, by_lobe(lobe, rng)?)
            }
            None => by_lobe(lobe, rng)?,
        },
        _ => {
            let own = if exact_cone(e, receiver) && lobe.is_none() {
                // A flat kernel over an exact cone: exact pieces (a rule
                // over the cone ends at one box and cannot vouch for it).
                blocked::over_cone(receiver, kernel, e, &e.cone(receiver)?)?
            } else if exact_cone(e, receiver) {
                integrate_over(rule, &e.cone(receiver)?, budget, rng, along())?
            } else if crosses(e, receiver, kernel)
                && (split || !scene.has_blockers(Some(k)))
                && let Some(own) = blocked::over_shape(receiver, kernel, e)?
            {
                // Cut where the horizon or the lobe's clamp crosses the
                // light: over its surface the integrand kinks there.
                own
            } else if let Some(lit) = &lit {
                // Split at the shadow boundaries: exact by Lambert's contour
                // on every piece (a light 1e24 long is a peak no rule
                // resolves in its map), or smooth on every piece.
                if let Some(exact) = lit_by_contour(e, receiver, kernel, lit) {
                    return Ok(exact);
                }
                let g = forms::area_integrand_with(scene, receiver, kernel, k, |_| true)?;
                let per = (budget / lit.len().max(1)).max(rule.min_budget(2));
                let mut sum = Estimate::zero();
                for t in lit {
                    sum = sum.combine(integrate_over(rule, t, per, rng, &g)?);
                }
                sum
            } else if split {
                let g = forms::area_integrand_with(scene, receiver, kernel, k, |_| true)?;
                integrate_over(rule, &e.surface(receiver)?, budget, rng, g)?
            } else {
                let g = forms::area_integrand(scene, receiver, kernel, k)?;
                integrate_over(rule, &e.surface(receiver)?, budget, rng, g)?
            };
            match lobe {
                // A lobe narrower than the light is smooth in the BRDF's
                // map and a peak in the light's; one crossing the
                // light's outline the other way round: both, the one
                // with the smaller error kept, checked by the other.
                Some(lobe) => cross_checked(own, by_lobe(lobe, rng)?),
                None => own,
            }
        }
    };
    let part = if split {
        // Where each blocker is wholly in front of the light or behind
        // it, piece by piece between the exact outlines; else over each
        // blocker's domain with a visibility test, trusted only where
        // nothing cuts it.
        let exact = blocked::hidden_by_arcs(scene, receiver, kernel, k)?;
        let mut hidden = exact.unwrap_or_else(Estimate::zero);
        let fallback = if exact.is_some() {
            Vec::new()
        } else {
            blocked::blockers(scene, k)
        };
        for (j, o) in fallback.iter().enumerate() {
            let h = blocked::hidden(scene, receiver, kernel, k, j)?;
            let domain = blocked::domain(o, receiver.point())?;
            let own = integrate_over(rule, &domain, budget, rng, &h)?;
            let checked = match lobe {
                Some(lobe) => cross_checked(
                    own,
                    integrate_over(
                        rule,
                        &BrdfSampled::new(*lobe),
                        budget,
                        rng,
                        blocked::hidden_along(scene, receiver, kernel, k, j)?,
                    )?,
                ),
                None => own,
            };
            // Outlines, the horizon or other blockers crossing the
            // domain make the evaluation's own error estimate unsafe.
            let trusted = blocked::smooth(scene, receiver, k, j);
            hidden = hidden.combine(Estimate {
                reliable: checked.reliable && trusted,
                ..checked
            });
        }
        part.combine(Estimate {
            value: -hidden.value,
            ..hidden
        })
    } else {
        part
    };
    Ok(part)
}

/// The flat kernel's value over the lit triangles `lit` of planar light
/// `e` (no lobe: [`lit_triangles`] is only asked then), by Lambert's contour
/// formula on each: `K L_e pi sum_i F_i`, `F_i` the form factor of
/// triangle `i` ([`exact::polygon_form_factor`]), `K` the kernel's constant
/// weight; 0 where the light faces away. Its error: `gamma_8` of the value
/// per triangle. `None` where a form factor fails.
fn lit_by_contour<K: Kernel>(
    e: &AnyEmitter<f64>,
    receiver: &Receiver,
    kernel: &K,
    lit: &[Triangle],
) -> Option<Estimate<f64>> {
    let (x, n) = (receiver.point(), receiver.normal());
    let Some(first) = lit.first() else {
        return Some(Estimate::deterministic(0.0, 0.0, 0));
    };
    let y = first.vertices()[0];
    if e.normal_at(y).dot(&(x - y)) <= 0.0 {
        return Some(Estimate::deterministic(0.0, 0.0, 0));
    }
    let mut sum = 0.0;
    for t in lit {
        sum += exact::polygon_form_factor(x, n, &t.vertices()).ok()?;
    }
    let value = kernel.weight(n) * e.radiance() * PI * sum;
    let error = crate::whitted::intersect::gamma(8) * value.abs() * lit.len() as f64;
    Some(Estimate::deterministic(value, error, lit.len() as u64))
}

/// The pieces of a Phong lobe's cone about its mirror direction, cut at
/// the receiver's horizon ([`clipped::pieces`]), out to where `cos^n alpha`
/// falls below 1e-30 of its peak; `None` for other BRDFs or no viewer.
fn phong_cone(built: &Built) -> Result<Option<Vec<clipped::ClippedCone>>, QuadError> {
    let n = match built.brdf {
        Some(AnyBrdf::Phong(p)) => p.exponent(),
        Some(AnyBrdf::NormalizedPhong(p)) => p.exponent(),
        _ => return Ok(None),
    };
    let Some(wo) = built.toward_viewer else {
        return Ok(None);
    };
    let normal = built.receiver.normal();
    let mirror = normal * (2.0 * normal.dot(&wo)) - wo;
    // cos^n alpha_max = 1e-30, at most 90 degrees (the lobe is clamped there).
    let one_minus_cos = if n > 0.0 {
        (-(1e-30_f64.ln() / n).exp_m1()).min(1.0)
    } else {
        1.0
    };
    clipped::pieces(mirror.normalize(), normal, one_minus_cos).map(Some)
}

/// The lit part of planar emitter `k` seen from `x`, as triangles, when the
/// shadow boundaries can be computed: every blocker is a planar polygon
/// (rectangle or triangle occluder) whose plane separates `x` from the
/// whole light, so that a point `y` of the light is in its shadow exactly
/// when `y` is inside the wedge of planes through `x` and the blocker's
/// edges. The lit part, the light less each wedge, is cut into convex
/// pieces (`L - C = union_i L cap H_1 cap .. cap H_(i-1) cap not H_i` for
/// the wedge's half-spaces `H_i`), each fanned into triangles. `None` where
/// some blocker is another shape (a sphere, a disk, another emitter) or
/// straddles the light's side.
pub fn lit_triangles(scene: &Scene<f64>, x: Vec3, k: usize) -> Option<Vec<Triangle>> {
    let light = match scene.emitters().get(k)? {
        AnyEmitter::Rectangle(r) => {
            let s = r.shape();
            let (o, a, b) = (s.origin(), s.edge_u(), s.edge_v());
            vec![o, o + a, o + a + b, o + b]
        }
        AnyEmitter::Triangle(t) => t.shape().vertices().to_vec(),
        _ => return None,
    };
    let others = scene
        .emitters()
        .iter()
        .enumerate()
        .any(|(i, e)| i != k && e.occluder().is_some());
    if others {
        return None;
    }
    let mut pieces = vec![light.clone()];
    for o in scene.occluders() {
        let (corners, normal) = match o {
            Occluder::Rectangle(r) => {
                let (p, a, b) = (r.origin(), r.edge_u(), r.edge_v());
                (vec![p, p + a, p + a + b, p + b], r.normal())
            }
            Occluder::Triangle(t) => (t.vertices().to_vec(), t.normal()),
            _ => return None,
        };
        // The blocker's plane separates x from every corner of the light.
        let side = |p: Vec3| normal.dot(&(p - corners[0]));
        let sx = side(x);
        if !(sx != 0.0 && light.iter().all(|&p| side(p) * sx < 0.0)) {
            return None;
        }
        // Inward normals of the wedge's planes through x and each edge.
        let centroid = corners.iter().fold(Vec3::zeros(), |s, p| s + p) / corners.len() as f64;
        let planes: Vec<Vec3> = (0..corners.len())
            .map(|i| {
                let m = (corners[i] - x).cross(&(corners[(i + 1) % corners.len()] - x));
                if m.dot(&(centroid - x)) < 0.0 { -m } else { m }
            })
            .collect();
        let mut next = Vec::new();
        for piece in pieces {
            // A piece wholly outside one of the wedge's planes is wholly lit
            // by this blocker: kept whole, not cut by the other planes (each
            // cut across the light multiplied the pieces, so that 1000
            // small blockers took seconds and 10 000 ran for minutes).
            if planes
                .iter()
                .any(|m| piece.iter().all(|&p| m.dot(&(p - x)) <= 0.0))
            {
                next.push(piece);
                continue;
            }
            let mut inside = piece;
            for m in &planes {
                // The part outside this plane is lit; the rest goes on.
                let outside = clip(&inside, |p| -m.dot(&(p - x)));
                if outside.len() >= 3 {
                    next.push(outside);
                }
                inside = clip(&inside, |p| m.dot(&(p - x)));
                if inside.len() < 3 {
                    break;
                }
            }
        }
        pieces = next;
    }
    let mut triangles = Vec::new();
    for piece in &pieces {
        for i in 1..piece.len() - 1 {
            // Slivers of zero area (a cut through a corner) hold nothing.
            if let Ok(t) = Triangle::new(piece[0], piece[i], piece[i + 1]) {
                triangles.push(t);
            }
        }
    }
    Some(triangles)
}

/// The part of the convex polygon `poly` where `side >= 0` (Sutherland–
/// Hodgman against one plane).
fn clip(poly: &[Vec3], side: impl Fn(Vec3) -> f64) -> Vec<Vec3> {
    let mut out = Vec::with_capacity(poly.len() + 1);
    for (i, &a) in poly.iter().enumerate() {
        let b = poly[(i + 1) % poly.len()];
        let (sa, sb) = (side(a), side(b));
        if sa >= 0.0 {
            out.push(a);
        }
        if (sa >= 0.0) != (sb >= 0.0) {
            out.push(a + (b - a) * (sa / (sa - sb)));
        }
    }
    out
}

/// The estimate of `a` and `b` (two forms of one integral) with the smaller
/// error, its error widened to their difference where they disagree by
/// more than ten times their errors together (one of them missed a feature
/// its own estimate could not see).
fn cross_checked(a: Estimate<f64>, b: Estimate<f64>) -> Estimate<f64> {
    let (best, other) = if a.error <= b.error { (a, b) } else { (b, a) };
    let difference = (best.value - other.value).abs();
    let error = if difference > 10.0 * (best.error + other.error) {
        best.error.max(difference)
    } else {
        best.error
    };
    Estimate {
        error,
        evaluations: a.evaluations + b.evaluations,
        ..best
    }
}

/// The closed form of `q` in this scene (module documentation).
pub(super) fn closed_form(built: &Built, q: RenderingQuantity) -> Option<f64> {
    let scene = &built.scene;
    let emitters = scene.emitters();
    let apart = emitters.len() == 1 || emitters.iter().all(|e| e.at_infinity());
    if !scene.occluders().is_empty() || !apart {
        return None;
    }
    let irradiance = || -> Option<f64> {
        emitters
            .iter()
            .map(|e| irradiance_from(e, &built.receiver))
            .sum::<Option<f64>>()
    };
    if !q.reflected() {
        return irradiance();
    }
    let wo = built.receiver.frame().to_local(built.toward_viewer?);
    match built.brdf? {
        AnyBrdf::Lambert(b) => Some(b.albedo / PI * irradiance()?),
        AnyBrdf::Phong(p) => phong_under_environment(emitters, wo, p.exponent(), p.k_s),
        AnyBrdf::NormalizedPhong(p) => {
            let n = p.exponent();
            phong_under_environment(emitters, wo, n, p.k_s * (n + 2.0) / (2.0 * PI))
        }
        AnyBrdf::Ggx(_) => None,
    }
}

/// `int_H k max(0, cos alpha)^n cos theta dw L` under the environment alone
/// (`alpha` from the mirror direction of the local `wo`): `2 pi / (n + 2)`
/// at normal incidence, the clamped-cosine product for `n = 1`.
fn phong_under_environment(
    emitters: &[AnyEmitter<f64>],
    wo: Vec3,
    n: f64,
    scale: f64,
) -> Option<f64> {
    let [AnyEmitter::Environment(env)] = emitters else {
        return None;
    };
    let lobe = if wo.x == 0.0 && wo.y == 0.0 {
        exact::phong_albedo_normal(n).ok()?
    } else if n == 1.0 {
        // The mirror direction makes theta_o with the normal.
        exact::clamped_cosine_product(wo.x.hypot(wo.y).atan2(wo.z)).ok()?
    } else {
        return None;
    };
    Some(env.radiance() * scale * lobe)
}

/// `E` at the receiver from one emitter alone, when it has a closed form.
fn irradiance_from(e: &AnyEmitter<f64>, receiver: &Receiver) -> Option<f64> {
    let (x, n) = (receiver.point(), receiver.normal());
    // A planar light seen from its dark side (or edge on) sends nothing.
    let facing = |normal: Vec3, on_plane: Vec3| normal.dot(&(x - on_plane)) > 0.0;
    let l = e.radiance();
    match e {
        AnyEmitter::Rectangle(r) => {
            let s = r.shape();
            let (o, a, b) = (s.origin(), s.edge_u(), s.edge_v());
            if !facing(s.normal(), o) {
                return Some(0.0);
            }
            let f = exact::polygon_form_factor(x, n, &[o, o + a, o + a + b, o + b]).ok()?;
            Some(PI * l * f)
        }
        AnyEmitter::Triangle(t) => {
            let s = t.shape();
            let v = s.vertices();
            if !facing(s.normal(), v[0]) {
                return Some(0.0);
            }
            Some(PI * l * exact::polygon_form_factor(x, n, &v).ok()?)
        }
        AnyEmitter::Disk(d) => {
            let h = coaxial(d, x)?;
            if h < 0.0 {
                return Some(0.0);
            }
            // The receiver's normal along the axis, toward the disk or away.
            let axis = d.shape().frame().n;
            let cos = n.dot(&axis);
            if n.cross(&axis).norm() > 1e-15 {
                return None;
            }
            if cos > 0.0 {
                return Some(0.0);
            }
            Some(PI * l * exact::disk_coaxial(h, d.shape().radius()).ok()?)
        }
        AnyEmitter::Sphere(s) => {
            let sphere = s.shape();
            let to_centre = sphere.centre - x;
            let d = to_centre.norm();
            let cos_omega = (n.dot(&to_centre) / d).clamp(-1.0, 1.0);
            let e = exact::spherical_cap_irradiance(cos_omega, sphere.radius / d).ok()?;
            Some(l * e)
        }
        AnyEmitter::Environment(_) => Some(PI * l),
        AnyEmitter::Cap(c) => Some(l * cap_irradiance(c, n)?),
    }
}

/// `int_cap max(0, cos theta) dw` of a cap light for the receiver normal
/// `n`: Snyder's formula for a cap of half-angle up to `pi/2`, and for a
/// wider one `pi` less the formula for the complementary cap about `-axis`.
fn cap_irradiance(c: &CapLight<f64>, n: Vec3) -> Option<f64> {
    let cap = c.cap();
    let k = cap.one_minus_cos();
    let sin_alpha = (k * (2.0 - k)).max(0.0).sqrt();
    let cos_omega = n.dot(&cap.axis()).clamp(-1.0, 1.0);
    if k <= 1.0 {
        return exact::spherical_cap_irradiance(cos_omega, sin_alpha).ok();
    }
    if sin_alpha == 0.0 {
        return Some(PI);
    }
    Some(PI - exact::spherical_cap_irradiance(-cos_omega, sin_alpha).ok()?)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed form of a cap light wider than a hemisphere is `pi` less
    /// its complement's: a cap of half-angle `pi` is the environment.
    #[test]
    fn a_cap_light_of_half_angle_pi_is_the_environment() -> Result<(), QuadError> {
        let whole = CapLight::new(Vec3::new(0.3, 0.1, -1.0), PI, 1.0)?;
        let e = cap_irradiance(&whole, Vec3::z()).ok_or(QuadError::invalid("cap", 0, "a value"))?;
        assert!((e - PI).abs() < 1e-15, "{e}");
        // A cap of 3 pi / 4 about the normal misses only the lower directions.
        let wide = CapLight::new(Vec3::z(), 0.75 * PI, 1.0)?;
        let e = cap_irradiance(&wide, Vec3::z()).ok_or(QuadError::invalid("cap", 0, "a value"))?;
        assert!((e - PI).abs() < 1e-15, "{e}");
        Ok(())
    }
}
