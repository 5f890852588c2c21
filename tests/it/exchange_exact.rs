//! The form factors between two surfaces (`lightquad::exact::exchange`,
//! Howell C-11, C-14 in `exact::rendering`) against 30-digit mpmath values
//! (tests/data/exchange_form_factors.json, scripts/gen_exchange_reference.py:
//! Howell's printed formulas, and a pair with no catalogue formula by the
//! 2-D integral of Lambert's point formula), and the contour form against
//! each closed form, with reciprocity between the two directions.

use lightquad::domain::Vec3;
use lightquad::exact::exchange::{coaxial_disks, polygon_pair};
use lightquad::exact::rendering::{parallel_rectangles, perpendicular_rectangles};

use crate::common::{data, num, rel};

fn p(x: f64, y: f64, z: f64) -> Vec3 {
    Vec3::new(x, y, z)
}

fn f(v: &serde_json::Value, key: &str) -> f64 {
    v[key].as_f64().unwrap_or_else(|| panic!("{key} in {v}"))
}

/// An `a x b` rectangle in z = 0 facing up, and the same at height `c`
/// facing down (corners counter-clockwise about each normal).
fn opposed(a: f64, b: f64, c: f64) -> ([Vec3; 4], [Vec3; 4]) {
    (
        [p(0., 0., 0.), p(a, 0., 0.), p(a, b, 0.), p(0., b, 0.)],
        [p(0., 0., c), p(0., b, c), p(a, b, c), p(a, 0., c)],
    )
}

/// An `l x w` floor (normal +z) and an `l x h` wall (normal +x) sharing
/// the edge of length `l` along y.
fn perpendicular(l: f64, w: f64, h: f64) -> ([Vec3; 4], [Vec3; 4]) {
    (
        [p(0., 0., 0.), p(w, 0., 0.), p(w, l, 0.), p(0., l, 0.)],
        [p(0., 0., 0.), p(0., l, 0.), p(0., l, h), p(0., 0., h)],
    )
}

#[test]
fn parallel_rectangles_closed_and_contour_forms_match_mpmath() {
    let table = data("exchange_form_factors.json");
    for case in table["parallel_rectangles"].as_array().expect("cases") {
        let (a, b, c) = (f(case, "a"), f(case, "b"), f(case, "c"));
        let want = num(&case["F"]);
        let howell = parallel_rectangles(a, b, c).expect("closed form");
        assert!(
            rel(howell, want) < 1e-13,
            "C-11 {a} {b} {c}: {howell} vs {want}"
        );
        let (lower, upper) = opposed(a, b, c);
        let contour = polygon_pair(&lower, &upper).expect("contour");
        assert!(
            rel(contour.value, want) < 1e-12,
            "contour {a} {b} {c}: {contour:?} vs {want}"
        );
        assert!(contour.error < 1e-12, "{contour:?}");
        // Identical plates: F_12 = F_21.
        let back = polygon_pair(&upper, &lower).expect("contour");
        assert!(rel(back.value, want) < 1e-12, "{back:?}");
    }
}

#[test]
fn perpendicular_rectangles_sharing_an_edge_match_mpmath_with_reciprocity() {
    let table = data("exchange_form_factors.json");
    for case in table["perpendicular_rectangles"].as_array().expect("cases") {
        let (l, w, h) = (f(case, "l"), f(case, "w"), f(case, "h"));
        let want = num(&case["F"]);
        let howell = perpendicular_rectangles(l, w, h).expect("closed form");
        assert!(
            rel(howell, want) < 1e-13,
            "C-14 {l} {w} {h}: {howell} vs {want}"
        );
        let (floor, wall) = perpendicular(l, w, h);
        let contour = polygon_pair(&floor, &wall).expect("contour");
        assert!(
            rel(contour.value, want) < 1e-12,
            "contour {l} {w} {h}: {contour:?} vs {want}"
        );
        // A_1 F_12 = A_2 F_21, the reverse direction computed on its own.
        let back = polygon_pair(&wall, &floor).expect("contour");
        assert!(rel(back.value * l * h, want * l * w) < 1e-12, "{back:?}");
    }
}

