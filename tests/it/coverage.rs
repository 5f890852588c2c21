//! Coverage of the stochastic methods' error estimates: over `R` independent
//! repeats, how often `|value - exact| <= 1.96 error` holds, for every
//! stochastic rule (monte-carlo, stratified, sobol) and every tracking
//! estimator on every quantity it estimates, against closed forms (constant
//! sphere: tau, I_B, I_E and I_L with the light behind the eye; Gaussian
//! blobs: tau, and I_E with `c = k v`, which is `(k / lambda) (1 - tau)`).
//!
//! The count is tested against Binomial(R, 0.95) two-sided at
//! `ALPHA = 1e-4`: an honest 95% interval fails the test by chance once in
//! 10^4 independent runs (the seeds are fixed, so every run is the same).
//! With `R = 400` the accepted counts are about 363..=396 (90.8%..99%).

use crate::common;
use common::*;
use lightquad::domain::Vec3;
use lightquad::exact::volume as exact;
use lightquad::family::{Family, Flag, Method};
use lightquad::geometry::Ray;
use lightquad::quadrature::{AnyRule, Rule};
use lightquad::volume::experiment::{Built, Volume, VolumeQuantity as Q};
use lightquad::volume::tracking::{Tracker, Wanted, radiance};
use lightquad::volume::{
    ConstantSphere, DepthScheme, DirectionalLight, EmissionMap, GaussianBlob, GaussianBlobs,
    ShadowMethod, VolumeScene,
};
use statrs::distribution::{Binomial, DiscreteCDF};
use std::sync::Arc;

/// Repeats per coverage count.
const R: u64 = 400;
/// Two-sided significance of the binomial test.
const ALPHA: f64 = 1e-4;

/// Panics unless `covered` of `R` is consistent with a coverage of 0.95 at
/// two-sided significance `ALPHA`.
fn assert_95(covered: u64, what: &str) {
    let binom = Binomial::new(0.95, R).expect("valid");
    let low = binom.cdf(covered);
    let high = 1.0 - binom.cdf(covered.saturating_sub(1));
    eprintln!("{what}: {covered}/{R}");
    assert!(
        low > ALPHA / 2.0 && high > ALPHA / 2.0,
        "{what}: {covered}/{R} covered at 1.96 errors (P(<=) {low:.1e}, P(>=) {high:.1e})"
    );
}

/// Panics unless `covered` of `R` is consistent with a coverage of at least
/// 0.95 (one-sided, at `ALPHA / 2`).
fn assert_at_least_95(covered: u64, what: &str) {
    let binom = Binomial::new(0.95, R).expect("valid");
    eprintln!("{what}: {covered}/{R}");
    assert!(
        binom.cdf(covered) > ALPHA / 2.0,
        "{what}: {covered}/{R} covered at 1.96 errors"
    );
}

/// Chord length 2 through a unit sphere of density `kappa` centred at the
/// origin; emission `c = 1`, background 0.5, a light of intensity 2 behind
/// the eye (so V-L has the closed form `exact::light_behind`).
fn sphere(kappa: f64, albedo: Option<f64>) -> VolumeScene {
    let ray = Ray::new(Vec3::new(-3.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0)).expect("ray");
    let mut s = VolumeScene::new(ray);
    s.medium = Some(Arc::new(
        ConstantSphere::new(Vec3::zeros(), 1.0, kappa).expect("sphere"),
    ));
    s.emission = Some(EmissionMap::Constant(1.0));
    s.background = Some(0.5);
    s.light = Some(DirectionalLight::new(Vec3::new(-1.0, 0.0, 0.0), 2.0, albedo).expect("light"));
    s
}

/// The closed forms of the sphere scene (`sigma = kappa`, chord 2).
fn sphere_exact(kappa: f64, albedo: Option<f64>, q: Q) -> f64 {
    let (sigma, chord) = (kappa, 2.0);
    let tau = (-sigma * chord).exp();
    let e = exact::emission(sigma, chord, 1.0);
    let l = exact::light_behind(sigma, chord, 2.0, albedo);
    match q {
        Q::Tau => tau,
        Q::LnTau => -sigma * chord,
        Q::Background => 0.5 * tau,
        Q::Emission => e,
        Q::Light => l,
        Q::Total => e + 0.5 * tau + l,
    }
}

