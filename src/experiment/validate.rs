//! From a parsed [`ExperimentSpec`] to a runnable [`Experiment`]: every number
//! checked once, here, with the JSON path of the fault in the error.

use std::collections::BTreeMap;
use std::sync::Arc;

use thiserror::Error;

use super::spec::{
    Budgets, EmissionSpec, ExperimentSpec, MediumSpec, Quantity, ReferenceSpec, RuleSpec,
};
use crate::domain::Vec3;
use crate::error::QuadError;
use crate::exact::volume as exact;
use crate::geometry::Ray;
use crate::volume::{
    ConstantSphere, DirectionalLight, EmissionMap, GaussianBlob, GaussianBlobs, Medium,
    VolumeScene, linear_gradient::LinearGradient, voxel_grid::VoxelGrid,
};

/// Largest budget accepted (per smooth piece).
pub const MAX_BUDGET: i64 = 100_000_000;

/// A fault in an experiment file, at a JSON path.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("at `{path}`: {message}")]
pub struct SpecError {
    /// JSON path of the fault (`scene.medium.kappa`, `budgets[2]`, ...).
    pub path: String,
    /// What is wrong and what is accepted.
    pub message: String,
}

impl SpecError {
    /// An error at `path`.
    pub fn at(path: impl Into<String>, message: impl Into<String>) -> Self {
        SpecError {
            path: path.into(),
            message: message.into(),
        }
    }

    /// A library error re-anchored under `path` (the library names the field).
    fn from_quad(path: &str, e: QuadError) -> Self {
        let (field, message) = match &e {
            QuadError::InvalidParameter { name, .. } => (Some(name.clone()), e.to_string()),
            _ => (None, e.to_string()),
        };
        let path = match field {
            Some(f) if !path.ends_with(&f) => format!("{path}.{f}"),
            _ => path.to_string(),
        };
        SpecError { path, message }
    }
}

/// Parses an experiment file, naming the JSON path of any fault.
pub fn parse(text: &str) -> Result<ExperimentSpec, SpecError> {
    let de = &mut serde_json::Deserializer::from_str(text);
    let spec: ExperimentSpec = serde_path_to_error::deserialize(de).map_err(|e| {
        let path = e.path().to_string();
        SpecError::at(
            if path.is_empty() { ".".into() } else { path },
            e.inner().to_string(),
        )
    })?;
    Ok(spec)
}

/// A validated experiment, ready to run.
#[derive(Debug, Clone)]
pub struct Experiment {
    /// The file as parsed.
    pub spec: ExperimentSpec,
    /// The scene.
    pub scene: VolumeScene,
    /// The budgets, ascending.
    pub budgets: Vec<usize>,
    /// Reference values known before running (closed forms, literals); the
    /// converged reference is computed when the experiment runs.
    pub reference: BTreeMap<Quantity, f64>,
    /// Reference uncertainty (absolute).
    pub uncertainty: f64,
}

fn vec3(v: [f64; 3]) -> Vec3 {
    Vec3::new(v[0], v[1], v[2])
}

fn finite(path: &str, x: f64, accepted: &str) -> Result<f64, SpecError> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(SpecError::at(path, format!("{x} is not {accepted}")))
    }
}

fn medium(spec: &MediumSpec) -> Result<Arc<dyn Medium>, SpecError> {
    let at = "scene.medium";
    Ok(match spec {
        MediumSpec::ConstantSphere {
            centre,
            radius,
            kappa,
        } => Arc::new(
            ConstantSphere::new(vec3(*centre), *radius, *kappa)
                .map_err(|e| SpecError::from_quad(at, e))?,
        ),
        MediumSpec::GaussianBlobs { blobs } => Arc::new(
            GaussianBlobs::new(
                blobs
                    .iter()
                    .map(|b| GaussianBlob {
                        centre: vec3(b.centre),
                        amplitude: b.amplitude,
                        width: b.width,
                    })
                    .collect(),
            )
            .map_err(|e| SpecError::from_quad(at, e))?,
        ),
        MediumSpec::LinearGradient {
            centre,
            radius,
            base,
            gradient,
        } => Arc::new(
            LinearGradient::new(vec3(*centre), *radius, *base, vec3(*gradient))
                .map_err(|e| SpecError::from_quad(at, e))?,
        ),
        MediumSpec::VoxelGrid {
            min,
            max,
            resolution,
            data,
        } => Arc::new(
            VoxelGrid::new(vec3(*min), vec3(*max), *resolution, data.clone())
                .map_err(|e| SpecError::from_quad(at, e))?,
        ),
    })
}

