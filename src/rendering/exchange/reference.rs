//! The exchange family's references: closed forms for one emitter in an
//! empty scene, and the converged evaluation on the smoothest form the
//! scene has.

use crate::domain::Vec3;
use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::exact::exchange::{coaxial_disks, polygon_pair};
use crate::rendering::emitter::AnyEmitter;
use crate::rendering::occluder::Occluder;

use super::forms::ExchangeForm;
use super::surface::Surface;
use super::{Built, CONVERGED_PER_N, converged_rule};

/// The corners of a polygon light, in order about its emitting normal.
pub(super) fn light_corners(e: &AnyEmitter<f64>) -> Option<Vec<Vec3>> {
    Surface::of_light(e)?.corners()
}

/// `F` from the receiver to the one emitter of an empty scene, where a
/// closed form exists (module documentation of the family) and is accurate
/// to 1e-12.
pub(super) fn closed_form_factor(built: &Built) -> Option<f64> {
    let [e] = built.scene.emitters() else {
        return None;
    };
    if !built.scene.occluders().is_empty() {
        return None;
    }
    if let (Some(from), Some(to)) = (built.receiver.corners(), light_corners(e)) {
        // Far apart or very unequal polygons cancel in the contour sum: no
        // closed form where its error passes 1e-12 of F.
        let f = polygon_pair(&from, &to).ok()?;
        let accurate = f.error <= 1e-12 * f.value.abs();
        return (accurate && (0.0..=1.0).contains(&f.value)).then_some(f.value);
    }
    let (Surface::Disk(r), AnyEmitter::Disk(d)) = (&built.receiver, e) else {
        return None;
    };
    let (n, m) = (r.frame().n, d.shape().frame().n);
    let axis = d.shape().centre() - r.centre();
    let h = n.dot(&axis);
    let off_axis = (axis - n * h).norm();
    let coaxial = off_axis <= 1e-14 * axis.norm() && (n + m).norm() <= 1e-14;
    (coaxial && h > 0.0)
        .then(|| coaxial_disks(r.radius(), d.shape().radius(), h).ok())
        .flatten()
}

/// Why the contour form cannot integrate this scene, or `None` where the
/// point form factor is closed at every receiver point.
pub(super) fn contour_lacks(built: &Built) -> Option<String> {
    let emitters = built.scene.emitters();
    let why = if emitters.len() != 1 {
        "it has more than one emitter (lights may shadow each other, and the point formula \
         takes one light)"
            .to_string()
    } else {
        match &emitters[0] {
            AnyEmitter::Disk(d) => {
                let (n, m) = (built.receiver.normal(), d.shape().frame().n);
                if !built.scene.occluders().is_empty() {
                    "its disk light has occluders in front of it (the point formula takes an \
                     unoccluded parallel disk)"
                        .to_string()
                } else if n.cross(&m).norm() > 1e-12 || n.dot(&m) > 0.0 {
                    "its disk light is not parallel to the receiver, facing it".to_string()
                } else {
                    return None;
                }
            }
            e => match separated(built, e) {
                Ok(()) => return None,
                Err(why) => why,
            },
        }
    };
    Some(format!(
        "the contour form needs the point form factor in closed form at every receiver point: \
         {why}; use the _area or _cone forms"
    ))
}

/// Whether every occluder is a polygon whose plane strictly separates the
/// whole receiver from the whole polygon light (where
/// [`crate::rendering::experiment::lit_triangles`] cuts the light exactly).
fn separated(built: &Built, e: &AnyEmitter<f64>) -> Result<(), String> {
    let light = light_corners(e).ok_or("its light is not a polygon")?;
    for (j, o) in built.scene.occluders().iter().enumerate() {
        let (p, n) = match o {
            Occluder::Rectangle(r) => (r.origin(), r.normal()),
            Occluder::Triangle(t) => (t.vertices()[0], t.normal()),
            _ => return Err(format!("occluder {j} is not a rectangle or triangle")),
        };
        let (hi, lo) = built.receiver.span_along(p, n);
        let sides: Vec<f64> = light.iter().map(|c| n.dot(&(c - p))).collect();
        let below = hi < 0.0 && sides.iter().all(|&s| s > 0.0);
        let above = lo > 0.0 && sides.iter().all(|&s| s < 0.0);
        if !(below || above) {
            return Err(format!(
                "the plane of occluder {j} does not separate the receiver from the light"
            ));
        }
    }
    Ok(())
}

/// The form the converged reference integrates: the contour form where the
/// scene has it, the area form otherwise.
pub(super) fn converged_form(built: &Built) -> ExchangeForm {
    if contour_lacks(built).is_none() {
        ExchangeForm::Contour
    } else {
        ExchangeForm::Area
    }
}

/// Its budget per emitter at `n`: `100 n` on the 2-D contour form, `1000 n`
/// on the 4-D area form.
pub(super) fn converged_budget(built: &Built, n: usize) -> usize {
    match converged_form(built) {
        ExchangeForm::Contour => CONVERGED_PER_N.saturating_mul(n),
        _ => CONVERGED_PER_N.saturating_mul(n).saturating_mul(10),
    }
}

/// `G_k` of every emitter by adaptive Genz–Malik on [`converged_form`].
pub(super) fn converged_exchange(built: &Built, n: usize) -> Result<Vec<Estimate<f64>>, QuadError> {
    let (form, budget) = (converged_form(built), converged_budget(built, n));
    let rule = converged_rule();
    let t = built.transport();
    let mut rng = <rand_pcg::Pcg64 as rand::SeedableRng>::seed_from_u64(0);
    (0..built.scene.emitters().len())
        .map(|k| t.integrate(form, k, &rule, budget, &mut rng))
        .collect()
}
