//! The exchange family (light between two surfaces) through the experiment
//! layer: every form against Howell's closed forms (C-11, C-14, C-41, whose
//! formulas tests/it/exchange_exact.rs checks against mpmath), the shared
//! edge's singular kernel to 1e-10 by the contour form, reciprocity with
//! the receiver and the emitter swapped, the occluded pair's converged
//! reference against Gauss–Legendre split at the penumbra's kink, and bad
//! scenes named at their JSON paths.

use std::f64::consts::PI;

use lightquad::exact::rendering::{parallel_rectangles, perpendicular_rectangles};
use lightquad::experiment::validate::{deserialize, validate};
use lightquad::family::{Family, Method};
use lightquad::quadrature::{GaussLegendre, Rule};
use lightquad::rendering::exchange::{Built, Exchange, ExchangeQuantity as Q};
use serde_json::{Value, json};

use crate::common::{rel, rng};

fn scene(v: Value) -> Built {
    Exchange::build(&serde_json::from_value(v).expect("spec")).expect("builds")
}

fn rect(o: [f64; 3], u: [f64; 3], v: [f64; 3]) -> Value {
    json!({"type": "rectangle", "origin": o, "edge_u": u, "edge_v": v})
}

fn light(mut shape: Value, radiance: f64) -> Value {
    shape["radiance"] = json!(radiance);
    shape
}

fn floor() -> Value {
    rect([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
}

/// The unit floor and a unit square facing it at height `c`.
fn opposed(c: f64) -> Value {
    json!({"receiver": floor(),
           "emitters": [light(rect([0.0, 0.0, c], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]), 2.0)]})
}

/// The unit floor receiving from a unit wall on its edge along y.
fn perpendicular() -> Value {
    json!({"receiver": floor(),
           "emitters": [light(rect([0.0; 3], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]), 1.0)]})
}

