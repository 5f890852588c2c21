//! The `integral` family: every domain's variables and measure against
//! closed forms written here, the infinite maps, RGB integrands, and every
//! fault refused at `check` with its JSON path and column, or failing its
//! job with the point named.

use std::f64::consts::PI;

use lightquad::experiment::validate::{deserialize, validate};
use lightquad::family::{Family, Measured, Method};
use lightquad::integral::{Integral, Quantity};
use lightquad::quadrature::AnyRule;
use rand::SeedableRng;
use serde_json::{Value as Json, json};

use crate::common::{bin, scratch, stderr};

/// An experiment of the family around `scene`.
fn experiment(scene: Json) -> Json {
    json!({
        "name": "t", "family": "integral", "scene": scene,
        "quantities": ["integral"], "rules": [{"rule": "gauss-legendre"}],
        "budgets": [16], "repeats": 1, "reference": {"type": "converged"}
    })
}

/// The built scene, or the validation error as text.
fn built(scene: Json) -> Result<lightquad::integral::Built, String> {
    deserialize(experiment(scene))
        .and_then(|spec| validate::<Integral>(spec, "h"))
        .map(|e| e.scene)
        .map_err(|e| e.to_string())
}

/// `rule` at budget `n` over `domain` of `integrand`.
fn integrate(domain: Json, integrand: &str, rule: &str, n: usize) -> Measured {
    let scene = built(json!({"domain": domain, "integrand": integrand}))
        .unwrap_or_else(|e| panic!("{integrand}: {e}"));
    let rule = AnyRule::by_name(rule).expect("rule");
    let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
    Integral::evaluate(
        &scene,
        &Method::Rule(rule),
        n,
        &mut rng,
        &[Quantity::Integral],
    )
    .unwrap_or_else(|e| panic!("{integrand}: {e}"))
    .remove(&Quantity::Integral)
    .expect("the integral")
}

/// The converged evaluation at `n`.
fn converged(domain: Json, integrand: &str, n: usize) -> Measured {
    let scene = built(json!({"domain": domain, "integrand": integrand}))
        .unwrap_or_else(|e| panic!("{integrand}: {e}"));
    Integral::converged(&scene, n, &[Quantity::Integral])
        .unwrap_or_else(|e| panic!("{integrand}: {e}"))
        .remove(&Quantity::Integral)
        .expect("the integral")
}

fn close(what: &str, got: f64, want: f64, tol: f64) {
    let err = (got - want).abs() / want.abs().max(1e-300);
    println!("{what}: {got:.17e} against {want:.17e} (relative {err:.1e})");
    assert!(
        err <= tol,
        "{what}: {got} against {want}: relative {err:e} > {tol:e}"
    );
}