pub(crate) fn built(scene: VolumeScene, scheme: DepthScheme, shadow: ShadowMethod) -> Built {
    Built {
        scene,
        scheme,
        shadow,
        sphere_kappa: None,
        printed: None,
        field_sphere_value: None,
    }
}

/// Coverage counts of `quantities` by `method` at `budget` over `R` seeds.
fn coverage(
    b: &Built,
    method: &Method<Tracker>,
    budget: usize,
    quantities: &[Q],
    exact: impl Fn(Q) -> f64,
) -> Vec<u64> {
    let mut covered = vec![0u64; quantities.len()];
    for seed in 0..R {
        let out = Volume::evaluate(b, method, budget, &mut rng(90_000 + seed), quantities)
            .expect("finite");
        for (c, q) in covered.iter_mut().zip(quantities) {
            let m = &out[q];
            if (m.value[0] - exact(*q)).abs() <= 1.96 * m.error[0] {
                *c += 1;
            }
        }
    }
    covered
}

#[test]
fn stochastic_rules_cover_95_percent_on_every_volume_quantity() {
    // On the constant sphere tau and I_B are exp(-depth) of a constant
    // integrand, exact for every rule (error 0 against rounding): their
    // coverage is taken on the blobs, whose density varies.
    let on_sphere = [Q::Emission, Q::Light, Q::Total];
    let on_blobs = [Q::Tau, Q::Background, Q::Emission, Q::Total];
    for name in ["monte-carlo", "stratified", "sobol"] {
        let rule = Method::Rule(AnyRule::by_name(name).expect("registered"));
        for (kappa, albedo) in [(2.0, None), (0.3, Some(0.8))] {
            let b = built(
                sphere(kappa, albedo),
                DepthScheme::Cumulative,
                ShadowMethod::ClosedFormWhereAvailable,
            );
            // 16 samples: the sample standard error alone covered 87-94%
            // (stratified: 5 degrees of freedom); the Student-t widening
            // must bring it to 95%.
            for n in [16, 64] {
                let counts = coverage(&b, &rule, n, &on_sphere, |q| sphere_exact(kappa, albedo, q));
                for (q, c) in on_sphere.iter().zip(counts) {
                    let what = format!("{name} kappa {kappa} albedo {albedo:?} {q:?} n = {n}");
                    if name == "stratified" {
                        // At 16 cells the second differences also carry the
                        // integrand's curvature, (f'' h^2)^2 against
                        // sigma^2 = (f' h)^2 / 12 (68% more at kappa 2), and
                        // the row's end triples count double; the end cells'
                        // first differences (which see an endpoint
                        // singularity) add (f' h)^2 at each row end, up to
                        // sqrt(1 + 24/m) in the error: conservative (99.75%
                        // at 64 cells), which only the lower bound checks.
                        assert_at_least_95(c, &what);
                    } else {
                        assert_95(c, &what);
                    }
                }
            }
        }
        let b = built(
            blobs(),
            DepthScheme::Cumulative,
            ShadowMethod::ClosedFormWhereAvailable,
        );
        // 256 samples: at 64 the sampled Gaussian bumps are still too skewed
        // for a normal interval (tau: 91% for monte-carlo and sobol).
        let counts = coverage(&b, &rule, 256, &on_blobs, blobs_exact);
        for (q, c) in on_blobs.iter().zip(counts) {
            assert_95(c, &format!("{name} blobs {q:?} n = 256"));
        }
    }
}