/// Builds the scene, naming the path of any bad number.
fn scene(spec: &ExperimentSpec) -> Result<VolumeScene, SpecError> {
    let s = &spec.scene;
    let ray = Ray::new(vec3(s.ray.origin), vec3(s.ray.direction))
        .map_err(|e| SpecError::from_quad("scene.ray", e))?;
    let mut scene = VolumeScene::new(ray);
    if let Some(t) = s.t_min {
        scene.t_min = finite("scene.t_min", t, "a finite number")?;
    }
    if let Some(t) = s.t_max {
        if t.is_nan() || t < scene.t_min {
            return Err(SpecError::at(
                "scene.t_max",
                format!("{t} must be >= t_min = {} (t_f >= t_n)", scene.t_min),
            ));
        }
        scene.t_max = t;
    }
    if let Some(l) = s.lambda {
        if !(l.is_finite() && l >= 0.0) {
            return Err(SpecError::at(
                "scene.lambda",
                format!("{l} is not a finite number >= 0"),
            ));
        }
        scene.lambda = l;
    }
    scene.medium = s.medium.as_ref().map(medium).transpose()?;
    scene.emission = match s.emission {
        None => None,
        Some(EmissionSpec::Constant { c }) => Some(EmissionMap::Constant(finite(
            "scene.emission.c",
            c,
            "a finite number",
        )?)),
        Some(EmissionSpec::Proportional { k }) => Some(EmissionMap::Proportional(finite(
            "scene.emission.k",
            k,
            "a finite number",
        )?)),
    };
    if let Some(b) = s.background {
        if !(b.is_finite() && b >= 0.0) {
            return Err(SpecError::at(
                "scene.background",
                format!("{b} is not a finite radiance >= 0"),
            ));
        }
        scene.background = Some(b);
    }
    if let Some(l) = &s.light {
        scene.light = Some(
            DirectionalLight::new(vec3(l.toward_light), l.intensity, l.albedo)
                .map_err(|e| SpecError::from_quad("scene.light", e))?,
        );
    }
    Ok(scene)
}

fn budgets(spec: &Budgets) -> Result<Vec<usize>, SpecError> {
    let accepted = format!("an integer in 1..={MAX_BUDGET}");
    let check = |path: String, n: i64| -> Result<usize, SpecError> {
        if (1..=MAX_BUDGET).contains(&n) {
            Ok(n as usize)
        } else {
            Err(SpecError::at(path, format!("{n} is not {accepted}")))
        }
    };
    let mut out = match spec {
        Budgets::List(list) => {
            if list.is_empty() {
                return Err(SpecError::at(
                    "budgets",
                    "an empty list: give at least one budget",
                ));
            }
            list.iter()
                .enumerate()
                .map(|(i, &n)| check(format!("budgets[{i}]"), n))
                .collect::<Result<Vec<_>, _>>()?
        }
        Budgets::Range(r) => {
            let from = check("budgets.from".into(), r.from)?;
            let to = check("budgets.to".into(), r.to)?;
            if to < from {
                return Err(SpecError::at(
                    "budgets.to",
                    format!("{to} is below from = {from}"),
                ));
            }
            if !(r.factor.is_finite() && r.factor > 1.0) {
                return Err(SpecError::at(
                    "budgets.factor",
                    format!("{} is not a finite number > 1", r.factor),
                ));
            }
            // Each budget at least one above the last, so factors near 1
            // still advance; at most MAX_BUDGETS of them.
            const MAX_BUDGETS: usize = 200;
            let mut v = vec![from];
            loop {
                let last = v[v.len() - 1];
                let next = ((last as f64 * r.factor).round() as usize).max(last + 1);
                if next > to {
                    break;
                }
                if v.len() == MAX_BUDGETS {
                    return Err(SpecError::at(
                        "budgets.factor",
                        format!(
                            "{} gives more than {MAX_BUDGETS} budgets from {from} to {to}: use a larger factor",
                            r.factor
                        ),
                    ));
                }
                v.push(next);
            }
            v
        }
    };
    out.sort_unstable();
    out.dedup();
    Ok(out)
}