/// Each surface, the hemisphere in its three measures and the pixel: the
/// variables are the point's coordinates (and angles) and the measure is
/// the one documented, against closed forms.
#[test]
fn every_domain_integrates_in_its_documented_measure() {
    let gl = |domain: Json, f: &str| integrate(domain, f, "gauss-legendre", 1024).value[0];
    // Rectangle in the plane z = 2 + x, [0, 2] x [0, 3] in (x, y): area
    // 6 sqrt(2); int z dA = sqrt(2) int (2 + x) dx dy = sqrt(2) (12 + 6).
    let rect =
        json!({"type": "rectangle", "origin": [0, 0, 2], "edge_u": [2, 0, 2], "edge_v": [0, 3, 0]});
    close(
        "rectangle area",
        gl(rect.clone(), "1"),
        6.0 * 2f64.sqrt(),
        1e-14,
    );
    close("rectangle z", gl(rect, "z"), 18.0 * 2f64.sqrt(), 1e-14);
    // Disk of radius 2 about the origin: int (x^2 + y^2) dA = pi R^4 / 2.
    let disk = json!({"type": "disk", "centre": [0, 0, 0], "normal": [0, 0, 1], "radius": 2});
    close("disk r^2", gl(disk, "x^2 + y^2"), PI * 16.0 / 2.0, 1e-13);
    // Triangle (0,0,0), (3,0,0), (0,4,0): area 6, centroid x = 1.
    let tri = json!({"type": "triangle", "a": [0, 0, 0], "b": [3, 0, 0], "c": [0, 4, 0]});
    close("triangle x", gl(tri, "x"), 6.0, 1e-13);
    // Sphere of radius 2: int z^2 dA = 4 pi R^4 / 3; int theta dA = 2 pi^2 R^2.
    let sphere = json!({"type": "sphere", "centre": [1, 1, 1], "radius": 2});
    close(
        "sphere z^2",
        gl(sphere.clone(), "(z - 1)^2"),
        4.0 * PI * 16.0 / 3.0,
        1e-13,
    );
    close(
        "sphere theta",
        gl(sphere, "theta"),
        2.0 * PI * PI * 4.0,
        1e-12,
    );
    // Cap of radius 1, cos_max 1/2 about +x: area 2 pi (1 - c) = pi; int
    // cos(theta) dA = pi (1 - c^2) = 3 pi / 4; x is cos(theta) there.
    let cap =
        json!({"type": "cap", "centre": [0, 0, 0], "axis": [1, 0, 0], "radius": 1, "cos_max": 0.5});
    close("cap area", gl(cap.clone(), "1"), PI, 1e-14);
    close(
        "cap cos theta",
        gl(cap.clone(), "cos(theta)"),
        0.75 * PI,
        1e-13,
    );
    close("cap x", gl(cap, "x"), 0.75 * PI, 1e-13);
    // Hemisphere: int cos(theta) d omega = pi in solid angle (uniform and
    // cosine maps); int 1 d omega_perp = pi in projected solid angle; phi
    // averages pi over [0, 2 pi): int phi cos(theta) d omega = pi^2. Tilted normal:
    // int (w . n) d omega = pi through x, y, z.
    for map in ["uniform", "cosine"] {
        let h = json!({"type": "hemisphere", "map": map});
        close(
            &format!("hemisphere {map} cos"),
            gl(h.clone(), "cos(theta)"),
            PI,
            1e-12,
        );
        // The cosine map's Jacobian pi / cos(theta) is infinite on the rim: its
        // integrands carry the cosine (src/domain/hemisphere.rs).
        close(
            &format!("hemisphere {map} phi cos"),
            gl(h, "phi*cos(theta)"),
            PI * PI,
            1e-12,
        );
    }
    close(
        "projected",
        gl(json!({"type": "hemisphere", "map": "projected"}), "1"),
        PI,
        1e-14,
    );
    let tilted = json!({"type": "hemisphere", "normal": [1, 1, 0]});
    close("tilted", gl(tilted, "(x + y)/sqrt(2)"), PI, 1e-12);
    // Pixel [1, 3] x [2, 5]: int x y = 4 * 10.5.
    let pixel = json!({"type": "pixel", "x0": 1, "y0": 2, "width": 2, "height": 3});
    close("pixel xy", gl(pixel, "x*y"), 42.0, 1e-14);
}

/// Boxes and cubes in 1 to 6 dimensions: `x1..xD` and the aliases `x, y, z`.
#[test]
fn boxes_take_every_dimension_to_six() {
    // int over [0,1]^D of prod (2 x_k) = 1; of x y z (D >= 3) = 1/8.
    let products = ["2*x1", "4*x1*x2", "8*x1*x2*x3", "16*x1*x2*x3*x4"];
    for (d, f) in products.iter().enumerate() {
        let cube = json!({"type": "cube", "dimension": d + 1});
        close(
            &format!("cube {}", d + 1),
            integrate(cube, f, "gauss-legendre", 4096).value[0],
            1.0,
            1e-14,
        );
    }
    let six = json!({"type": "cube", "dimension": 6});
    let m = integrate(six, "64*x1*x2*x3*x4*x5*x6", "gauss-legendre", 64);
    close("cube 6", m.value[0], 1.0, 1e-14);
    let five = json!({"type": "cube", "dimension": 5});
    close(
        "aliases",
        integrate(five, "x*y*z", "genz-malik", 2000).value[0],
        0.125,
        1e-13,
    );
    // Box [-1, 2] x [0, 1] x [1, 3] x [0, 2] x [2, 3]: volume 12; int x1 + x5 = 12 (1/2 + 5/2).
    let b = json!({"type": "box", "min": [-1, 0, 1, 0, 2], "max": [2, 1, 3, 2, 3]});
    close(
        "box",
        integrate(b, "x1 + x5", "genz-malik", 4000).value[0],
        36.0,
        1e-13,
    );
}