#[test]
fn delta_tracking_covers_95_percent_on_every_quantity_it_estimates() {
    let delta = Method::Estimator(Tracker::Delta);
    let quantities = Volume::estimates(&Tracker::Delta).to_vec();
    for (kappa, albedo) in [(2.0, None), (0.3, Some(0.8))] {
        for shadow in [
            ShadowMethod::ClosedFormWhereAvailable,
            ShadowMethod::Quadrature,
        ] {
            let b = built(sphere(kappa, albedo), DepthScheme::Cumulative, shadow);
            let counts = coverage(&b, &delta, 1000, &quantities, |q| {
                sphere_exact(kappa, albedo, q)
            });
            for (q, c) in quantities.iter().zip(counts) {
                assert_95(
                    c,
                    &format!("delta kappa {kappa} albedo {albedo:?} {shadow:?} {q:?}"),
                );
            }
        }
    }
}

/// Two overlapping Gaussian blobs crossed off-centre: density varies along
/// the ray, so tracking draws null collisions.
pub(crate) fn blobs() -> VolumeScene {
    let medium = GaussianBlobs::new(vec![
        GaussianBlob {
            centre: Vec3::new(0.0, 0.1, 0.0),
            amplitude: 1.2,
            width: 0.4,
        },
        GaussianBlob {
            centre: Vec3::new(0.6, -0.2, 0.1),
            amplitude: 0.8,
            width: 0.25,
        },
    ])
    .expect("blobs");
    let ray = Ray::new(Vec3::new(-6.0, 0.0, 0.05), Vec3::new(1.0, 0.02, 0.0)).expect("ray");
    let mut s = VolumeScene::new(ray);
    s.medium = Some(Arc::new(medium));
    s.lambda = 1.5;
    s.emission = Some(EmissionMap::Proportional(0.6));
    s.background = Some(0.7);
    s
}

/// tau of the blob scene in closed form, and I_E with `c = k v`:
/// `int tau k v dt = (k / lambda) int sigma tau dt = (k / lambda) (1 - tau)`.
pub(crate) fn blobs_exact(q: Q) -> f64 {
    let s = blobs();
    let medium = s.medium.as_deref().expect("medium");
    let depth = s.lambda
        * medium
            .density_integral(&s.ray, 0.0, f64::INFINITY)
            .expect("erf");
    let tau = (-depth).exp();
    match q {
        Q::Tau => tau,
        Q::Background => 0.7 * tau,
        Q::Emission => 0.6 / s.lambda * (1.0 - tau),
        Q::Total => 0.6 / s.lambda * (1.0 - tau) + 0.7 * tau,
        Q::LnTau => -depth,
        Q::Light => 0.0,
    }
}

#[test]
fn every_tracker_covers_95_percent_with_null_collisions() {
    let b = built(
        blobs(),
        DepthScheme::Cumulative,
        ShadowMethod::ClosedFormWhereAvailable,
    );
    for tracker in [Tracker::Delta, Tracker::Ratio, Tracker::ResidualRatio] {
        // Every quantity the tracker estimates that the blob scene has in
        // closed form (it has no light).
        let quantities: Vec<Q> = Volume::estimates(&tracker)
            .iter()
            .copied()
            .filter(|q| *q != Q::Light)
            .collect();
        let counts = coverage(
            &b,
            &Method::Estimator(tracker),
            1000,
            &quantities,
            blobs_exact,
        );
        for (q, c) in quantities.iter().zip(counts) {
            assert_95(c, &format!("{} blobs {q:?}", tracker.name()));
        }
    }
}