/// The closed form of a quantity for this scene, when `exact` has one.
pub fn closed_form(spec: &ExperimentSpec, scene: &VolumeScene, q: Quantity) -> Option<f64> {
    let ray = scene.ray;
    let tau = match &scene.medium {
        None => 1.0,
        Some(m) => (-scene.lambda * m.density_integral(&ray, scene.t_min, scene.t_max)?).exp(),
    };
    // The constant sphere's chord inside the looked-at part, and whether that
    // part holds the whole chord (the light closed forms need it).
    let sphere = match &spec.scene.medium {
        Some(MediumSpec::ConstantSphere { kappa, .. }) => scene
            .medium
            .as_ref()
            .and_then(|m| {
                m.support(&ray, scene.t_min, scene.t_max)
                    .first()
                    .map(|s| (s.start(), s.end()))
            })
            .map(|(a, b)| {
                (
                    scene.lambda * kappa,
                    b - a,
                    a > scene.t_min && b < scene.t_max,
                )
            }),
        _ => None,
    };
    let emission = || -> Option<f64> {
        let Some(map) = scene.emission else {
            return Some(0.0);
        };
        if scene.medium.is_none() {
            return Some(0.0);
        }
        let (sigma, chord, _) = sphere?;
        let kappa = if scene.lambda > 0.0 {
            sigma / scene.lambda
        } else {
            return None;
        };
        let c = match map {
            EmissionMap::Constant(c) => c,
            EmissionMap::Proportional(k) => k * kappa,
        };
        Some(exact::emission(sigma, chord, c))
    };
    let light = || -> Option<f64> {
        let Some(light) = scene.light else {
            return Some(0.0);
        };
        if scene.medium.is_none() {
            return Some(0.0);
        }
        let (sigma, chord, whole) = sphere?;
        if !whole {
            return None;
        }
        let cos = light.toward_light.dot(&ray.dir);
        if (cos - 1.0).abs() < 1e-12 {
            Some(exact::light_ahead(
                sigma,
                chord,
                light.intensity,
                light.albedo,
            ))
        } else if (cos + 1.0).abs() < 1e-12 {
            Some(exact::light_behind(
                sigma,
                chord,
                light.intensity,
                light.albedo,
            ))
        } else {
            None
        }
    };
    let background = scene.background.unwrap_or(0.0) * tau;
    match q {
        Quantity::Tau => Some(tau),
        Quantity::Background => Some(background),
        Quantity::Emission => emission(),
        Quantity::Light => light(),
        Quantity::Total => Some(emission()? + background + light()?),
    }
}

