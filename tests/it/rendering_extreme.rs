//! The rendering family on extreme geometry (issue 49): each case is a
//! bundled experiment with one field changed, and each value is checked
//! against a closed form written here (the coaxial disk, Lambert's contour
//! formula over the lit polygon clipped here), an exact zero (a light
//! hidden whole), or the same scene evaluated another way (linearity in the
//! radiance).

use std::f64::consts::PI;
use std::fs;

use crate::common::root;

use lightquad::domain::Vec3;
use lightquad::experiment::validate::{Experiment, deserialize, validate};
use lightquad::family::{Family, Method};
use lightquad::rendering::experiment::{Mis, Rendering, RenderingQuantity as Q};
use rand::SeedableRng;
use serde_json::{Value, json};

/// The bundled experiment `name` as JSON.
fn bundled(name: &str) -> Value {
    let text = fs::read_to_string(root().join(format!("experiments/{name}.json"))).expect("read");
    serde_json::from_str(&text).expect("json")
}

/// Validated, or the error's text.
fn try_load(json: Value) -> Result<Experiment<Rendering>, String> {
    let spec = deserialize::<Rendering>(json).map_err(|e| e.to_string())?;
    validate::<Rendering>(spec, "hash").map_err(|e| e.to_string())
}

fn load(json: Value) -> Experiment<Rendering> {
    try_load(json).expect("valid")
}

/// `q` by the rule `rule` at `budget`.
fn by(exp: &Experiment<Rendering>, rule: &str, budget: usize, q: Q) -> f64 {
    let method: Method<Mis> = serde_json::from_value(json!({ "rule": rule })).expect("a rule");
    let mut rng = rand_pcg::Pcg64::seed_from_u64(17);
    let out = Rendering::evaluate(&exp.scene, &method, budget, &mut rng, &[q]).expect("evaluates");
    out[&q].value[0]
}

/// The converged reference: value and evaluations.
fn converged(exp: &Experiment<Rendering>, q: Q) -> (f64, u64) {
    let out = Rendering::converged(&exp.scene, 400, &[q]).expect("converges");
    (out[&q].value[0], out[&q].evaluations)
}

/// The warnings' texts.
fn warnings(exp: &Experiment<Rendering>) -> Vec<String> {
    Rendering::warnings(&exp.scene)
        .iter()
        .map(|w| w.to_string())
        .collect()
}

fn v3(x: f64, y: f64, z: f64) -> Vec3 {
    Vec3::new(x, y, z)
}

/// Lambert's contour formula `E = L |sum theta_i (n . g_i)| / 2` for a
/// polygon above the receiver's horizon (`x` at the origin, `n = z`),
/// written out here; the cross products' norms are taken in a scaled form
/// so that corners at 1e24 do not overflow.
fn contour_e(corners: &[Vec3]) -> f64 {
    let mut sum = 0.0;
    for i in 0..corners.len() {
        let a = corners[i].normalize();
        let b = corners[(i + 1) % corners.len()].normalize();
        let c = a.cross(&b);
        let s = c.norm();
        if s > 0.0 {
            sum += s.atan2(a.dot(&b)) * c.z / s;
        }
    }
    sum.abs() / 2.0
}