#[test]
fn walks_that_all_agree_are_flagged_and_their_error_is_not_zero() {
    // tau = e^-5 = 0.0067 at n = 16: most runs see no walk get through. The
    // sample standard error is then 0 (at d2a83ee: 179 of 200 runs gave
    // 0 +- 0, coverage 10.5%); the Wilson half-width must cover instead.
    let kappa = 2.5;
    let b = built(
        sphere(kappa, None),
        DepthScheme::Cumulative,
        ShadowMethod::ClosedFormWhereAvailable,
    );
    let tau = sphere_exact(kappa, None, Q::Tau);
    for tracker in [Tracker::Delta, Tracker::Ratio] {
        let (mut alike, mut covered) = (0u64, 0u64);
        for seed in 0..R {
            let out = Volume::evaluate(
                &b,
                &Method::Estimator(tracker),
                16,
                &mut rng(seed),
                &[Q::Tau],
            )
            .expect("finite");
            let m = &out[&Q::Tau];
            if m.flags.contains(&Flag::AllWalksAlike { walks: 16 }) {
                alike += 1;
                assert!(m.error[0] > 0.0, "{}: 0 +- 0", tracker.name());
            }
            if (m.value[0] - tau).abs() <= 1.96 * m.error[0] {
                covered += 1;
            }
        }
        eprintln!(
            "{}: {alike}/{R} runs all alike, coverage {covered}/{R}",
            tracker.name()
        );
        match tracker {
            // Most runs are degenerate here (P(no walk through) = (1 - tau)^16 = 0.90).
            Tracker::Delta => assert!(alike > R * 8 / 10, "delta: {alike}"),
            // Ratio tracking at the rate 10 sigma (D = 5: ratio_rate_factor)
            // scores 0.9^K for K ~ Poisson(50) collisions, never all alike; at
            // the bound itself (before 2026-11-24) every weight was 1 - sigma /
            // (sigma (1 + 8 eps)) ~ 0 and every run was degenerate.
            _ => assert_eq!(alike, 0, "ratio: {alike} runs all alike"),
        }
        // The bound is conservative here: coverage must not fall below 95%.
        assert_at_least_95(covered, tracker.name());
    }
}

#[test]
fn delta_tracking_radiance_is_unbiased_against_closed_forms() {
    // 200 000 walks: each estimate within 4 standard errors of its closed
    // form, and the standard error small enough (< 2% of the value) that a
    // bias of 8% would be seen.
    let n = 200_000;
    for (kappa, albedo, shadow) in [
        (2.0, None, ShadowMethod::ClosedFormWhereAvailable),
        (2.0, Some(0.8), ShadowMethod::Quadrature),
        (0.3, None, ShadowMethod::Quadrature),
        (0.3, Some(0.5), ShadowMethod::ClosedFormWhereAvailable),
    ] {
        let scene = sphere(kappa, albedo);
        let wanted = Wanted {
            emission: true,
            light: true,
        };
        let r = radiance(&scene, shadow, wanted, n, &mut rng(11)).expect("finite");
        for (q, t) in [
            (Q::Tau, r.tau),
            (Q::Background, r.background),
            (Q::Emission, r.emission),
            (Q::Light, r.light),
            (Q::Total, r.total),
        ] {
            let x = sphere_exact(kappa, albedo, q);
            let z = (t.value - x) / t.error;
            eprintln!(
                "kappa {kappa} {albedo:?} {shadow:?} {q:?}: {} vs {x}, z = {z:.2}",
                t.value
            );
            assert!(z.abs() < 4.0, "{q:?}: {} vs {x} (z = {z})", t.value);
            assert!(t.error < 2e-2 * x, "{q:?}: error {} of {x}", t.error);
        }
    }
    // Emission and light where sigma = 0 (lambda = 0): tau = 1, I_E = c L,
    // and V-L as printed is I_p L (a collision estimator c / sigma would be
    // undefined here).
    let mut scene = sphere(2.0, None);
    scene.lambda = 0.0;
    let wanted = Wanted {
        emission: true,
        light: true,
    };
    let r = radiance(
        &scene,
        ShadowMethod::Quadrature,
        wanted,
        20_000,
        &mut rng(3),
    )
    .expect("finite");
    assert_eq!(r.tau.value, 1.0);
    for (t, x) in [(r.emission, 2.0), (r.light, 4.0)] {
        assert!(((t.value - x) / t.error).abs() < 4.0, "{} vs {x}", t.value);
    }
}