/// Validates a parsed experiment.
pub fn validate(spec: ExperimentSpec) -> Result<Experiment, SpecError> {
    if spec.name.is_empty()
        || !spec
            .name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
    {
        return Err(SpecError::at(
            "name",
            format!(
                "{:?} is not a name of letters, digits, '-' and '_'",
                spec.name
            ),
        ));
    }
    for (i, id) in spec.equations.iter().enumerate() {
        const KNOWN: [&str; 6] = ["V-tau", "V-E", "V-B", "V-Lp", "V-L", "V-I"];
        if !KNOWN.contains(&id.as_str()) {
            return Err(SpecError::at(
                format!("equations[{i}]"),
                format!(
                    "unknown equation ID {id:?}: expected one of {}",
                    KNOWN.join(", ")
                ),
            ));
        }
    }
    if spec.quantities.is_empty() {
        return Err(SpecError::at(
            "quantities",
            "an empty list: name at least one of tau, I_E, I_B, I_L, I",
        ));
    }
    if spec.rules.is_empty() {
        return Err(SpecError::at(
            "rules",
            "an empty list: name at least one rule",
        ));
    }
    for (i, r) in spec.rules.iter().enumerate() {
        match r {
            RuleSpec::GaussKronrod { abs_tol, rel_tol } => {
                for (name, t) in [("abs_tol", abs_tol), ("rel_tol", rel_tol)] {
                    if !(t.is_finite() && *t >= 0.0) {
                        return Err(SpecError::at(
                            format!("rules[{i}].{name}"),
                            format!("{t} is not a finite number >= 0"),
                        ));
                    }
                }
            }
            RuleSpec::Sobol { replicates } if *replicates < 2 => {
                return Err(SpecError::at(
                    format!("rules[{i}].replicates"),
                    format!("{replicates} is not an integer >= 2"),
                ));
            }
            _ => {}
        }
    }
    if !(1..=1000).contains(&spec.repeats) {
        return Err(SpecError::at(
            "repeats",
            format!("{} is not an integer in 1..=1000", spec.repeats),
        ));
    }
    for (i, t) in spec.targets.iter().enumerate() {
        if !(t.is_finite() && *t > 0.0 && *t < 1.0) {
            return Err(SpecError::at(
                format!("targets[{i}]"),
                format!("{t} is not a relative error in (0, 1)"),
            ));
        }
    }
    let scene = scene(&spec)?;
    let budgets = budgets(&spec.budgets)?;
    // Budgets below a rule's minimum are skipped for that rule; a rule left
    // with none is an error, so no rule silently disappears.
    let largest = budgets.last().copied().unwrap_or(0);
    for (i, r) in spec.rules.iter().enumerate() {
        if largest < r.min_budget() {
            return Err(SpecError::at(
                "budgets",
                format!(
                    "no budget reaches what rules[{i}] ({}) needs: at least {}",
                    r.name(),
                    r.min_budget()
                ),
            ));
        }
    }
    let (reference, uncertainty) = match &spec.reference {
        ReferenceSpec::ClosedForm {} => {
            let mut values = BTreeMap::new();
            for q in &spec.quantities {
                let Some(v) = closed_form(&spec, &scene, *q) else {
                    return Err(SpecError::at(
                        "reference",
                        format!(
                            "quantity {} has no closed form for this scene (closed forms: tau for the \
                             constant sphere, blobs and gradient; I_E for the constant sphere; I_L for \
                             the constant sphere with the light along the ray): use {{\"type\": \"converged\"}}",
                            q.name()
                        ),
                    ));
                };
                values.insert(*q, v);
            }
            (values, 0.0)
        }
        ReferenceSpec::Value {
            values,
            uncertainty,
        } => {
            for q in &spec.quantities {
                match values.get(q) {
                    Some(v) if v.is_finite() => {}
                    Some(v) => {
                        return Err(SpecError::at(
                            format!("reference.values.{}", q.name()),
                            format!("{v} is not finite"),
                        ));
                    }
                    None => {
                        return Err(SpecError::at(
                            "reference.values",
                            format!("no value for quantity {}", q.name()),
                        ));
                    }
                }
            }
            if !(uncertainty.is_finite() && *uncertainty >= 0.0) {
                return Err(SpecError::at(
                    "reference.uncertainty",
                    format!("{uncertainty} is not a finite number >= 0"),
                ));
            }
            (values.clone(), *uncertainty)
        }
        ReferenceSpec::Mitsuba { .. } => (BTreeMap::new(), 0.0),
        ReferenceSpec::Converged { n } => {
            if !(2..=100_000).contains(n) {
                return Err(SpecError::at(
                    "reference.n",
                    format!("{n} is not an integer in 2..=100000"),
                ));
            }
            (BTreeMap::new(), 0.0)
        }
    };
    Ok(Experiment {
        spec,
        scene,
        budgets,
        reference,
        uncertainty,
    })
}

/// Reads a Mitsuba values file for an experiment whose file hashes to `hash`:
/// the value and standard error per quantity, and a note for the report.
pub fn mitsuba_reference(
    path: &str,
    hash: &str,
    quantities: &[Quantity],
) -> Result<(BTreeMap<Quantity, f64>, f64, String), SpecError> {
    let at = "reference.file";
    let text = std::fs::read_to_string(path).map_err(|e| {
        SpecError::at(
            at,
            format!("{path}: {e} (run scripts/reference.sh to generate it)"),
        )
    })?;
    let json: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| SpecError::at(at, format!("{path}: {e}")))?;
    let file_hash = json["experiment_hash"].as_str().unwrap_or("");
    if file_hash != hash {
        return Err(SpecError::at(
            at,
            format!(
                "{path} is stale: it was made from an experiment file with hash {file_hash:?}, this one \
                 hashes to {hash:?}; regenerate it (scripts/reference.sh)"
            ),
        ));
    }
    let mut values = BTreeMap::new();
    let mut worst = 0.0f64;
    for q in quantities {
        let entry = &json["quantities"][q.name()];
        let (Some(v), Some(se)) = (entry["value"].as_f64(), entry["std_error"].as_f64()) else {
            return Err(SpecError::at(
                at,
                format!(
                    "{path} has no value for quantity {} (Mitsuba cannot compute it here?)",
                    q.name()
                ),
            ));
        };
        values.insert(*q, v);
        worst = worst.max(se);
    }
    let note = format!(
        "Mitsuba 3 ({} {}), largest standard error {worst:.1e}: errors below a few standard errors \
         (and the float32 floor of ~1e-6 relative) are not resolved.",
        json["mitsuba_variant"].as_str().unwrap_or("?"),
        json["mitsuba_version"].as_str().unwrap_or("?")
    );
    Ok((values, worst, note))
}
