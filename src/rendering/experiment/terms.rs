//! What a scene evaluates, in words for the report: its emitters and
//! occluders, whether visibility is evaluated, and the forms and terms.

use crate::family;
use crate::rendering::emitter::{AnyEmitter, Emitter};

use super::reference::exact_cone;
use super::spec::{SceneSpec, needs_visibility};
use super::{Built, Form, RenderingQuantity};

pub(super) fn settings(spec: &SceneSpec) -> String {
    let (e, o) = (spec.emitters.len(), spec.occluders.len());
    let visibility = if needs_visibility(spec) {
        format!(
            "visibility V (R-A's shadow rays, the V of R-3P's g) evaluated: one shadow ray per \
             area-form evaluation whose other factors are non-zero, tested against {o} \
             occluder(s) and the other finite emitters"
        )
    } else {
        "visibility V (R-A's shadow rays, the V of R-3P's g) not evaluated: no occluder, and no \
         emitter can shadow another, so V = 1 and no shadow ray is cast"
            .to_string()
    };
    format!(
        "{e} emitter(s), {o} occluder(s); {visibility}; the R-H forms find L_i by one ray per \
         evaluation against the emitters and occluders (none where the kernel times cos theta \
         is 0); the cone and area forms spend the budget on each emitter; MIS draws one light \
         and one BRDF sample per unit of budget"
    )
}

/// The report's section on this scene: the forms and the terms each
/// evaluates.
pub(super) fn terms_section(built: &Built) -> String {
    use std::fmt::Write as _;
    let scene = &built.scene;
    let mut s = String::from("## Forms and terms of this scene\n\n");
    let names: Vec<&str> = scene
        .emitters()
        .iter()
        .map(|e| match e {
            AnyEmitter::Rectangle(_) => "rectangle",
            AnyEmitter::Disk(_) => "disk",
            AnyEmitter::Triangle(_) => "triangle",
            AnyEmitter::Sphere(_) => "sphere",
            AnyEmitter::Environment(_) => "environment",
            AnyEmitter::Cap(_) => "cap",
        })
        .collect();
    let cones: Vec<&str> = scene
        .emitters()
        .iter()
        .map(|e| {
            if exact_cone(e, &built.receiver) {
                "exact"
            } else {
                "bounding"
            }
        })
        .collect();
    let _ = writeln!(
        s,
        "Emitters: {} (cones from the receiver: {}); occluders: {}.\n",
        names.join(", "),
        cones.join(", "),
        scene.occluders().len()
    );
    let shadow: Vec<String> = scene
        .emitters()
        .iter()
        .enumerate()
        .map(|(k, e)| {
            let skip = if e.at_infinity() { None } else { Some(k) };
            if scene.has_blockers(skip) {
                format!("emitter {k}: tested")
            } else {
                format!("emitter {k}: not evaluated (nothing can block it; 0 shadow rays)")
            }
        })
        .collect();
    s.push_str("| quantity | form | domain | integrand | terms evaluated per node |\n");
    s.push_str("|---|---|---|---|---|\n");
    let brdf = built.brdf.is_some();
    let kernel = |q: RenderingQuantity| if q.reflected() { "f_r " } else { "" };
    for &q in <RenderingQuantity as family::Quantity>::all() {
        if q.reflected() && !brdf {
            continue;
        }
        let k = kernel(q);
        let (form, domain, integrand, terms) = match q.form() {
            Form::Hemisphere => (
                "R-H",
                "hemisphere, uniform map",
                format!("2 pi {k}L_i cos theta"),
                "L_i: one ray against every surface",
            ),
            Form::Cosine => (
                "R-H",
                "hemisphere, projected (Malley) map",
                format!("pi {k}L_i"),
                "L_i: one ray against every surface",
            ),
            Form::Brdf => (
                "R-H",
                "BRDF-sampled map",
                "f_r L_i cos theta / pdf".to_string(),
                "L_i: one ray against every surface",
            ),
            Form::Cone => (
                "R-H per emitter",
                "the emitter's cone of directions",
                format!("{k}L_i^k cos theta J"),
                "L_i^k: one ray against every surface",
            ),
            Form::Area => (
                "R-A (R-S, g of R-3P) per emitter",
                "the emitter's surface, its map's Jacobian",
                format!("L_e {k}cos theta cos theta' / r^2 V J"),
                "V: a shadow ray where tested (below)",
            ),
        };
        let name = family::Quantity::name(&q);
        let _ = writeln!(s, "| {name} | {form} | {domain} | {integrand} | {terms} |");
    }
    let _ = writeln!(
        s,
        "\nJ is the Jacobian of the domain's map. Visibility of the area forms: {}.",
        shadow.join("; ")
    );
    s
}
