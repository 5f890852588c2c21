//! Ground truth for a scene built in code: a quantity of any family by its
//! closed form where the family has one, else by its converged
//! evaluation (doubled until it settles), with its accuracy: the same
//! references the reports measure errors against.
//!
//! ```
//! use lightquad::rendering::experiment::{Rendering, RenderingQuantity};
//! use lightquad::rendering::experiment::{
//!     DiskLightSpec, DiskSpec, EmitterSpec, OccluderSpec, ReceiverSpec, SceneSpec,
//! };
//! use lightquad::testing::truth;
//!
//! // Irradiance at the origin from a disk light of radius 1 at height 2,
//! // radiance 3: pi L r^2 / (h^2 + r^2) in closed form.
//! let receiver = ReceiverSpec { point: [0.0; 3], normal: [0.0, 0.0, 1.0], brdf: None, toward_viewer: None };
//! let disk = EmitterSpec::Disk(DiskLightSpec {
//!     centre: [0.0, 0.0, 2.0], normal: [0.0, 0.0, -1.0], radius: 1.0, radiance: 3.0,
//! });
//! let mut scene = SceneSpec { receiver, emitters: vec![disk], occluders: vec![] };
//! let open = truth::<Rendering>(&scene, RenderingQuantity::EArea, 1e-12)?;
//! let pi = std::f64::consts::PI;
//! assert!((open.value[0] - 3.0 * pi / 5.0).abs() < 1e-14);
//! // Half hidden by a disk occluder off the axis: no closed form, a converged value.
//! scene.occluders.push(OccluderSpec::Disk(DiskSpec {
//!     centre: [0.5, 0.0, 1.0], normal: [0.0, 0.0, 1.0], radius: 0.4,
//! }));
//! let hidden = truth::<Rendering>(&scene, RenderingQuantity::EArea, 1e-12)?;
//! assert!(hidden.value[0] < open.value[0] && hidden.accuracy[0] < 1e-10);
//! // Its evaluation does not split at the shadow's edge on the light, so it
//! // doubts its own error estimate, and says so.
//! assert!(!hidden.verified);
//! println!("{}", hidden.how);
//! # Ok::<(), lightquad::experiment::SpecError>(())
//! ```

use crate::experiment::SpecError;
use crate::experiment::reference::{CONVERGED_FLOOR, reference};
use crate::experiment::validate::{deserialize, validate};
use crate::family::{Family, Quantity};

/// The relative accuracy stated for a closed form: every family's closed
/// forms are checked against independent 30–50 digit evaluations (mpmath)
/// to this level in lightquad's tests.
pub const CLOSED_FORM_ACCURACY: f64 = 1e-12;

/// Nodes per smooth piece of the first converged evaluation.
const CONVERGED_N: usize = 64;

/// A quantity's true value, per channel.
#[derive(Debug, Clone, PartialEq)]
pub struct Truth {
    /// Per channel.
    pub value: Vec<f64>,
    /// Its absolute accuracy per channel.
    pub accuracy: Vec<f64>,
    /// False where a converged evaluation doubts its own error estimate
    /// (across a discontinuity it does not split at, such as an
    /// occluder's shadow edge on a light): `accuracy` is then its change
    /// between budgets, which can understate the error.
    pub verified: bool,
    /// How it was found, in a sentence.
    pub how: String,
}

/// `quantity` of the family `F`'s scene `scene`: its closed form where the
/// family has one (accurate to [`CLOSED_FORM_ACCURACY`] of its value),
/// else its converged evaluation, doubled until it changes by less than
/// `goal` (relative; never below [`CONVERGED_FLOOR`]). Errors name the
/// field of the scene (`scene.emitters[0].radius`) as the experiment
/// files' do; a converged evaluation that did not reach `goal` is an
/// error saying how far it got.
pub fn truth<F: Family>(
    scene: &F::SceneSpec,
    quantity: F::Quantity,
    goal: f64,
) -> Result<Truth, SpecError> {
    if !(goal.is_finite() && goal > 0.0) {
        return Err(SpecError::at(
            "goal",
            format!("{goal} is not a finite relative accuracy > 0"),
        ));
    }
    let built = F::build(scene)?;
    if let Some(why) = F::lacks(&built, quantity) {
        return Err(SpecError::at(
            "quantity",
            format!(
                "{} cannot be computed in this scene: {why}",
                quantity.name()
            ),
        ));
    }
    let channels = F::channels(&built, quantity);
    if let Some(value) = F::closed_form(&built, quantity)
        .filter(|v| v.len() == channels && v.iter().all(|x| x.is_finite()))
    {
        let accuracy = value
            .iter()
            .map(|x| CLOSED_FORM_ACCURACY * x.abs())
            .collect();
        return Ok(Truth {
            value,
            accuracy,
            verified: true,
            how: format!(
                "the closed form of {} ({} family)",
                quantity.name(),
                F::NAME
            ),
        });
    }
    converged::<F>(scene, quantity, goal.max(CONVERGED_FLOOR))
}

/// `json` without its null members: a spec writes an absent optional
/// field as `null`, which the files' reader (where absent means the
/// default) refuses.
fn without_nulls(json: &mut serde_json::Value) {
    match json {
        serde_json::Value::Object(map) => {
            map.retain(|_, v| !v.is_null());
            map.values_mut().for_each(without_nulls);
        }
        serde_json::Value::Array(items) => items.iter_mut().for_each(without_nulls),
        _ => {}
    }
}

/// The converged reference of a one-quantity experiment around `scene`.
fn converged<F: Family>(
    scene: &F::SceneSpec,
    quantity: F::Quantity,
    goal: f64,
) -> Result<Truth, SpecError> {
    let mut scene_json = serde_json::to_value(scene)
        .map_err(|e| SpecError::at("scene", format!("cannot be written as JSON: {e}")))?;
    without_nulls(&mut scene_json);
    let json = serde_json::json!({
        "name": "truth",
        "family": F::NAME,
        "scene": scene_json,
        "quantities": [quantity.name()],
        "rules": [{"rule": "gauss-legendre"}],
        "budgets": [CONVERGED_N],
        "reference": {"type": "converged", "n": CONVERGED_N},
        // The reference aims at a hundredth of the tightest target; a
        // target is below 1.
        "targets": [(goal * 100.0).min(0.5)],
    });
    let exp = validate(deserialize::<F>(json)?, "truth")?;
    let found = reference(&exp);
    let name = quantity.name();
    let (Some(value), Some(accuracy)) = (found.values.get(name), found.channel_accuracy.get(name))
    else {
        let why = found.missing.get(name).cloned().unwrap_or(found.note);
        return Err(SpecError::at(
            "quantity",
            format!("{name} has no reference: {why}"),
        ));
    };
    let relative = found.accuracy_of(name);
    if relative > goal {
        return Err(SpecError::at(
            "goal",
            format!(
                "the converged evaluation of {name} settled only to {relative:.1e} (relative), \
                 not {goal:.1e}: {}",
                found.note
            ),
        ));
    }
    Ok(Truth {
        value: value.clone(),
        accuracy: accuracy.clone(),
        verified: !found.unverified.iter().any(|q| q == name),
        how: format!(
            "the converged evaluation of {name} ({} family): {}",
            F::NAME,
            found.note
        ),
    })
}
