//! V-E beyond a constant emission: a transfer function
//! `c(v)` as a piecewise-linear table, and an emission field `Le(p)` of its
//! own. Every value is checked against a closed form derived here or an
//! independent adaptive Simpson on the exact integrand, never against the
//! code's own output.

use std::f64::consts::PI;
use std::sync::Arc;

use lightquad::domain::{Segment, Vec3};
use lightquad::error::QuadError;
use lightquad::family::Family;
use lightquad::geometry::Ray;
use lightquad::quadrature::{GaussLegendre, Rule, Trapezoid};
use lightquad::volume::experiment::{SceneSpec, Volume, VolumeQuantity};
use lightquad::volume::{
    ConstantSphere, DepthScheme, EmissionMap, GaussianBlob, GaussianBlobs, LinearGradient, Medium,
    ShadowMethod, TransferTable, VolumeScene, evaluate,
};
use rand::SeedableRng;
use rand_pcg::Pcg64;

/// Relative difference `|a - b| / |b|`.
fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

/// Gauss–Legendre with exactly `n` nodes per smooth piece.
fn gl() -> GaussLegendre {
    GaussLegendre {
        error_estimate: false,
    }
}

fn ray(origin: [f64; 3], dir: [f64; 3]) -> Ray {
    Ray::new(Vec3::from(origin), Vec3::from(dir)).expect("valid ray")
}

/// I_E of `scene` by `rule` at `n` per smooth piece, cumulative depth.
fn i_e<R: Rule>(scene: &VolumeScene, rule: &R, n: usize) -> f64 {
    evaluate(
        scene,
        rule,
        n,
        DepthScheme::Cumulative,
        ShadowMethod::ClosedFormWhereAvailable,
        &mut Pcg64::seed_from_u64(0),
    )
    .expect("evaluates")
    .emission
    .expect("emits")
    .value
}

/// Adaptive Simpson on `[a, b]` to absolute tolerance `tol`, with Richardson's
/// correction (an independent reference: it sees only `f`).
fn simpson(f: &dyn Fn(f64) -> f64, a: f64, b: f64, tol: f64) -> f64 {
    /// `[a, b]` with `f` at `a`, the middle and `b`, and the Simpson value
    /// `whole` on it.
    fn rec(
        f: &dyn Fn(f64) -> f64,
        [a, b]: [f64; 2],
        [fa, fm, fb]: [f64; 3],
        whole: f64,
        tol: f64,
        depth: u32,
    ) -> f64 {
        let m = 0.5 * (a + b);
        let (lm, rm) = (0.5 * (a + m), 0.5 * (m + b));
        let (flm, frm) = (f(lm), f(rm));
        let left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
        let right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
        let diff = left + right - whole;
        if depth == 0 || diff.abs() <= 15.0 * tol {
            return left + right + diff / 15.0;
        }
        rec(f, [a, m], [fa, flm, fm], left, 0.5 * tol, depth - 1)
            + rec(f, [m, b], [fm, frm, fb], right, 0.5 * tol, depth - 1)
    }
    let (fa, fm, fb) = (f(a), f(0.5 * (a + b)), f(b));
    let whole = (b - a) / 6.0 * (fa + 4.0 * fm + fb);
    rec(f, [a, b], [fa, fm, fb], whole, tol, 50)
}

/// Adaptive Simpson over consecutive pieces `cuts[i]..cuts[i+1]` (the kinks).
fn simpson_pieces(f: &dyn Fn(f64) -> f64, cuts: &[f64], tol: f64) -> f64 {
    cuts.windows(2).map(|w| simpson(f, w[0], w[1], tol)).sum()
}

/// The table of the gradient tests: knots 0.3, 0.8, 1.2, 1.6, clamped.
const POINTS: [(f64, f64); 4] = [(0.3, 0.5), (0.8, 2.0), (1.2, 1.0), (1.6, 3.0)];

/// `c(v)` of [`POINTS`] by hand, for `v > 0`.
fn c_by_hand(v: f64) -> f64 {
    if v <= 0.3 {
        0.5
    } else if v <= 0.8 {
        0.5 + 1.5 * (v - 0.3) / 0.5
    } else if v <= 1.2 {
        2.0 - (v - 0.8) / 0.4
    } else if v <= 1.6 {
        1.0 + 2.0 * (v - 1.2) / 0.4
    } else {
        3.0
    }
}