/// Intervals with infinite ends through the documented maps, and a
/// segment's breaks.
#[test]
fn infinite_intervals_and_breaks() {
    let line = json!({"type": "interval", "a": "-inf", "b": "inf"});
    let m = converged(line, "exp(-(x^2))", 400);
    close("gaussian over the line", m.value[0], PI.sqrt(), 1e-13);
    let above = json!({"type": "interval", "a": 0, "b": "inf"});
    close(
        "e^-x on [0, inf)",
        converged(above, "exp(-x)", 400).value[0],
        1.0,
        1e-13,
    );
    let below = json!({"type": "interval", "a": "-inf", "b": 1});
    close(
        "e^(x-1) on (-inf, 1]",
        converged(below, "exp(x - 1)", 400).value[0],
        1.0,
        1e-13,
    );
    let tail = json!({"type": "interval", "a": 1, "b": "inf"});
    close(
        "x^-3 on [1, inf)",
        converged(tail.clone(), "x^(-3)", 400).value[0],
        0.5,
        1e-13,
    );
    // Slow decay and a singular finite end: each infinite end and each
    // finite one is at u = 0 of its piece, where f64 resolves u to 1e-308
    // (one map of [1, inf) lost 1.1e-8 of 2 past x = 1e16, while its
    // reference claimed 6e-11; the mirrored map met the 1/sqrt at x = 0).
    let slow = json!({"type": "interval", "a": 1, "b": "inf"});
    close(
        "x^-1.5 on [1, inf)",
        converged(slow, "1/x^1.5", 400).value[0],
        2.0,
        1e-12,
    );
    let singular = json!({"type": "interval", "a": "-inf", "b": 0});
    let m = converged(singular, "exp(x)/sqrt(-x)", 400);
    close("e^x / sqrt(-x) on (-inf, 0]", m.value[0], PI.sqrt(), 1e-10);
    let mirrored = json!({"type": "interval", "a": 0, "b": "inf"});
    let m = converged(mirrored, "exp(-x)/sqrt(x)", 400);
    close("e^-x / sqrt(x) on [0, inf)", m.value[0], PI.sqrt(), 1e-10);
    // A rule with a node at the infinite end (trapezoid) takes it as 0.
    let m = integrate(tail, "x^(-3)", "trapezoid", 4097);
    close("trapezoid x^-3", m.value[0], 0.5, 1e-6);
    // |t - 1| on [0, 3] cut at 1: two Gauss–Legendre nodes a piece are exact.
    let seg = json!({"type": "segment", "a": 0, "b": 3, "breaks": [1]});
    close(
        "kink at a break",
        integrate(seg, "abs(t - 1)", "gauss-legendre", 2).value[0],
        2.5,
        1e-15,
    );
}

/// A list of three expressions is an RGB integrand, each channel its own.
#[test]
fn three_expressions_are_three_channels() {
    let scene = json!({
        "domain": {"type": "interval", "a": 0, "b": 1},
        "integrand": ["exp(x)", "2*x", "3*x^2"],
        "exact": ["e - 1", 1, "1"]
    });
    let b = built(scene).expect("valid");
    assert_eq!(Integral::channels(&b, Quantity::Integral), 3);
    let exact = Integral::closed_form(&b, Quantity::Integral).expect("given");
    assert_eq!(exact, vec![std::f64::consts::E - 1.0, 1.0, 1.0]);
    let rule = AnyRule::by_name("gauss-legendre").expect("rule");
    let mut rng = rand_pcg::Pcg64::seed_from_u64(1);
    let m = Integral::evaluate(&b, &Method::Rule(rule), 16, &mut rng, &[Quantity::Integral])
        .expect("runs")
        .remove(&Quantity::Integral)
        .expect("the integral");
    for (c, want) in exact.iter().enumerate() {
        close(&format!("channel {c}"), m.value[c], *want, 1e-14);
    }
}