/// One tentative collision scores `c / mu`: with c = 8e306 and a thin medium
/// (sigma = 1e-3) that is 8e309, beyond f64, although I_E = 1.6e304. The
/// scores were inf (and their mean NaN, a failed job); now every term is
/// finite and within 4 standard errors of its closed form.
#[test]
fn delta_tracking_scores_beyond_f64_in_a_thin_medium_stay_finite() {
    let (kappa, c, i_p, b) = (1e-3, 8e306, 1e306, 1e306);
    let mut scene = sphere(kappa, None);
    scene.emission = Some(EmissionMap::Constant(c));
    scene.light = Some(DirectionalLight::new(Vec3::new(-1.0, 0.0, 0.0), i_p, None).expect("light"));
    scene.background = Some(b);
    let wanted = Wanted {
        emission: true,
        light: true,
    };
    let r = radiance(
        &scene,
        ShadowMethod::ClosedFormWhereAvailable,
        wanted,
        40_000,
        &mut rng(5),
    )
    .expect("finite");
    let (sigma, chord) = (kappa, 2.0);
    let e = exact::emission(sigma, chord, c);
    let l = exact::light_behind(sigma, chord, i_p, None);
    let bg = b * (-sigma * chord).exp();
    for (what, t, x) in [
        ("I_E", r.emission, e),
        ("I_L", r.light, l),
        ("I_B", r.background, bg),
        ("I", r.total, e + l + bg),
    ] {
        assert!(t.value.is_finite() && t.error.is_finite(), "{what}: {t:?}");
        let z = (t.value - x) / t.error;
        assert!(z.abs() < 4.0, "{what}: {} vs {x} (z = {z})", t.value);
    }
}

/// Panics unless `count` of `R` is consistent with a rate of at least `p`
/// (one-sided binomial at `ALPHA / 2`).
fn assert_at_least(p: f64, count: u64, what: &str) {
    let binom = Binomial::new(p, R).expect("valid");
    eprintln!("{what}: {count}/{R}");
    assert!(
        binom.cdf(count) > ALPHA / 2.0,
        "{what}: {count}/{R}, below a rate of {p}"
    );
}

/// Over `R` seeds of a 1-D integral by `rule` at budget `n`: how many runs
/// covered `exact` at 1.96 errors, how many were flagged (`reliable ==
/// false`), and how many did neither.
fn rule_runs(rule: &AnyRule, n: usize, f: Integrand, exact: f64) -> (u64, u64, u64) {
    let (mut covered, mut flagged, mut missed) = (0, 0, 0);
    for seed in 0..R {
        let e = rule
            .integrate::<1, f64, _, _>(n, &mut rng(70_000 + seed), |u: [f64; 1]| f(u[0]))
            .expect("finite");
        let c = (e.value - exact).abs() <= 1.96 * e.error;
        covered += c as u64;
        flagged += !e.reliable as u64;
        missed += (!c && e.reliable) as u64;
    }
    (covered, flagged, missed)
}

/// A 1-D integrand.
type Integrand = fn(f64) -> f64;

fn random_rule(name: &str) -> AnyRule {
    AnyRule::by_name(name).expect("registered")
}

#[test]
fn unseen_rare_events_and_samples_that_all_agree_are_flagged() {
    // f = 1e6 on [0.5, 0.5 + 1e-6), 0 elsewhere: int = 1e6 * 1e-6 = 1. At
    // ~1000 samples 999 runs in 1000 see only zeros (at c3ad464: 0 +- 0,
    // unflagged, coverage 0-0.7% for all three rules); a run that hits the
    // event sees one sample dominate the spread.
    let rare: Integrand = |x| {
        if (0.5..0.5 + 1e-6).contains(&x) {
            1e6
        } else {
            0.0
        }
    };
    for (name, n) in [("monte-carlo", 1000), ("sobol", 1024), ("stratified", 1000)] {
        let (covered, flagged, missed) = rule_runs(&random_rule(name), n, rare, 1.0);
        eprintln!(
            "{name} rare event: covered {covered}, flagged {flagged}, missed {missed} of {R}"
        );
        assert_eq!(missed, 0, "{name}: uncovered and unflagged runs");
        // A constant integrand (int = 2.5) is exact and flagged: nothing
        // was seen to vary, which is what the flag says.
        let e = random_rule(name)
            .integrate::<1, f64, _, _>(64, &mut rng(1), |_| 2.5)
            .expect("finite");
        assert!(!e.reliable && (e.value - 2.5).abs() < 1e-14 && e.error == 0.0);
    }
    // int_0^1 [x < 0.1] = 0.1. Each scrambled net of 2^k points puts
    // floor(0.1 2^k) or one more below 0.1, with one chance in
    // P = frac(0.1 2^k) of the latter, so all eight scrambles agree with
    // probability P^8 + (1 - P)^8 (0.17 at 2^9 points): at c3ad464 sobol
    // covered 82% at every n, unflagged; now 0-0.2% neither covered nor
    // flagged.
    let step: Integrand = |x| f64::from(x < 0.1);
    let (_, _, missed) = rule_runs(&random_rule("sobol"), 4096, step, 0.1);
    assert_at_least_95(R - missed, "sobol [x < 0.1] n = 4096 covered or flagged");
}