/// A medium that delegates to `inner` but claims its density crosses no
/// level (`Some(vec![])`, `hide`) or has no closed-form crossings (`None`, so
/// V-E brackets them): to measure what the knot cuts are worth and to test
/// the bracketing against the closed form.
#[derive(Debug)]
struct Crossings<M: Medium> {
    inner: M,
    hide: bool,
}

impl<M: Medium> Medium for Crossings<M> {
    fn name(&self) -> &'static str {
        self.inner.name()
    }
    fn density(&self, p: Vec3) -> f64 {
        self.inner.density(p)
    }
    fn density_on(&self, p: Vec3, inside: Vec3) -> f64 {
        self.inner.density_on(p, inside)
    }
    fn support(&self, ray: &Ray, t_min: f64, t_max: f64) -> Vec<Segment> {
        self.inner.support(ray, t_min, t_max)
    }
    fn max_density(&self, ray: &Ray, t0: f64, t1: f64) -> f64 {
        self.inner.max_density(ray, t0, t1)
    }
    fn level_crossings(&self, _: &Ray, _: f64, _: f64, _: Vec3, _: f64) -> Option<Vec<f64>> {
        self.hide.then(Vec::new)
    }
}

/// The gradient scene: `v = 1 + 0.8 x` in the unit sphere, the ray along x
/// at height 0.2, lambda 1.5, the table [`POINTS`]; with its reference.
///
/// With `s = sqrt(1 - 0.2^2)` the chord is `x in [-s, s]` (t = x + 3), the
/// optical depth from its start is
/// `1.5 int_{-s}^x (1 + 0.8 u) du = 1.5 ((x + s) + 0.4 (x^2 - s^2))`, and
/// `I_E = int_{-s}^{s} e^{-depth(x)} c(1 + 0.8 x) dx`, kinked where
/// `1 + 0.8 x = v_k`: at `x = -0.875, -0.25, 0.25, 0.75`.
fn gradient_scene(hide: Option<bool>) -> (VolumeScene, f64) {
    let inner = LinearGradient::new(Vec3::zeros(), 1.0, 1.0, Vec3::new(0.8, 0.0, 0.0))
        .expect("valid gradient");
    let medium: Arc<dyn Medium> = match hide {
        None => Arc::new(inner),
        Some(hide) => Arc::new(Crossings { inner, hide }),
    };
    let mut scene = VolumeScene::new(ray([-3.0, 0.2, 0.0], [1.0, 0.0, 0.0]));
    scene.medium = Some(medium);
    scene.lambda = 1.5;
    scene.emission = Some(EmissionMap::Table(
        TransferTable::new(POINTS.to_vec()).expect("valid table"),
    ));
    let s = (1.0f64 - 0.04).sqrt();
    let f = |x: f64| (-1.5 * ((x + s) + 0.4 * (x * x - s * s))).exp() * c_by_hand(1.0 + 0.8 * x);
    let reference = simpson_pieces(&f, &[-s, -0.875, -0.25, 0.25, 0.75, s], 1e-17);
    (scene, reference)
}

#[test]
fn transfer_table_on_a_linear_gradient_matches_an_independent_adaptive_simpson() {
    let (scene, reference) = gradient_scene(None);
    for n in [8, 16] {
        let got = i_e(&scene, &gl(), n);
        assert!(
            rel(got, reference) < 1e-13,
            "GL n = {n}: {got} vs {reference} (rel {:e})",
            rel(got, reference)
        );
    }
}

/// Knot crossings bracketed numerically (the medium claims no closed form)
/// land where the linear gradient's closed form puts them: the same I_E to
/// 1e-13 against the reference.
#[test]
fn bracketed_knot_crossings_give_the_closed_form_cuts() {
    let (scene, reference) = gradient_scene(Some(false));
    let got = i_e(&scene, &gl(), 12);
    assert!(rel(got, reference) < 1e-13, "{got} vs {reference}");
}