/// Every fault in the scene: refused at `check` with its JSON path, and the
/// column for an expression.
#[test]
fn faults_are_refused_at_their_path_and_column() {
    let cube2 = json!({"type": "cube", "dimension": 2});
    let cases: Vec<(Json, &str, &[&str])> = vec![
        (
            json!({"domain": cube2, "integrand": "x + w"}),
            "scene.integrand",
            &["column 5", "unknown name `w`", "x1, x2, x, y"],
        ),
        (
            json!({"domain": cube2, "integrand": "z"}),
            "scene.integrand",
            &["column 1", "`z`"],
        ),
        (
            json!({"domain": cube2, "integrand": "exp(-x^2)"}),
            "scene.integrand",
            &["column 7", "-(a^b)"],
        ),
        (
            json!({"domain": cube2, "integrand": "sin(x"}),
            "scene.integrand",
            &["column 4", "never closed"],
        ),
        (
            json!({"domain": cube2, "integrand": ["x", "y"]}),
            "scene.integrand",
            &["a list of 2", "3 (R, G, B)"],
        ),
        (
            json!({"domain": cube2, "integrand": ["x", 2, "y"]}),
            "scene.integrand[1]",
            &["a number 2"],
        ),
        (
            json!({"domain": cube2, "integrand": ["x", "y", "q"]}),
            "scene.integrand[2]",
            &["unknown name `q`"],
        ),
        (
            json!({"domain": cube2, "integrand": 5}),
            "scene.integrand",
            &["expected an expression"],
        ),
        (
            json!({"domain": cube2, "integrand": "x", "exact": "1/0"}),
            "scene.exact",
            &["inf", "finite"],
        ),
        (
            json!({"domain": cube2, "integrand": "x", "exact": "x"}),
            "scene.exact",
            &["unknown name `x`", "none"],
        ),
        (
            json!({"domain": cube2, "integrand": "x", "exact": [1, 2, 3]}),
            "scene.exact",
            &["3 value(s)", "expected 1"],
        ),
        (
            json!({"domain": cube2, "integrand": "x", "exact": true}),
            "scene.exact",
            &["a boolean"],
        ),
        (
            json!({"domain": {"type": "cube", "dimension": 7}, "integrand": "1"}),
            "scene.domain.dimension",
            &["1 to 6"],
        ),
        (
            json!({"domain": {"type": "box", "min": [0, 0], "max": [1]}, "integrand": "1"}),
            "scene.domain.max",
            &["2 numbers"],
        ),
        (
            json!({"domain": {"type": "box", "min": [0, 1], "max": [1, 1]}, "integrand": "1"}),
            "scene.domain.max[1]",
            &["above min[1]"],
        ),
        (
            json!({"domain": {"type": "interval", "a": 1, "b": 1}, "integrand": "1"}),
            "scene.domain.b",
            &["b > a"],
        ),
        (
            json!({"domain": {"type": "interval", "a": "inf", "b": 1}, "integrand": "1"}),
            "scene.domain.a",
            &["-inf"],
        ),
        (
            json!({"domain": {"type": "interval", "a": "x", "b": 1}, "integrand": "1"}),
            "scene.domain.a",
            &["\"inf\""],
        ),
        (
            json!({"domain": {"type": "disk", "centre": [0, 0, 0], "normal": [0, 0, 1], "radius": -1}, "integrand": "1"}),
            "scene.domain.radius",
            &["-1"],
        ),
        (
            json!({"domain": {"type": "hemisphere", "normal": [0, 0, 0]}, "integrand": "1"}),
            "scene.domain.normal",
            &["non-zero"],
        ),
        (
            json!({"domain": {"type": "box", "min": [0, 0], "max": [1e-200, 1e-200]}, "integrand": "1e300"}),
            "scene.domain",
            &["volume is 0e0", "rescale"],
        ),
        (
            json!({"domain": {"type": "sphere", "centre": [0, 0, 0], "radius": 1e200}, "integrand": "1"}),
            "scene.domain",
            &["area is inf"],
        ),
        (
            json!({"domain": cube2, "integrand": "x*1e309"}),
            "scene.integrand",
            &["column 3", "beyond the f64 range"],
        ),
        (
            json!({"domain": {"type": "torus"}, "integrand": "1"}),
            "scene.domain.type",
            &["interval", "pixel"],
        ),
        (
            json!({"domain": {"type": "pixel", "x0": 0, "y0": 0, "width": 1, "height": 1, "depth": 1}, "integrand": "1"}),
            "scene.domain.depth",
            &["unknown field `depth`"],
        ),
    ];
    for (scene, path, says) in cases {
        let e = built(scene.clone())
            .err()
            .unwrap_or_else(|| panic!("{scene} was accepted"));
        assert!(
            e.contains(&format!("`{path}`")),
            "{scene}: {e} (expected at {path})"
        );
        for s in says {
            assert!(e.contains(s), "{scene}: {e} (expected {s:?})");
        }
    }
}