#[test]
fn infinite_variance_samples_are_flagged_or_covered() {
    // int_0^1 x^-0.9 dx = x^0.1 / 0.1 |_0^1 = 10 (finite mean, infinite
    // variance): at c3ad464 monte-carlo and sobol covered 25-30% of runs at
    // every n, unflagged. Measured now at 256 and 1024 samples (1000
    // repeats): 96-99% flagged, 1.4-3.3% neither covered nor flagged.
    let x09: Integrand = |x| x.powf(-0.9);
    // int_0^1 x^-0.6 dx = x^0.4 / 0.4 |_0^1 = 2.5 (infinite variance):
    // coverage 67-79% unflagged at 256 samples before, 88-89% flagged now.
    let x06: Integrand = |x| x.powf(-0.6);
    for name in ["monte-carlo", "sobol"] {
        let rule = random_rule(name);
        for n in [256, 1024] {
            let (covered, flagged, missed) = rule_runs(&rule, n, x09, 10.0);
            eprintln!("{name} x^-0.9 n = {n}: covered {covered}, flagged {flagged}");
            assert_at_least(
                0.95,
                R - missed,
                &format!("{name} x^-0.9 n = {n} covered or flagged"),
            );
        }
        let (_, flagged, _) = rule_runs(&rule, 256, x06, 2.5);
        assert_at_least(0.8, flagged, &format!("{name} x^-0.6 n = 256 flagged"));
    }
}

/// Stratified sampling at an endpoint singularity `x^-a` (integral `1/(1 -
/// a)`): one sample of the end cell cannot show that its variance is large
/// or infinite, and with second differences alone the estimate was unflagged
/// at 56% (`a = 0.9`), 82% (0.6) and 90-92% (0.25) coverage, with 59 of 400
/// runs at `a = 0.9` under a tenth of the error. A row's end cells now also
/// count their first difference, which sees the value grow toward the
/// boundary: coverage at 1.96 errors of 97.5% (`a = 0.6`) and 99.8%
/// (0.45). At `a = 0.9` it stays near 68%, and about 3% of runs (11 of 400
/// measured) remain under a tenth of the error, unflagged: said here, not
/// fixed.
#[test]
fn stratified_covers_an_endpoint_singularity_of_finite_variance() {
    let rule = random_rule("stratified");
    let x06: Integrand = |x| x.powf(-0.6);
    let x045: Integrand = |x| x.powf(-0.45);
    for n in [32, 1024] {
        for (f, exact, what) in [(x06, 2.5, "x^-0.6"), (x045, 1.0 / 0.55, "x^-0.45")] {
            let (covered, flagged, _) = rule_runs(&rule, n, f, exact);
            assert_eq!(flagged, 0, "{what} n = {n}");
            assert_at_least_95(covered, &format!("stratified {what} n = {n} covered"));
        }
        let mut lies = 0;
        for seed in 0..R {
            let e = rule
                .integrate::<1, f64, _, _>(n, &mut rng(80_000 + seed), |u: [f64; 1]| {
                    u[0].powf(-0.9)
                })
                .expect("finite");
            lies += u64::from(e.reliable && e.error < 0.1 * (e.value - 10.0).abs());
        }
        eprintln!("stratified x^-0.9 n = {n}: {lies} of {R} under a tenth of the error");
        assert!(lies * 20 < R, "x^-0.9 n = {n}: {lies} of {R}");
    }
}