/// Without the cuts at the knots a kink lies inside a piece and
/// Gauss–Legendre converges only algebraically; with them it reaches 1e-13 at
/// 8 nodes per piece, and the trapezoid rule's error falls by 4 per doubling
/// (order 2) with cuts.
#[test]
fn knot_cuts_restore_the_rules_orders_on_a_transfer_table() {
    let (cut, reference) = gradient_scene(None);
    let (uncut, _) = gradient_scene(Some(true));
    let with = rel(i_e(&cut, &gl(), 16), reference);
    let without = rel(i_e(&uncut, &gl(), 16), reference);
    assert!(with < 1e-13, "with cuts: {with:e}");
    assert!(without > 1e-6, "without cuts: {without:e}");
    let errs: Vec<f64> = [65, 129, 257, 513]
        .iter()
        .map(|&n| (i_e(&cut, &Trapezoid, n) - reference).abs())
        .collect();
    for w in errs.windows(2) {
        let ratio = w[0] / w[1];
        assert!(
            (3.8..4.2).contains(&ratio),
            "trapezoid ratio {ratio}: {errs:?}"
        );
    }
}

/// A Gaussian blob read through a table, its crossings bracketed: along the
/// line through the blob at height `h` the density is
/// `A e^{-(t - t_c)^2 / (2 w^2)}`, `A = a e^{-h^2/(2w^2)}`, crossing `v_k` at
/// `t_c +- w sqrt(2 ln(A / v_k))`; the optical depth from the start `t_0` of
/// the 12-width support is `lambda A w sqrt(pi/2) [erf((t - t_c)/(w sqrt 2))
/// - erf((t_0 - t_c)/(w sqrt 2))]` (libm's erf).
#[test]
fn transfer_table_on_a_gaussian_blob_brackets_its_knots() {
    let (a, w, h, lambda) = (2.0f64, 0.4f64, 0.1f64, 0.8f64);
    let blob = GaussianBlob {
        centre: Vec3::zeros(),
        amplitude: a,
        width: w,
    };
    let mut scene = VolumeScene::new(ray([-6.0, h, 0.0], [1.0, 0.0, 0.0]));
    scene.medium = Some(Arc::new(GaussianBlobs::new(vec![blob]).expect("valid")));
    scene.lambda = lambda;
    scene.emission = Some(EmissionMap::Table(
        TransferTable::new(POINTS.to_vec()).expect("valid table"),
    ));
    let peak = a * (-h * h / (2.0 * w * w)).exp();
    let tc = 6.0;
    let half = (12.0 * w * 12.0 * w - h * h).sqrt();
    let t0 = tc - half;
    let v = |t: f64| peak * (-(t - tc) * (t - tc) / (2.0 * w * w)).exp();
    let s2 = w * 2f64.sqrt();
    let depth = |t: f64| {
        lambda
            * peak
            * w
            * (PI / 2.0).sqrt()
            * (libm::erf((t - tc) / s2) - libm::erf((t0 - tc) / s2))
    };
    let f = |t: f64| (-depth(t)).exp() * c_by_hand(v(t));
    let mut cuts = vec![t0, tc + half];
    for (vk, _) in POINTS {
        let d = w * (2.0 * (peak / vk).ln()).sqrt();
        cuts.extend([tc - d, tc + d]);
    }
    cuts.sort_by(f64::total_cmp);
    let reference = simpson_pieces(&f, &cuts, 1e-17);
    let got = i_e(&scene, &gl(), 24);
    assert!(rel(got, reference) < 1e-12, "{got} vs {reference}");
}

/// On a constant sphere a table is the constant `c(kappa)`: `kappa = 1.0`
/// lies on the segment (0.8, 2.0)..(1.2, 1.0), so `c = 1.5` and
/// `I_E = c (1 - e^{-sigma L}) / sigma` with `sigma = lambda kappa`.
#[test]
fn transfer_table_on_a_constant_sphere_is_constant_emission_at_c_of_kappa() {
    let mut scene = VolumeScene::new(ray([-3.0, 0.3, 0.0], [1.0, 0.0, 0.0]));
    scene.medium = Some(Arc::new(
        ConstantSphere::new(Vec3::zeros(), 1.0, 1.0).expect("valid"),
    ));
    scene.lambda = 2.0;
    scene.emission = Some(EmissionMap::Table(
        TransferTable::new(POINTS.to_vec()).expect("valid table"),
    ));
    let chord = 2.0 * (1.0f64 - 0.09).sqrt();
    let expected = 1.5 * (1.0 - (-2.0 * chord).exp()) / 2.0;
    let got = i_e(&scene, &gl(), 8);
    assert!(rel(got, expected) < 1e-13, "{got} vs {expected}");
    let cf = closed_form(&scene_json(
        r#"{ "type": "constant-sphere", "centre": [0, 0, 0], "radius": 1.0, "kappa": 1.0 }"#,
        2.0,
        r#"{ "type": "table", "points": [[0.3, 0.5], [0.8, 2.0], [1.2, 1.0], [1.6, 3.0]] }"#,
    ));
    assert!(rel(cf.expect("a closed form"), expected) < 1e-14);
}