/// A point where the integrand is not finite fails that job, the point
/// named in the domain's variables; other jobs run.
#[test]
fn a_non_finite_point_fails_its_job_with_the_point_named() {
    let dir = scratch("integral-nan");
    let file = dir.join("nan.json");
    let spec = json!({
        "name": "nan", "family": "integral",
        "scene": {"domain": {"type": "box", "min": [0, 1], "max": [1, 2]}, "integrand": "log(x)*y", "exact": "-3/2"},
        "quantities": ["integral"],
        "rules": [{"rule": "trapezoid"}, {"rule": "gauss-legendre"}],
        "budgets": [64], "repeats": 1, "reference": {"type": "closed-form"}
    });
    std::fs::write(&file, spec.to_string()).expect("write");
    let out = bin()
        .args(["run", file.to_str().expect("utf-8"), "--out"])
        .arg(dir.join("rep"))
        .output()
        .expect("runs");
    let results = std::fs::read_to_string(dir.join("rep/nan/results.jsonl")).expect("results");
    let failed: Vec<&str> = results
        .lines()
        .filter(|l| l.contains("\"failure\":\""))
        .collect();
    println!("{}\n{results}", stderr(&out));
    assert!(
        results.contains("-inf at x1 = 0, x2 = 1"),
        "the trapezoid's job names the point: {results}"
    );
    assert_eq!(failed.len(), 1, "the trapezoid's job alone fails");
    // The failed row counts nothing and times nothing: no 0 evaluations,
    // no NaN seconds, in the report, its page or its summary.
    let report = std::fs::read_to_string(dir.join("rep/nan/report.md")).expect("report");
    let row = report
        .lines()
        .find(|l| l.starts_with("| trapezoid | 64 |"))
        .expect("the trapezoid's row");
    assert!(
        row.starts_with("| trapezoid | 64 | — | — | — | — | — | — | failed: "),
        "{row}"
    );
    let page = std::fs::read_to_string(dir.join("rep/nan/index.html")).expect("page");
    assert!(!page.contains("NaN"), "NaN on the page");
    let summary: Json = serde_json::from_str(
        &std::fs::read_to_string(dir.join("rep/nan/summary.json")).expect("summary"),
    )
    .expect("json");
    let trapezoid = summary.to_string();
    assert!(
        trapezoid.contains("\"evaluations\":null") && trapezoid.contains("\"evaluations\":149.0"),
        "the failed row's evaluations null, Gauss–Legendre's 8^2 + 7^2 + 6^2: {trapezoid}"
    );
    // Gauss–Legendre's nodes are inside: its job ran, near -3/2 (8 x 8 nodes on a log).
    let gl = results
        .lines()
        .find(|l| l.contains("gauss-legendre"))
        .expect("a gauss-legendre row");
    let row: Json = serde_json::from_str(gl).expect("json");
    let value = row["quantities"]["integral"]["value"][0]
        .as_f64()
        .expect("a value");
    close("gauss-legendre log(x) y", value, -1.5, 2e-2);
}