/// The part of the convex polygon `poly` where `side >= 0`.
fn clip(poly: &[Vec3], side: impl Fn(Vec3) -> f64) -> Vec<Vec3> {
    let mut out = Vec::new();
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
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

/// r-shadow-boundary's light, `[-1, 1]^2` at height 2: its contour value
/// with nothing in the way.
fn square_light() -> f64 {
    contour_e(&[
        v3(-1.0, -1.0, 2.0),
        v3(-1.0, 1.0, 2.0),
        v3(1.0, 1.0, 2.0),
        v3(1.0, -1.0, 2.0),
    ])
}

/// The coaxial disk 1e-12 above the receiver fills its hemisphere but for
/// a band 1e-12 wide at the horizon: `E = pi / (1 + h^2) = pi` (Howell).
/// Every ray met the disk inside the old fixed offset (1e-10 of the scene's
/// size) and was not counted: E_cone and E_cosine were 0.
#[test]
fn a_disk_light_1e_12_above_the_receiver_is_seen() {
    for h in [1e-12, 1e-200] {
        let mut j = bundled("r-coaxial-disk-1e-3");
        j["scene"]["emitters"][0]["centre"][2] = json!(h);
        let exp = load(j);
        let want = PI / (1.0 + h * h);
        for q in [Q::ECone, Q::ECosine] {
            for rule in ["gauss-legendre", "genz-malik"] {
                let got = by(&exp, rule, 64, q);
                assert!((got - want).abs() < 1e-9, "h {h} {q:?} {rule}: {got}");
            }
        }
    }
}

/// An occluder 1e-12 above the receiver, over it, hides the whole light:
/// every form and the reference give exactly 0 (they gave 0.73-0.94).
#[test]
fn an_occluder_1e_12_above_the_receiver_hides_the_light() {
    for z in [1e-12, 1e-200] {
        let mut j = bundled("r-shadow-boundary");
        j["scene"]["occluders"][0]["origin"][2] = json!(z);
        let exp = load(j);
        for q in [Q::EArea, Q::ECone, Q::EHemisphere] {
            assert_eq!(by(&exp, "gauss-legendre", 64, q), 0.0, "z {z} {q:?}");
        }
        assert!(converged(&exp, Q::EArea).0.abs() < 1e-15, "z {z}");
    }
}

/// An occluder 1.2e23 long beside the light's cone blocks nothing: every
/// form gives the light's contour value (the cone and hemisphere forms
/// gave 0 with an estimate of 0).
#[test]
fn a_long_occluder_beside_the_receiver_blocks_nothing() {
    let mut j = bundled("r-shadow-boundary");
    j["scene"]["occluders"][0]["edge_u"] = json!([5.2, 1.2e23, 0.0]);
    let exp = load(j);
    let want = square_light();
    let got = by(&exp, "genz-malik", 4096, Q::EArea);
    assert!(
        ((got - want) / want).abs() < 1e-8,
        "E_area: {got} vs {want}"
    );
    // The cone (the light's bounding cone) and the hemisphere meet the
    // light's outline as a jump: within 1% at 4096 nodes.
    for q in [Q::ECone, Q::EHemisphere] {
        let got = by(&exp, "gauss-legendre", 4096, q);
        assert!(((got - want) / want).abs() < 1e-2, "{q:?}: {got} vs {want}");
    }
    let (reference, _) = converged(&exp, Q::EArea);
    assert!(((reference - want) / want).abs() < 1e-10, "{reference}");
}

/// A light 1.2e24 long: its lit part is the strip less the occluder's
/// shadow (the occluder's parallelogram scaled by 2 from the receiver onto
/// the light's plane), whose contour value is computed here. The cone
/// form and the reference reach it (the cone forms gave 0).
#[test]
fn a_long_light_is_seen_through_its_cone() {
    let mut j = bundled("r-shadow-boundary");
    j["scene"]["emitters"][0]["edge_v"][0] = json!(1.2e24);
    let exp = load(j);
    let far = 1.2e24 - 1.0;
    let strip = vec![
        v3(-1.0, -1.0, 2.0),
        v3(-1.0, 1.0, 2.0),
        v3(far, 1.0, 2.0),
        v3(far, -1.0, 2.0),
    ];
    // The shadow: 2 (o + a e_1 + b e_2) on z = 2, as four half-planes.
    let (o, e1, e2) = (v3(-5.0, -3.0, 2.0), v3(10.4, 6.0, 0.0), v3(-3.0, 5.2, 0.0));
    let across = |e: Vec3| v3(-e.y, e.x, 0.0);
    let (n1, n2) = (across(e1), across(e2));
    let s1 = n1.dot(&e2).signum();
    let s2 = n2.dot(&e1).signum();
    let mut shadow = strip.clone();
    shadow = clip(&shadow, |p| s1 * n1.dot(&(p - o)));
    shadow = clip(&shadow, |p| -s1 * n1.dot(&(p - o - e2)));
    shadow = clip(&shadow, |p| s2 * n2.dot(&(p - o)));
    shadow = clip(&shadow, |p| -s2 * n2.dot(&(p - o - e1)));
    let want = contour_e(&strip) - contour_e(&shadow);
    assert!(want > 0.5 && want < PI, "{want}");
    let got = by(&exp, "genz-malik", 4096, Q::ECone);
    assert!(
        ((got - want) / want).abs() < 1e-3,
        "E_cone: {got} vs {want}"
    );
    let (reference, _) = converged(&exp, Q::EArea);
    assert!(
        ((reference - want) / want).abs() < 1e-6,
        "{reference} vs {want}"
    );
    // The area form's peak, 2 / 1.2e24 of the map wide, is beyond f64's
    // resolution of the map: check warns at the light.
    let w = warnings(&exp);
    assert!(
        w.iter()
            .any(|w| w.contains("scene.emitters[0]") && w.contains("area form")),
        "{w:?}"
    );
}

/// An occluder in the plane of the light, over it, is no blocker in any
/// form (R-A's visibility is of what lies strictly between): every form
/// gives the unblocked contour value, and check warns at the occluder.
#[test]
fn an_occluder_coincident_with_the_light_blocks_in_no_form_and_is_warned() {
    let mut j = bundled("r-shadow-boundary");
    let light = j["scene"]["emitters"][0].clone();
    j["scene"]["occluders"][0] = json!({
        "type": "rectangle", "origin": light["origin"],
        "edge_u": light["edge_u"], "edge_v": light["edge_v"],
    });
    let exp = load(j);
    let w = warnings(&exp);
    assert!(
        w.iter()
            .any(|w| w.contains("scene.occluders[0]") && w.contains("plane")),
        "{w:?}"
    );
    let want = square_light();
    let got = by(&exp, "genz-malik", 4096, Q::EArea);
    assert!(
        ((got - want) / want).abs() < 1e-8,
        "E_area: {got} vs {want}"
    );
    // The cone (the light's bounding cone) and the hemisphere meet the
    // light's outline as a jump: within 1% at 4096 nodes.
    for q in [Q::ECone, Q::EHemisphere] {
        let got = by(&exp, "gauss-legendre", 4096, q);
        assert!(((got - want) / want).abs() < 1e-2, "{q:?}: {got} vs {want}");
    }
    let (reference, _) = converged(&exp, Q::EArea);
    assert!(((reference - want) / want).abs() < 1e-10, "{reference}");
}

/// A receiver inside a sphere occluder sees nothing of a light outside it:
/// the reference is exactly 0 (it was -1.1e-16, so every rule's 0 read as
/// a relative error of 1), every form gives 0, and check warns.
#[test]
fn a_receiver_inside_a_sphere_occluder_sees_nothing() {
    let mut j = bundled("r-shadow-boundary");
    j["scene"]["occluders"][0] =
        json!({"type": "sphere", "centre": [0.1, 0.0, 0.2], "radius": 1.0});
    let exp = load(j);
    let w = warnings(&exp);
    assert!(
        w.iter()
            .any(|w| w.contains("scene.occluders[0]") && w.contains("inside")),
        "{w:?}"
    );
    for q in [Q::EArea, Q::ECone, Q::EHemisphere] {
        assert_eq!(converged(&exp, q).0, 0.0, "{q:?}");
        assert_eq!(by(&exp, "gauss-legendre", 64, q), 0.0, "{q:?}");
    }
}

/// A radiance of 1e-320 (subnormal) or 0 adds nothing the reference must
/// chase: E is linear in each light's radiance, so the value is the one
/// without that light's term (to rounding), and it costs no more
/// evaluations than the bundled file (the reference ran over 300 s at
/// 1e-320, 34 s at 0, against 1.3 s).
#[test]
fn a_subnormal_or_zero_radiance_costs_the_reference_nothing_extra() {
    let bundled_file = load(bundled("mitsuba-r-three-lights"));
    let (_, plain) = converged(&bundled_file, Q::EArea);
    let with = |at: usize, radiance: f64| {
        let mut j = bundled("mitsuba-r-three-lights");
        j["scene"]["emitters"][at]["radiance"] = json!(radiance);
        converged(&load(j), Q::EArea)
    };
    let (zero, n_zero) = with(2, 0.0);
    let (tiny, n_tiny) = with(2, 1e-320);
    assert!(((tiny - zero) / zero).abs() < 1e-14, "{tiny} vs {zero}");
    assert!(
        n_tiny <= plain && n_zero <= plain,
        "{n_tiny} {n_zero} vs {plain}"
    );
    let (_, n_dark) = with(0, 0.0);
    assert!(n_dark <= plain, "{n_dark} vs {plain}");
}

/// 100 000 sphere lights: every shadow ray tests every light, so a job
/// costs about 1e5 times its budget per light; check refuses it with the
/// estimate (it ran without printing for 180 s).
#[test]
fn a_hundred_thousand_sphere_lights_are_refused_at_check() {
    let mut j = bundled("mitsuba-r-three-lights");
    let lights: Vec<Value> = (0..100_000)
        .map(|i| {
            let (a, b) = ((i % 400) as f64, (i / 400) as f64);
            json!({"type": "sphere", "centre": [a - 200.0, b - 125.0, 50.0], "radius": 0.1, "radiance": 1.0})
        })
        .collect();
    j["scene"]["emitters"] = Value::Array(lights);
    let Err(err) = try_load(j) else {
        panic!("100 000 sphere lights accepted")
    };
    assert!(
        err.contains("budgets") || err.contains("reference.n"),
        "{err}"
    );
    assert!(err.contains("evaluations"), "{err}");
}

/// 2500 small triangles at height 1 in a 50 x 50 grid between the
/// receiver and r-shadow-boundary's light: their shadows on the light (the
/// corners scaled by 2 from the receiver at the origin) lie inside it and
/// apart, so `E = E_light - sum_i E(shadow_i)`, each by the contour formula
/// here. (The reference cut the light by every plane of every blocker's
/// wedge, far from the wedge too: the pieces multiplied, 1000 blockers took
/// seconds and 10 000 ran for minutes at 335 MB; a probe saw 5.5 GB. Pieces
/// outside a wedge are now kept whole: their sum must stay exact.)
#[test]
fn many_small_blockers_leave_the_reference_exact() {
    let mut e = bundled("r-shadow-boundary");
    let (side, step) = (0.008, 0.0198);
    let mut occluders = Vec::new();
    let mut shadows = 0.0;
    for i in 0..50 {
        for j in 0..50 {
            let (x, y) = (-0.495 + i as f64 * step, -0.495 + j as f64 * step);
            let corners = [v3(x, y, 1.0), v3(x + side, y, 1.0), v3(x, y + side, 1.0)];
            shadows += contour_e(&corners.map(|c| c * 2.0));
            let [a, b, c] = corners.map(|c| [c.x, c.y, c.z]);
            occluders.push(json!({"type": "triangle", "a": a, "b": b, "c": c}));
        }
    }
    e["scene"]["occluders"] = Value::Array(occluders);
    let exp = load(e);
    let exact = square_light() - shadows;
    let (value, _) = converged(&exp, Q::EArea);
    assert!(
        (value - exact).abs() <= 1e-9 * exact,
        "reference {value} against {exact} (the light {}, its shadows {shadows})",
        square_light()
    );
}

/// A disk occluder of radius 0.5 at height h = 1e-15 .. 1e-300 over the
/// receiver, under a coaxial disk light of radius 1 at height 1: every ray
/// to the light leaves within 45 degrees and crosses the occluder's plane
/// at a radius of at most h, inside it: E = 0 exactly. The reference took a
/// blocker within 1e-14 of its size of the receiver for edge on and gave
/// pi/2, the light unoccluded, while every rule gave 0.
#[test]
fn a_disk_occluder_just_above_the_receiver_hides_the_light_in_the_reference() {
    for h in [1e-15, 1e-100, 1e-300] {
        let e = json!({
            "name": "oc", "family": "rendering",
            "scene": {
                "receiver": {"point": [0, 0, 0], "normal": [0, 0, 1]},
                "emitters": [{"type": "disk", "centre": [0, 0, 1], "normal": [0, 0, -1],
                              "radius": 1.0, "radiance": 1.0}],
                "occluders": [{"type": "disk", "centre": [0, 0, h], "normal": [0, 0, 1],
                               "radius": 0.5}]
            },
            "quantities": ["E_area", "E_cosine"], "rules": [{"rule": "gauss-legendre"}],
            "budgets": [64], "repeats": 1, "reference": {"type": "converged"}
        });
        let exp = load(e);
        for q in [Q::EArea, Q::ECosine] {
            let (value, _) = converged(&exp, q);
            assert_eq!(value, 0.0, "h = {h:e}, {q:?}");
            assert_eq!(by(&exp, "gauss-legendre", 64, q), 0.0, "h = {h:e}, {q:?}");
        }
    }
}