/// A density of zero emits nothing through a table, whatever `c(0+)`: a
/// kappa = 0 sphere gives I_E = 0.
#[test]
fn transfer_table_emits_nothing_where_the_density_is_zero() {
    let mut scene = VolumeScene::new(ray([-3.0, 0.3, 0.0], [1.0, 0.0, 0.0]));
    scene.medium = Some(Arc::new(
        ConstantSphere::new(Vec3::zeros(), 1.0, 0.0).expect("valid"),
    ));
    scene.emission = Some(EmissionMap::Table(
        TransferTable::new(vec![(0.0, 4.0), (1.0, 5.0)]).expect("valid"),
    ));
    assert_eq!(i_e(&scene, &gl(), 8), 0.0);
}

/// Density: a unit sphere of kappa 2 (sigma = 2); emission field: a
/// concentric sphere of radius 1.5 and value 0.7. Along y = 0.3 the density
/// chord is `[-h1, h1]`, `h1 = sqrt(1 - 0.09)`, the field's `[-h2, h2]`,
/// `h2 = sqrt(2.25 - 0.09)`, so
/// `I_E = 0.7 [(h2 - h1) + (1 - e^{-2 sigma h1}) / sigma + e^{-2 sigma h1} (h2 - h1)]`:
/// unattenuated before the medium, absorbed inside, attenuated by the whole
/// chord after it.
#[test]
fn emission_field_sphere_around_an_absorbing_sphere_matches_its_piecewise_closed_form() {
    let (sigma, c) = (2.0f64, 0.7f64);
    let (h1, h2) = ((1.0f64 - 0.09).sqrt(), (2.25f64 - 0.09).sqrt());
    let tau = (-2.0 * sigma * h1).exp();
    let expected = c * ((h2 - h1) + (1.0 - tau) / sigma + tau * (h2 - h1));
    let mut scene = VolumeScene::new(ray([-3.0, 0.3, 0.0], [1.0, 0.0, 0.0]));
    scene.medium = Some(Arc::new(
        ConstantSphere::new(Vec3::zeros(), 1.0, 2.0).expect("valid"),
    ));
    scene.emission = Some(EmissionMap::Field(Arc::new(
        ConstantSphere::new(Vec3::zeros(), 1.5, c).expect("valid"),
    )));
    let got = i_e(&scene, &gl(), 8);
    assert!(rel(got, expected) < 1e-13, "{got} vs {expected}");
    // The trapezoid is exact on the constant pieces and O(h^2) inside the medium.
    let trap = i_e(&scene, &Trapezoid, 1025);
    assert!(rel(trap, expected) < 1e-5, "{trap} vs {expected}");
    let cf = closed_form(&scene_json(
        r#"{ "type": "constant-sphere", "centre": [0, 0, 0], "radius": 1.0, "kappa": 2.0 }"#,
        1.0,
        r#"{ "type": "field", "field": { "type": "constant-sphere", "centre": [0, 0, 0], "radius": 1.5, "kappa": 0.7 } }"#,
    ));
    assert!(rel(cf.expect("a closed form"), expected) < 1e-14);
}