#[test]
fn a_value_whose_product_with_the_jacobian_passes_the_range_is_named_as_such() {
    // 1.7e308 on [-1, 1]: the unit cube's Jacobian 2 takes it past
    // f64::MAX (1.797e308), and the integral, 3.4e308, is past it too.
    // The segment's own map applies its length (the domain's Jacobian)
    // to what the integrand returns; the interval's is the family's.
    let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
    for (domain, integrand, said) in [
        ("interval", json!("1.7e308"), "1.7e308 at x = "),
        ("segment", json!("1.7e308"), "1.7e308 at unit-cube point ["),
        (
            "segment",
            json!(["1", "1e308", "2"]),
            "1, 1e308, 2 at unit-cube point [",
        ),
    ] {
        let scene =
            built(json!({"domain": {"type": domain, "a": -1, "b": 1}, "integrand": integrand}))
                .unwrap_or_else(|e| panic!("{integrand}: {e}"));
        for rule in ["gauss-legendre", "trapezoid"] {
            let err = Integral::evaluate(
                &scene,
                &Method::Rule(AnyRule::by_name(rule).expect("rule")),
                16,
                &mut rng,
                &[Quantity::Integral],
            )
            .expect_err("past the range");
            let text = err.to_string();
            assert!(
                text.contains(said)
                    && text.contains("times the domain's Jacobian 2, is beyond the f64 range"),
                "{domain} {rule}: {text}"
            );
            assert!(!text.contains("returned"), "{domain} {rule}: {text}");
        }
    }
    // 8.9e307 times 2 is within the range: the integral, 1.78e308.
    let m = integrate(
        json!({"type": "interval", "a": -1, "b": 1}),
        "8.9e307",
        "gauss-legendre",
        16,
    );
    close("8.9e307 on [-1, 1]", m.value[0], 1.78e308, 1e-15);
}

/// Pieces each within the range whose sum is not: `1e308` on a segment cut
/// at 1 is `1e308` on each piece, `2e308` in all; `8e307 / (1 + x^2)` on
/// the whole line is `8e307 pi = 2.5e308`, its pieces `(-inf, -1]`,
/// `[-1, 1]` and `[1, inf)` `8e307 pi / 4`, `/ 2` and `/ 4`. The sum was a
/// bare "non-finite integral (inf)"; it now says the total is beyond the
/// range. Pieces `1e308, 1e308, -1e308` (in either order) sum to `1e308`,
/// within it: the plain running sum passed the range on the way.
#[test]
fn pieces_whose_sum_passes_the_range_are_named_and_summed_in_any_order() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
    let evaluate = |domain: &Json, integrand: &str, rule: &str, rng: &mut rand_pcg::Pcg64| {
        let scene = built(json!({"domain": domain, "integrand": integrand}))
            .unwrap_or_else(|e| panic!("{integrand}: {e}"));
        Integral::evaluate(
            &scene,
            &Method::Rule(AnyRule::by_name(rule).expect("rule")),
            64,
            rng,
            &[Quantity::Integral],
        )
    };
    for (domain, integrand, pieces) in [
        (
            json!({"type": "segment", "a": 0, "b": 2, "breaks": [1]}),
            "1e308",
            2,
        ),
        (
            json!({"type": "interval", "a": "-inf", "b": "inf"}),
            "8e307/(1 + x*x)",
            3,
        ),
    ] {
        for rule in ["gauss-legendre", "trapezoid"] {
            let err = evaluate(&domain, integrand, rule, &mut rng).expect_err("past the range");
            let text = err.to_string();
            assert!(
                text.contains(&format!(
                    "[inf], the sum of its integrals over {pieces} pieces, is beyond the f64 range"
                )),
                "{domain} {rule}: {text}"
            );
        }
    }
    for integrand in ["1e308*(1 - 2*step(t - 2))", "1e308*(1 - 2*step(1 - t))"] {
        let domain = json!({"type": "segment", "a": 0, "b": 3, "breaks": [1, 2]});
        let m = evaluate(&domain, integrand, "gauss-legendre", &mut rng)
            .unwrap_or_else(|e| panic!("{integrand}: {e}"));
        close(integrand, m[&Quantity::Integral].value[0], 1e308, 1e-15);
    }
}