#[test]
fn smooth_integrands_keep_their_coverage_unflagged() {
    // int_0^1 x = 1/2, e^x = e - 1, sin(pi x) = 2/pi. The tail diagnostic
    // flagged none of 1000 runs from 64 samples on, and 0.1-0.6% at 16.
    let smooth: [(Integrand, f64, &str); 3] = [
        (|x| x, 0.5, "x"),
        (f64::exp, std::f64::consts::E - 1.0, "e^x"),
        (
            |x| (std::f64::consts::PI * x).sin(),
            2.0 / std::f64::consts::PI,
            "sin(pi x)",
        ),
    ];
    for name in ["monte-carlo", "sobol", "stratified"] {
        let rule = random_rule(name);
        for (f, exact, what) in smooth {
            for n in [16, 64, 1024] {
                let (covered, flagged, _) = rule_runs(&rule, n, f, exact);
                let what = format!("{name} {what} n = {n}");
                if n == 16 {
                    assert!(flagged <= R / 50, "{what}: {flagged}/{R} flagged");
                } else {
                    assert_eq!(flagged, 0, "{what}: flagged");
                }
                if name == "stratified" {
                    // Conservative below ~256 cells (97-99%): the lower
                    // bound only.
                    assert_at_least_95(covered, &what);
                } else {
                    assert_95(covered, &what);
                }
            }
        }
    }
}

#[test]
fn stratified_sees_a_jump_inside_one_cell() {
    // A step inside one cell is seen by a triple only where the cell sits
    // in its middle or its sample falls on the side unlike its neighbours:
    // with disjoint triples (c3ad464) coverage was 33% (step at 0.123456,
    // n = 100), 30% (0.5013, n = 1000), 25% (e^x + 2 step(0.7071), n = 64;
    // 0.7072 here, in the same cell), unflagged. Every sliding triple sees
    // it now: 100% over 2000 repeats.
    const C: f64 = 0.123456;
    let cases: [(Integrand, f64, &str, &[usize]); 4] = [
        // int_0^1 [x >= C] = 1 - C.
        (
            |x| f64::from(x >= C),
            1.0 - C,
            "step",
            &[32, 100, 1000, 1024],
        ),
        // int_0^1 x + [x >= C] = 1/2 + 1 - C.
        (|x| x + f64::from(x >= C), 1.5 - C, "x + step", &[100, 1000]),
        // int_0^1 [x >= 0.5013] = 0.4987.
        (
            |x| f64::from(x >= 0.5013),
            0.4987,
            "step at 0.5013",
            &[256, 1000],
        ),
        // int_0^1 e^x + 2 [x >= 0.7072] = e - 1 + 2 (1 - 0.7072).
        (
            |x| x.exp() + 2.0 * f64::from(x >= 0.7072),
            std::f64::consts::E - 1.0 + 2.0 * (1.0 - 0.7072),
            "e^x + 2 step",
            &[16, 64],
        ),
    ];
    let rule = random_rule("stratified");
    for (f, exact, what, budgets) in cases {
        for &n in budgets {
            let (_, _, missed) = rule_runs(&rule, n, f, exact);
            assert_at_least_95(
                R - missed,
                &format!("stratified {what} n = {n} covered or flagged"),
            );
        }
    }
    // A spike inside one cell, 1e4 on [0.3, 0.3001): int = 1. A run whose
    // sample misses it sees a constant and is flagged; one that hits it
    // has a triple of size 1e4 and covers.
    let spike: Integrand = |x| if (0.3..0.3001).contains(&x) { 1e4 } else { 0.0 };
    for n in [64, 1024] {
        let (_, _, missed) = rule_runs(&rule, n, spike, 1.0);
        assert_eq!(missed, 0, "spike at n = {n}");
    }
}