/// An emission field of one Gaussian blob with nothing absorbing (no medium;
/// or a medium with lambda = 0), the ray at height h = 0.3 from its centre:
/// `I_E = a w sqrt(2 pi) e^{-h^2/(2 w^2)}`, the
/// blob's integral along the whole line (the 12-width cut-off drops e^-72).
#[test]
fn emission_field_of_a_gaussian_blob_without_absorption_is_its_line_integral() {
    let (a, w, h) = (1.3f64, 0.25f64, 0.3f64);
    let expected = a * w * (2.0 * PI).sqrt() * (-h * h / (2.0 * w * w)).exp();
    let field: Arc<dyn Medium> = Arc::new(
        GaussianBlobs::new(vec![GaussianBlob {
            centre: Vec3::new(0.5, 0.0, 0.0),
            amplitude: a,
            width: w,
        }])
        .expect("valid"),
    );
    let mut vacuum = VolumeScene::new(ray([-3.0, h, 0.0], [1.0, 0.0, 0.0]));
    vacuum.emission = Some(EmissionMap::Field(field.clone()));
    let mut clear = vacuum.clone();
    clear.medium = Some(Arc::new(
        ConstantSphere::new(Vec3::zeros(), 1.0, 3.0).expect("valid"),
    ));
    clear.lambda = 0.0;
    for scene in [&vacuum, &clear] {
        let got = i_e(scene, &gl(), 96);
        assert!(rel(got, expected) < 1e-13, "{got} vs {expected}");
    }
    let blob = r#"{ "type": "field", "field": { "type": "gaussian-blobs", "blobs": [ { "centre": [0.5, 0, 0], "amplitude": 1.3, "width": 0.25 } ] } }"#;
    let cf = closed_form(&scene_json(
        r#"{ "type": "constant-sphere", "centre": [0, 0, 0], "radius": 1.0, "kappa": 3.0 }"#,
        0.0,
        blob,
    ));
    assert!(rel(cf.expect("a closed form"), expected) < 1e-14);
    // Absorbed by a sphere whose chord overlaps the blob: no closed form is
    // claimed (None, not a wrong value).
    let absorbed = scene_json(
        r#"{ "type": "constant-sphere", "centre": [0, 0, 0], "radius": 1.0, "kappa": 3.0 }"#,
        1.0,
        blob,
    );
    assert!(closed_form(&absorbed).is_none());
}

/// A scene spec with the ray along x at height 0.3 (`medium`, `emission` as
/// JSON text).
fn scene_json(medium: &str, lambda: f64, emission: &str) -> String {
    format!(
        r#"{{ "ray": {{ "origin": [-3.0, 0.3, 0.0], "direction": [1.0, 0.0, 0.0] }},
             "medium": {medium}, "lambda": {lambda}, "emission": {emission} }}"#
    )
}

/// The experiment layer's closed form of I_E for a scene spec.
fn closed_form(json: &str) -> Option<f64> {
    let spec: SceneSpec = serde_json::from_str(json).expect("a scene spec");
    let built = Volume::build(&spec).expect("builds");
    Volume::closed_form(&built, VolumeQuantity::Emission).map(|v| v[0])
}

/// The build error of a scene spec.
fn build_error(json: &str) -> String {
    let spec: SceneSpec = serde_json::from_str(json).expect("a scene spec");
    match Volume::build(&spec) {
        Ok(_) => panic!("accepted: {json}"),
        Err(e) => e.to_string(),
    }
}

const SPHERE: &str =
    r#"{ "type": "constant-sphere", "centre": [0, 0, 0], "radius": 1.0, "kappa": 1.0 }"#;

#[test]
fn bad_transfer_tables_name_the_json_path_and_what_is_accepted() {
    let cases = [
        (
            r#"{ "type": "table", "points": [[0.0, 1.0], [0.5, 1.0], [0.5, 2.0]] }"#,
            "scene.emission.points[2][0]",
            "strictly increasing",
        ),
        (
            r#"{ "type": "table", "points": [[0.0, 1.0], [0.5, 1.0], [0.4, 2.0]] }"#,
            "scene.emission.points[2][0]",
            "a density > points[1][0] = 0.5",
        ),
        (
            r#"{ "type": "table", "points": [[0.5, 1.0]] }"#,
            "scene.emission.points",
            "at least 2 points",
        ),
        (
            r#"{ "type": "table", "points": [] }"#,
            "scene.emission.points",
            "at least 2 points",
        ),
        (
            r#"{ "type": "table", "points": [[0.0, 1.0], [1.0, -0.5]] }"#,
            "scene.emission.points[1][1]",
            "c >= 0",
        ),
        (
            r#"{ "type": "table", "points": [[-1.0, 1.0], [1.0, 0.5]] }"#,
            "scene.emission.points[0][0]",
            "v >= 0",
        ),
        (
            r#"{ "type": "field", "field": { "type": "constant-sphere", "centre": [0, 0, 0], "radius": 1.0, "kappa": -1.0 } }"#,
            "scene.emission.field.kappa",
            "a finite density >= 0",
        ),
    ];
    for (emission, path, what) in cases {
        let msg = build_error(&scene_json(SPHERE, 1.0, emission));
        assert!(
            msg.contains(&format!("at `{path}`")),
            "no `{path}` in: {msg}"
        );
        assert!(msg.contains(what), "no `{what}` in: {msg}");
    }
    // A table point is a pair: three numbers do not parse.
    let three = scene_json(
        SPHERE,
        1.0,
        r#"{ "type": "table", "points": [[0.0, 1.0, 2.0], [1.0, 1.0]] }"#,
    );
    assert!(serde_json::from_str::<SceneSpec>(&three).is_err());
}