#[test]
fn coaxial_disks_match_mpmath_with_reciprocity() {
    let table = data("exchange_form_factors.json");
    for case in table["coaxial_disks"].as_array().expect("cases") {
        let (r1, r2, h) = (f(case, "r1"), f(case, "r2"), f(case, "h"));
        let want = num(&case["F"]);
        let got = coaxial_disks(r1, r2, h).expect("closed form");
        assert!(
            rel(got, want) < 1e-14,
            "C-41 {r1} {r2} {h}: {got} vs {want}"
        );
        let back = coaxial_disks(r2, r1, h).expect("closed form");
        assert!(rel(back * r2 * r2, got * r1 * r1) < 1e-14);
    }
    // Far apart: F -> r2^2 / h^2 without cancellation (the printed form
    // loses every digit at h = 1e8).
    let far = coaxial_disks(1.0, 1.0, 1e8).expect("closed form");
    assert!(rel(far, 1e-16) < 1e-15, "{far}");
}

#[test]
fn a_general_polygon_pair_matches_the_integral_of_lamberts_formula() {
    let table = data("exchange_form_factors.json");
    let case = &table["general_pair"];
    let v = |x: &serde_json::Value| {
        let c: Vec<f64> = x
            .as_array()
            .expect("point")
            .iter()
            .map(|c| c.as_f64().expect("number"))
            .collect();
        p(c[0], c[1], c[2])
    };
    let r = &case["receiver"];
    let (o, eu, ev) = (v(&r["origin"]), v(&r["edge_u"]), v(&r["edge_v"]));
    let receiver = [o, o + eu, o + eu + ev, o + ev];
    let tri: Vec<Vec3> = case["triangle"]
        .as_array()
        .expect("corners")
        .iter()
        .map(v)
        .collect();
    // Ordered to face the receiver below it.
    let triangle = [tri[0], tri[2], tri[1]];
    let want = num(&case["F"]);
    let got = polygon_pair(&receiver, &triangle).expect("contour");
    assert!(rel(got.value, want) < 1e-12, "{got:?} vs {want}");
    // Reciprocity against the triangle's own direction.
    let back = polygon_pair(&triangle, &receiver).expect("contour");
    let (a1, a2) = (
        eu.cross(&ev).norm(),
        0.5 * (tri[1] - tri[0]).cross(&(tri[2] - tri[0])).norm(),
    );
    assert!(rel(back.value * a2, got.value * a1) < 1e-12);
}

#[test]
fn the_contour_form_refuses_what_it_cannot_integrate() {
    let (lower, upper) = opposed(1.0, 1.0, 1.0);
    // Facing away: the upper plate's corners reversed.
    let mut away = upper;
    away.reverse();
    let named = |r: Result<_, lightquad::QuadError>, name: &str| match r {
        Err(lightquad::QuadError::InvalidParameter { name: n, .. }) => assert_eq!(n, name),
        other => panic!("{other:?}"),
    };
    named(polygon_pair(&away, &lower), "to");
    named(polygon_pair(&lower, &away), "from");
    named(polygon_pair(&lower[..2], &upper), "from");
    let mut nan = upper;
    nan[1].x = f64::NAN;
    named(polygon_pair(&lower, &nan), "to");
    let mut bent = upper;
    bent[2].z += 0.1;
    named(polygon_pair(&lower, &bent), "to");
    // Coplanar, side by side: neither is in front of the other's plane
    // strictly, but both lie in it; F = 0 (no corner behind).
    let beside = [p(2., 0., 0.), p(3., 0., 0.), p(3., 1., 0.), p(2., 1., 0.)];
    let f = polygon_pair(&lower, &beside).expect("contour");
    assert!(f.value.abs() < 1e-14, "{f:?}");
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(coaxial_disks(bad, 1.0, 1.0).is_err());
        assert!(coaxial_disks(1.0, 1.0, bad).is_err());
    }
}