fn gl() -> Method<lightquad::rendering::exchange::ExchangeMis> {
    serde_json::from_str(r#"{"rule": "gauss-legendre"}"#).expect("rule")
}

fn by(
    built: &Built,
    method: &Method<lightquad::rendering::exchange::ExchangeMis>,
    n: usize,
    q: Q,
) -> f64 {
    let out = Exchange::evaluate(built, method, n, &mut rng(1), &[q]).expect("evaluates");
    let v = out[&q].value[0];
    assert!(v.is_finite(), "{q:?} at {n}: {v}");
    v
}

#[test]
fn every_value_is_the_closed_form_factor_scaled_and_the_forms_converge_to_it() {
    let built = scene(opposed(1.0));
    let f = parallel_rectangles(1.0, 1.0, 1.0).expect("C-11");
    let closed = |q| Exchange::closed_form(&built, q).expect("closed")[0];
    assert!(rel(closed(Q::FArea), f) < 1e-14);
    // Phi = pi L A_r F, E_mean = pi L F (L = 2, A_r = 1).
    assert!(rel(closed(Q::PhiCone), PI * 2.0 * f) < 1e-14);
    assert!(rel(closed(Q::EMeanContour), PI * 2.0 * f) < 1e-14);
    // The smooth 4-D area form and the 2-D contour form by Gauss–Legendre.
    assert!(rel(by(&built, &gl(), 65536, Q::FArea), f) < 1e-13);
    assert!(rel(by(&built, &gl(), 1024, Q::FContour), f) < 1e-13);
    // The cone form's integrand jumps at the light's outline: slow, but it
    // gets there.
    assert!(rel(by(&built, &gl(), 262_144, Q::FCone), f) < 5e-2);
}

#[test]
fn the_stiff_pairs_reach_their_closed_forms_by_the_contour_form() {
    // Opposed at 0.1 of their side (C-11, F = 0.827).
    let near = scene(opposed(0.1));
    let f = parallel_rectangles(1.0, 1.0, 0.1).expect("C-11");
    assert!(rel(by(&near, &gl(), 16384, Q::FContour), f) < 1e-10);
    // Sharing an edge (C-14): the kernel is singular along it, and the
    // contour form's point form factor is not (it tends to 1/2 there), so
    // Gauss–Legendre gets it to 1e-10.
    let edge = scene(perpendicular());
    let f = perpendicular_rectangles(1.0, 1.0, 1.0).expect("C-14");
    let closed = Exchange::closed_form(&edge, Q::FArea).expect("closed")[0];
    assert!(rel(closed, f) < 1e-13, "{closed} vs {f}");
    assert!(rel(by(&edge, &gl(), 16384, Q::FContour), f) < 1e-10);
    let converged = Exchange::converged(&edge, 400, &[Q::FContour]).expect("converged");
    assert!(rel(converged[&Q::FContour].value[0], f) < 1e-10);
    // The area form is off by far more at the same budget, but finite.
    let area = by(&edge, &gl(), 16384, Q::FArea);
    assert!(rel(area, f) > 1e-3, "{area}");
}

#[test]
fn reciprocity_holds_with_the_receiver_and_the_emitter_swapped() {
    // A_1 F_12 = A_2 F_21 for an unequal perpendicular pair (floor 1 x 2,
    // wall 1 x 0.5), and for a tilted triangle over a parallelogram.
    let floor2 = rect([0.0; 3], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    let wall = rect([0.0; 3], [0.0, 1.0, 0.0], [0.0, 0.0, 0.5]);
    let tri = json!({"type": "triangle", "a": [0.2, 0.1, 0.7], "b": [0.4, 1.2, 0.9],
                     "c": [1.1, 0.4, 1.3]});
    let para = rect([0.0; 3], [1.0, 0.0, 0.0], [0.3, 0.8, 0.0]);
    for (r1, r2) in [(floor2, wall), (para, tri)] {
        let forward = scene(json!({"receiver": r1, "emitters": [light(r2.clone(), 1.0)]}));
        let back = scene(json!({"receiver": r2, "emitters": [light(r1.clone(), 1.0)]}));
        let (a1, a2) = (forward.receiver.area(), back.receiver.area());
        let f12 = Exchange::closed_form(&forward, Q::FArea).expect("closed")[0];
        let f21 = Exchange::closed_form(&back, Q::FArea).expect("closed")[0];
        assert!(rel(a1 * f12, a2 * f21) < 1e-12, "{f12} {f21}");
        // The converged references at n = 4000 (the bundled default), each on
        // its own side's contour form.
        let c12 = Exchange::converged(&forward, 4000, &[Q::FContour]).expect("converged");
        let c21 = Exchange::converged(&back, 4000, &[Q::FContour]).expect("converged");
        let (c12, c21) = (c12[&Q::FContour].value[0], c21[&Q::FContour].value[0]);
        assert!(rel(a1 * c12, a2 * c21) < 1e-12, "{c12} {c21}");
        assert!(rel(c12, f12) < 1e-12, "{c12} vs {f12}");
    }
}

#[test]
fn coaxial_disks_by_every_form_and_an_offset_pair_by_two() {
    let disk = |c: [f64; 3], n: [f64; 3], r: f64| json!({"type": "disk", "centre": c, "normal": n, "radius": r});
    let built = scene(json!({"receiver": disk([0.0; 3], [0.0, 0.0, 1.0], 1.0),
        "emitters": [light(disk([0.0, 0.0, 0.2], [0.0, 0.0, -1.0], 0.5), 1.0)]}));
    let f = lightquad::exact::exchange::coaxial_disks(1.0, 0.5, 0.2).expect("C-41");
    assert!(
        rel(
            Exchange::closed_form(&built, Q::FArea).expect("closed")[0],
            f
        ) < 1e-14
    );
    assert!(rel(by(&built, &gl(), 16384, Q::FContour), f) < 1e-6);
    let converged = Exchange::converged(&built, 400, &[Q::FContour]).expect("converged");
    assert!(rel(converged[&Q::FContour].value[0], f) < 1e-10);
    let area = by(&built, &gl(), 262_144, Q::FArea);
    assert!(rel(area, f) < 1e-2, "{area} vs {f}");
    // Off the axis there is no pair formula: Howell's element-to-disk
    // formula integrated over the receiver against the area form.
    let offset = scene(json!({"receiver": disk([0.0; 3], [0.0, 0.0, 1.0], 1.0),
        "emitters": [light(disk([0.7, 0.2, 0.6], [0.0, 0.0, -1.0], 0.5), 1.0)]}));
    assert!(Exchange::closed_form(&offset, Q::FArea).is_none());
    let contour = Exchange::converged(&offset, 400, &[Q::FContour]).expect("converged");
    let contour = contour[&Q::FContour].value[0];
    let area = by(&offset, &gl(), 262_144, Q::FArea);
    assert!(rel(area, contour) < 1e-6, "{area} vs {contour}");
}

#[test]
fn the_occluded_pairs_reference_agrees_with_gauss_legendre_split_at_the_kink() {
    // An opaque unit square halfway up, shifted by (0.25, -0.5): from the
    // receiver point (x, y) its shadow on the light covers x' in [0.5 - x,
    // 2.5 - x], y' in [-1 - y, 1 - y], so the point form factor kinks only
    // where x = 0.5 on the receiver.
    let mut s = opposed(1.0);
    s["occluders"] = json!([rect([0.25, -0.5, 0.5], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])]);
    let built = scene(s);
    assert!(Exchange::closed_form(&built, Q::FArea).is_none());
    let converged = Exchange::converged(&built, 400, &[Q::FContour]).expect("converged");
    let reference = converged[&Q::FContour].value[0];
    let t = built.transport();
    let rule = GaussLegendre::default();
    let mut split = 0.0;
    for (x0, x1) in [(0.0, 0.5), (0.5, 1.0)] {
        let half = rule
            .integrate(4096, &mut rng(0), |[u, v]: [f64; 2]| {
                let x = lightquad::domain::Vec3::new(x0 + (x1 - x0) * u, v, 0.0);
                t.point_factor(0, x).expect("closed at every point") * (x1 - x0)
            })
            .expect("integrates");
        split += half.value;
    }
    assert!(rel(reference, split) < 1e-12, "{reference} vs {split}");
    // And against the 4-D area form, which sees the occluder by shadow
    // rays: Sobol' at 2^20 points.
    let sobol: Method<lightquad::rendering::exchange::ExchangeMis> =
        serde_json::from_str(r#"{"rule": "sobol"}"#).expect("rule");
    let area = by(&built, &sobol, 1 << 20, Q::FArea);
    assert!(rel(area, reference) < 2e-3, "{area} vs {reference}");
}

fn file(scene: Value, quantities: Value) -> Value {
    json!({"name": "x", "family": "exchange", "scene": scene, "quantities": quantities,
        "rules": [{"rule": "gauss-legendre"}], "budgets": [16], "repeats": 1,
        "reference": {"type": "converged"}})
}

fn refused(scene: Value, quantities: Value) -> String {
    deserialize(file(scene, quantities))
        .and_then(|spec| validate::<Exchange>(spec, "h"))
        .map(|_| ())
        .expect_err("refused")
        .to_string()
}

fn warned(scene: Value) -> String {
    let built = Exchange::build(&serde_json::from_value(scene).expect("spec")).expect("builds");
    Exchange::warnings(&built)
        .iter()
        .map(|w| w.to_string())
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn bad_scenes_are_named_at_their_paths_and_doubtful_ones_warned() {
    let sphere = json!({"type": "sphere", "centre": [0, 0, 2], "radius": 0.5, "radiance": 1});
    let msg = refused(
        json!({"receiver": floor(), "emitters": [sphere]}),
        json!(["F_area"]),
    );
    assert!(msg.contains("scene.emitters[0].type"), "{msg}");
    let msg = refused(
        json!({"receiver": floor(), "emitters": []}),
        json!(["F_area"]),
    );
    assert!(msg.contains("scene.emitters"), "{msg}");
    let flat = rect([0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]);
    let msg = refused(
        json!({"receiver": flat, "emitters": [light(floor(), 1.0)]}),
        json!(["F_area"]),
    );
    assert!(msg.contains("scene.receiver"), "{msg}");
    let msg = refused(
        json!({"receiver": {"type": "sphere", "centre": [0, 0, 0], "radius": 1},
               "emitters": [light(floor(), 1.0)]}),
        json!(["F_area"]),
    );
    assert!(
        msg.contains("scene.receiver") && msg.contains("sphere"),
        "{msg}"
    );
    // The contour form without its point formula: a tilted disk light.
    let tilted = json!({"type": "disk", "centre": [0.5, 0.5, 1.0], "normal": [0.3, 0.0, -1.0],
                        "radius": 0.3, "radiance": 1.0});
    let msg = refused(
        json!({"receiver": floor(), "emitters": [tilted.clone()]}),
        json!(["F_contour"]),
    );
    assert!(
        msg.contains("quantities[0]") && msg.contains("not parallel"),
        "{msg}"
    );
    // ... which the other forms take.
    let built = scene(json!({"receiver": floor(), "emitters": [tilted]}));
    assert!(by(&built, &gl(), 256, Q::FArea) > 0.0);
    // A light facing away, one in the receiver's plane, one behind it.
    let up = light(rect([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]), 1.0);
    let w = warned(json!({"receiver": floor(), "emitters": [up]}));
    assert!(
        w.contains("scene.emitters[0]") && w.contains("faces away"),
        "{w}"
    );
    let beside = light(rect([2.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]), 1.0);
    let w = warned(json!({"receiver": floor(), "emitters": [beside]}));
    assert!(w.contains("receiver's plane"), "{w}");
    let below = light(
        rect([0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        1.0,
    );
    let w = warned(json!({"receiver": floor(), "emitters": [below]}));
    assert!(w.contains("behind the receiver"), "{w}");
    // Crossing the receiver: warned, and every form finite.
    let across = light(
        rect([0.5, 0.0, -0.5], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
        1.0,
    );
    let s = json!({"receiver": floor(), "emitters": [across]});
    let w = warned(s.clone());
    assert!(w.contains("crosses the receiver"), "{w}");
    let built = scene(s);
    for q in [Q::FArea, Q::FCone, Q::FContour] {
        for rule in ["gauss-legendre", "trapezoid", "genz-malik", "sobol"] {
            let m: Method<lightquad::rendering::exchange::ExchangeMis> =
                serde_json::from_value(json!({"rule": rule})).expect("rule");
            by(&built, &m, 256, q);
        }
    }
}

#[test]
fn the_shared_edge_carries_the_limit_one_half_so_closed_rules_converge_at_their_order() {
    let edge = scene(perpendicular());
    let t = edge.transport();
    // On the shared edge (x = 0), F -> 1/2 from inside the floor.
    for y in [0.25, 0.5, 0.75] {
        let f = t
            .point_factor(0, lightquad::domain::Vec3::new(0.0, y, 0.0))
            .expect("closed");
        assert!((f - 0.5).abs() < 1e-15, "{y}: {f}");
    }
    // The trapezoid rule's error on the contour form then falls at order 2
    // in the points per axis (it was first order with 0 on the edge).
    let f = perpendicular_rectangles(1.0, 1.0, 1.0).expect("C-14");
    let trapezoid: Method<lightquad::rendering::exchange::ExchangeMis> =
        serde_json::from_str(r#"{"rule": "trapezoid"}"#).expect("rule");
    let e1 = rel(by(&edge, &trapezoid, 65 * 65, Q::FContour), f);
    let e2 = rel(by(&edge, &trapezoid, 129 * 129, Q::FContour), f);
    let order = (e1 / e2).log2();
    assert!(order > 1.8, "{e1:e} {e2:e}: order {order}");
}

#[test]
fn mis_estimates_agree_with_the_references_within_their_standard_errors() {
    let mut occluded = opposed(1.0);
    occluded["occluders"] = json!([rect([0.25, -0.5, 0.5], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])]);
    for (s, closed) in [
        (opposed(1.0), true),
        (occluded, false),
        (perpendicular(), true),
    ] {
        let built = scene(s);
        let want = if closed {
            Exchange::closed_form(&built, Q::FArea).expect("closed")[0]
        } else {
            Exchange::converged(&built, 400, &[Q::FArea]).expect("converged")[&Q::FArea].value[0]
        };
        for (rule, q, scale) in [
            ("mis-balance", Q::FArea, 1.0),
            ("mis-power", Q::FCone, 1.0),
            ("mis-balance", Q::PhiArea, PI * 2.0),
            ("mis-power", Q::EMeanCone, PI * 2.0),
        ] {
            let m: Method<lightquad::rendering::exchange::ExchangeMis> =
                serde_json::from_value(json!({"rule": rule})).expect("rule");
            let out = Exchange::evaluate(&built, &m, 1 << 16, &mut rng(3), &[q]).expect("runs");
            let (v, se) = (out[&q].value[0], out[&q].error[0]);
            let radiance =
                lightquad::rendering::emitter::Emitter::radiance(&built.scene.emitters()[0]);
            let want = want * if scale > 1.0 { PI * radiance } else { 1.0 };
            assert!(
                (v - want).abs() < 4.0 * se && se < 2e-2 * want,
                "{rule} {q:?}: {v} +- {se} vs {want}"
            );
        }
    }
    // The contour form has no light strategy to combine.
    let m: Method<lightquad::rendering::exchange::ExchangeMis> =
        serde_json::from_str(r#"{"rule": "mis-balance"}"#).expect("rule");
    assert!(Exchange::evaluate(&scene(opposed(1.0)), &m, 64, &mut rng(0), &[Q::FContour]).is_err());
}

#[test]
fn extreme_scales_and_degenerate_pairs_give_the_right_value_or_a_named_refusal() {
    let f = parallel_rectangles(1.0, 1.0, 1.0).expect("C-11");
    // The unit pair scaled by 1e80 and 1e-80: every length 1e80 (1e-80).
    for s in [1e80, 1e-80] {
        let built = scene(
            json!({"receiver": rect([0.0; 3], [s, 0.0, 0.0], [0.0, s, 0.0]),
            "emitters": [light(rect([0.0, 0.0, s], [0.0, s, 0.0], [s, 0.0, 0.0]), 1.0)]}),
        );
        assert!(rel(by(&built, &gl(), 1024, Q::FContour), f) < 1e-12, "{s}");
        assert!(rel(by(&built, &gl(), 65536, Q::FArea), f) < 1e-12, "{s}");
    }
    // Coplanar and overlapping: no light passes, the closed form is 0.
    let coplanar = scene(json!({"receiver": floor(),
        "emitters": [light(rect([0.5, 0.5, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]), 1.0)]}));
    assert_eq!(Exchange::closed_form(&coplanar, Q::FArea), Some(vec![0.0]));
    // Tiny squares far apart: the contour sum cancels, so no closed form
    // (the converged reference takes over).
    let far = scene(
        json!({"receiver": rect([0.0; 3], [1e-5, 0.0, 0.0], [0.0, 1e-5, 0.0]),
        "emitters": [light(rect([0.0, 0.0, 1.0], [0.0, 1e-5, 0.0], [1e-5, 0.0, 0.0]), 1.0)]}),
    );
    assert_eq!(Exchange::closed_form(&far, Q::FArea), None);
    let c = Exchange::converged(&far, 400, &[Q::FContour]).expect("converged");
    // C-11 at 60 digits (mpmath; the f64 formula itself cancels here).
    let want = 3.183_098_861_625_700_1e-11;
    assert!(
        rel(c[&Q::FContour].value[0], want) < 1e-12,
        "{:?} vs {want}",
        c[&Q::FContour]
    );
    // Below 1e-100 a patch is refused at its path.
    let msg = refused(
        json!({"receiver": rect([0.0; 3], [1e-101, 0.0, 0.0], [0.0, 1e-101, 0.0]),
               "emitters": [light(floor(), 1.0)]}),
        json!(["F_area"]),
    );
    assert!(
        msg.contains("scene.receiver") && msg.contains("1e-100"),
        "{msg}"
    );
    // An emitter 1e-12 above the receiver is not "in its plane", nor is a
    // unit light 1 above a receiver 1e12 wide.
    let close = json!({"receiver": floor(),
        "emitters": [light(rect([0.0, 0.0, 1e-12], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]), 1.0)]});
    assert_eq!(warned(close), "");
    let wide = json!({"receiver": rect([-5e11, -5e11, 0.0], [1e12, 0.0, 0.0], [0.0, 1e12, 0.0]),
        "emitters": [light(rect([0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]), 1.0)]});
    assert_eq!(warned(wide), "");
    // A long thin receiver crossed by a small light: warned.
    let thin = json!({"receiver": rect([0.0; 3], [1000.0, 0.0, 0.0], [0.0, 0.001, 0.0]),
        "emitters": [light(rect([0.5, -0.1, -0.1], [0.0, 0.2, 0.0], [0.0, 0.0, 0.2]), 1.0)]});
    assert!(warned(thin).contains("crosses the receiver"));
}

#[test]
fn the_library_refuses_polygons_that_are_not_simple_and_disks_stay_finite() {
    use lightquad::domain::Vec3;
    use lightquad::exact::exchange::{coaxial_disks, polygon_pair};
    let p = |x: f64, y: f64, z: f64| Vec3::new(x, y, z);
    let floor = [p(0., 0., 0.), p(1., 0., 0.), p(1., 1., 0.), p(0., 1., 0.)];
    let repeated = [
        p(0., 0., 1.),
        p(0., 1., 1.),
        p(0., 1., 1.),
        p(1., 1., 1.),
        p(1., 0., 1.),
    ];
    let eight = [p(0., 0., 1.), p(0., 0.5, 1.), p(2., 0., 1.), p(2., 1., 1.)];
    let twice = [
        p(0., 0., 1.),
        p(0., 1., 1.),
        p(1., 1., 1.),
        p(1., 0., 1.),
        p(0., 0., 1.),
        p(0., 1., 1.),
        p(1., 1., 1.),
        p(1., 0., 1.),
    ];
    for bad in [&repeated[..], &eight[..], &twice[..]] {
        match polygon_pair(&floor, bad) {
            Err(lightquad::QuadError::InvalidParameter { name, .. }) => assert_eq!(name, "to"),
            other => panic!("{bad:?}: {other:?}"),
        }
    }
    // A tiny disk under a huge one sees all of it; a huge one under a tiny
    // one sees r^2 / h^2 of it.
    assert!(rel(coaxial_disks(1e-200, 1.0, 1.0).expect("finite"), 0.5) < 1e-15);
    assert!(rel(coaxial_disks(1.0, 1e200, 1.0).expect("finite"), 1.0) < 1e-15);
    let tiny = coaxial_disks(1e200, 1.0, 1.0).expect("finite");
    assert!((0.0..1e-300).contains(&tiny), "{tiny}");
}

/// Runs `spec` (an experiment file) through the command line and returns
/// its summary's quantities by name: `quantity -> rule label -> rows`.
fn summary_rows(
    tag: &str,
    spec: Value,
) -> std::collections::BTreeMap<String, std::collections::BTreeMap<String, Vec<Value>>> {
    let dir = crate::common::scratch(tag);
    let path = dir.join("exp.json");
    std::fs::write(&path, spec.to_string()).expect("written");
    let o = crate::common::bin()
        .args(["run", path.to_str().expect("utf-8"), "--out"])
        .arg(dir.join("out"))
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", crate::common::stderr(&o));
    let name = spec["name"].as_str().expect("name");
    let text =
        std::fs::read_to_string(dir.join("out").join(name).join("summary.json")).expect("summary");
    let summary: Value = serde_json::from_str(&text).expect("json");
    let mut out = std::collections::BTreeMap::new();
    for q in summary["experiments"][0]["quantities"]
        .as_array()
        .expect("quantities")
    {
        let rules = q["rules"].as_array().expect("rules").iter().map(|r| {
            let rows = r["rows"].as_array().expect("rows").clone();
            (r["label"].as_str().expect("label").to_string(), rows)
        });
        out.insert(
            q["quantity"].as_str().expect("name").to_string(),
            rules.collect(),
        );
    }
    out
}

fn budgets_of(rows: &[Value]) -> Vec<u64> {
    rows.iter()
        .map(|r| r["budget"].as_u64().expect("budget"))
        .collect()
}

#[test]
fn a_rules_4d_minimum_does_not_hold_back_its_2d_contour_rows() {
    // Trapezoid needs 3^4 = 81 nodes in 4-D and 2^2 = 4 in 2-D; Genz–Malik
    // 57 in 4-D (2^4 + 2*4^2 + 8 + 1) and 17 in 2-D.
    let mut spec = file(perpendicular(), json!(["F_area", "F_contour"]));
    spec["name"] = json!("exchange-min-budget");
    spec["rules"] = json!([{"rule": "trapezoid"}, {"rule": "genz-malik"}]);
    spec["budgets"] = json!([16, 64, 256]);
    let rows = summary_rows("exchange-min-budget", spec);
    assert_eq!(budgets_of(&rows["F_contour"]["trapezoid"]), [16, 64, 256]);
    assert_eq!(budgets_of(&rows["F_area"]["trapezoid"]), [256]);
    assert_eq!(budgets_of(&rows["F_contour"]["genz-malik"]), [64, 256]);
    assert_eq!(budgets_of(&rows["F_area"]["genz-malik"]), [64, 256]);
    // The contour rows at 16 are values: C-14's 0.2000437950...
    let f = perpendicular_rectangles(1.0, 1.0, 1.0).expect("C-14");
    let v = rows["F_contour"]["trapezoid"][0]["value"][0]
        .as_f64()
        .expect("value");
    assert!(rel(v, f) < 0.1, "{v} against {f}");
}

#[test]
fn monte_carlo_on_the_infinite_variance_kernel_is_not_called_consistent() {
    // Along the shared edge the area form's kernel is ~1/r^2 in the 2-D
    // cross-section: its square is not integrable, so a sample variance is
    // carried by the few samples nearest the edge, and Monte Carlo flags it.
    let mut spec = file(perpendicular(), json!(["F_area"]));
    spec["name"] = json!("exchange-heavy-verdicts");
    spec["rules"] = json!([{"rule": "monte-carlo"}]);
    spec["budgets"] = json!([1024, 4096, 16384, 65536]);
    spec["repeats"] = json!(4);
    let rows = summary_rows("exchange-heavy-verdicts", spec);
    let mc = &rows["F_area"]["monte-carlo"];
    let doubted = |r: &Value| {
        r["flags"]
            .as_array()
            .expect("flags")
            .iter()
            .any(|f| f["kind"] == "unreliable-estimate")
    };
    let verdict = |r: &Value| {
        r["verdict"]["verdict"]
            .as_str()
            .expect("verdict")
            .to_string()
    };
    assert!(mc.iter().any(doubted), "no row flagged: {mc:?}");
    for r in mc.iter().filter(|r| doubted(r)) {
        assert_ne!(verdict(r), "consistent", "{r}");
    }
    assert!(mc.iter().any(|r| verdict(r) == "se-in-doubt"), "{mc:?}");
}