/// NaN and infinities cannot be written in JSON; the library refuses them,
/// naming the entry.
#[test]
fn transfer_table_refuses_non_finite_entries_naming_them() {
    let name = |e: QuadError| match e {
        QuadError::InvalidParameter { name, .. } => name,
        other => panic!("unexpected {other}"),
    };
    let nan_v = TransferTable::new(vec![(0.0, 1.0), (f64::NAN, 1.0)]).expect_err("NaN v");
    assert_eq!(name(nan_v), "points[1][0]");
    let nan_c = TransferTable::new(vec![(0.0, 1.0), (1.0, f64::NAN)]).expect_err("NaN c");
    assert_eq!(name(nan_c), "points[1][1]");
    let inf_c = TransferTable::new(vec![(0.0, f64::INFINITY), (1.0, 1.0)]).expect_err("inf c");
    assert_eq!(name(inf_c), "points[0][1]");
}

/// The table's values by hand: clamped below the first and above the last
/// knot, linear between, 0 at v = 0.
#[test]
fn transfer_table_interpolates_linearly_and_clamps_at_the_ends() {
    let t = TransferTable::new(POINTS.to_vec()).expect("valid");
    for v in [1e-9, 0.1, 0.3, 0.55, 0.8, 1.0, 1.2, 1.4, 1.6, 7.0] {
        assert!((t.at(v) - c_by_hand(v)).abs() < 1e-15, "c({v})");
    }
    assert_eq!(t.at(0.0), 0.0);
}

/// A 1-D voxel grid (4 voxels over x in [-1, 1], values 0.2, 1.0, 1.4, 0.5
/// at the centres -0.75, -0.25, 0.25, 0.75, held constant in the half-voxel
/// margins) read through the table [`POINTS`], nothing absorbing, the ray
/// along x: `I_E = int_{-1}^{1} c(v(x)) dx` with `v` linear between the
/// centres. Its knot crossings (bracketed: the grid has no closed form for
/// them) are found here by inverting each linear piece by hand; the
/// reference is an adaptive Simpson cut at the centres and those crossings.
/// With the cuts, `c(v(x))` is linear on every piece, so 2 Gauss–Legendre
/// nodes per piece are exact up to rounding.
#[test]
fn transfer_table_on_a_voxel_grid_brackets_its_knots() {
    let xs = [-0.75, -0.25, 0.25, 0.75];
    let vs = [0.2, 1.0, 1.4, 0.5];
    let grid = lightquad::volume::VoxelGrid::new(
        Vec3::new(-1.0, -1.0, -1.0),
        Vec3::new(1.0, 1.0, 1.0),
        [4, 1, 1],
        vs.to_vec(),
    )
    .expect("valid grid");
    let mut scene = VolumeScene::new(ray([-3.0, 0.1, 0.2], [1.0, 0.0, 0.0]));
    scene.medium = Some(Arc::new(grid));
    scene.lambda = 0.0;
    scene.emission = Some(EmissionMap::Table(
        TransferTable::new(POINTS.to_vec()).expect("valid table"),
    ));
    let v = |x: f64| {
        if x <= xs[0] {
            return vs[0];
        }
        if x >= xs[3] {
            return vs[3];
        }
        let i = xs.iter().rposition(|&c| c <= x).expect("inside");
        let i = i.min(2);
        vs[i] + (vs[i + 1] - vs[i]) * (x - xs[i]) / (xs[i + 1] - xs[i])
    };
    let mut cuts = vec![-1.0, 1.0];
    cuts.extend(xs);
    for i in 0..3 {
        for (vk, _) in POINTS {
            let u = (vk - vs[i]) / (vs[i + 1] - vs[i]);
            if 0.0 < u && u < 1.0 {
                cuts.push(xs[i] + u * (xs[i + 1] - xs[i]));
            }
        }
    }
    cuts.sort_by(f64::total_cmp);
    let reference = simpson_pieces(&|x| c_by_hand(v(x)), &cuts, 1e-17);
    let got = i_e(&scene, &gl(), 2);
    assert!(rel(got, reference) < 1e-13, "{got} vs {reference}");
}
