//! The statistical verdicts: their p-values against independently computed
//! ones (mpmath quadratures of the densities), and their false-alarm rate on lightquad's own unbiased
//! estimators over 200 independent seeds.

use lightquad::experiment::report::verdict::{ALPHA, Verdict, judge_budget, sidak, wilson};
use rayon::prelude::*;

#[test]
fn p_values_match_mpmath_quadratures() {
    // t = 1 / (sqrt(2.5) / sqrt 5) = sqrt 2 with 4 degrees of freedom; p = 2
    // int_t^inf of the density (mpmath, 30 digits) = 0.23019964108049898.
    let xs: Vec<(f64, f64)> = [1.0, 2.0, 3.0, 4.0, 5.0].map(|x| (x, 1.0)).to_vec();
    let j = judge_budget(std::slice::from_ref(&xs), &[2.0], &[0.0], 0.01);
    assert!((j.t - std::f64::consts::SQRT_2).abs() < 1e-12, "{}", j.t);
    assert!(
        (j.p_bias - 0.230_199_641_080_498_98).abs() < 1e-10,
        "{}",
        j.p_bias
    );
    // Error bars: sd^2 = 2.5, mean s^2 = 1, X = 4 * 2.5 = 10 with 4 degrees
    // of freedom; 2 int_10^inf of the density (mpmath) =
    // 0.0808553639890256.
    assert!((j.p_se.expect("SE given") - 0.080_855_363_989_025_58).abs() < 1e-10);
    assert!((j.se_ratio.expect("ratio") - 2.5f64.sqrt()).abs() < 1e-12);
    assert_eq!(j.verdict, Verdict::Consistent);
    // At level 0.1 the spread is too wide for the claimed errors.
    assert_eq!(
        judge_budget(&[xs], &[3.0], &[0.0], 0.1).verdict,
        Verdict::SeTooSmall
    );
    // The reference's tolerance absorbs an offset within it.
    let shifted: Vec<(f64, f64)> = [11.0, 12.0, 13.0, 14.0, 15.0].map(|x| (x, 1.6)).to_vec();
    assert_eq!(
        judge_budget(std::slice::from_ref(&shifted), &[3.0], &[0.0], 0.01).verdict,
        Verdict::Biased
    );
    assert_eq!(
        judge_budget(&[shifted], &[3.0], &[10.0], 0.01).verdict,
        Verdict::Consistent
    );
    // No standard error given: the bias test still runs.
    let bare: Vec<(f64, f64)> = [1.0, 2.0, 3.0].map(|x| (x, f64::INFINITY)).to_vec();
    assert_eq!(
        judge_budget(&[bare], &[2.0], &[0.0], 0.01).verdict,
        Verdict::NoSe
    );
    // Three repeats that happen to cluster 0.06 above the reference, each
    // claiming a standard error of 0.12: within their error bars, so not
    // biased (their own spread alone would give t = 21); the error-bar test
    // alone speaks of the clustering.
    let clustered = vec![(4.7492, 0.16), (4.7512, 0.08), (4.7418, 0.15)];
    let j = judge_budget(&[clustered], &[4.6856], &[0.0], 0.0033);
    assert!(j.p_bias > 0.1, "{j:?}");
    // A constant integrand: every repeat alike, standard errors at rounding
    // level: consistent, not "SE too large".
    let constant = vec![(4.68559, 6.85e-15); 3];
    assert_eq!(
        judge_budget(&[constant], &[4.68559], &[0.0], 0.01).verdict,
        Verdict::Consistent
    );
    // Wilson's interval for 15 of 16 (statsmodels proportion_confint(15, 16,
    // method='wilson')): (0.7167, 0.9889).
    let [lo, hi] = wilson(15, 16);
    assert!(
        (lo - 0.716_7).abs() < 1e-4 && (hi - 0.988_9).abs() < 1e-4,
        "{lo} {hi}"
    );
    // Šidák: 1 - 0.99^(1/6).
    assert!((sidak(0.01, 6) - 0.001_673_653_852_310_441_6).abs() < 1e-12);
}

#[test]
fn where_the_method_doubted_its_error_bars_the_coverage_decides() {
    // Ten repeats of a heavy-tailed estimator: nine 3 standard errors off
    // the reference with small error bars, and one lucky draw far off with
    // a large one, which inflates both the spread and the mean squared
    // error bar: sd / rms SE is near 1 and the bias is within the spread,
    // so neither test rejects; one repeat in ten is covered.
    let mut heavy: Vec<(f64, f64)> = (0..9)
        .map(|i| (1.0 + if i % 2 == 0 { 0.03 } else { -0.03 }, 0.01))
        .collect();
    heavy.push((1.5, 0.5));
    let j = judge_budget(std::slice::from_ref(&heavy), &[1.0], &[0.0], 1e-6);
    assert_eq!(j.covered, [1, 10]);
    let exact = 0.05f64.powi(10) + 10.0 * 0.95 * 0.05f64.powi(9);
    assert!(
        (j.p_coverage - exact).abs() < 1e-12 * exact,
        "{}",
        j.p_coverage
    );
    assert_eq!(j.verdict, Verdict::Consistent, "{j:?}");
    // Undoubted, it stays consistent; with one repeat doubted, the
    // coverage decides: P(X <= 1 | Binomial(10, 0.95)) = 0.05^10 + 10 *
    // 0.95 * 0.05^9 = 1.86e-11 < 1e-6, so the error bars are too small.
    assert_eq!(j.clone().in_doubt(0, 1e-6).verdict, Verdict::Consistent);
    let d = j.in_doubt(1, 1e-6);
    assert_eq!((d.verdict, d.doubted), (Verdict::SeTooSmall, 1));
    // Every repeat covered (P(X <= 10) = 1): in doubt.
    let fine: Vec<(f64, f64)> = (0..10)
        .map(|i| (1.0 + 0.01 * ((i % 5) as f64 - 2.0) / 1.4, 0.01))
        .collect();
    let j = judge_budget(&[fine], &[1.0], &[0.0], 0.01);
    assert_eq!(j.verdict, Verdict::Consistent, "{j:?}");
    assert_eq!((j.covered, j.p_coverage), ([10, 10], 1.0), "{j:?}");
    assert_eq!(j.in_doubt(3, 0.01).verdict, Verdict::SeInDoubt);
    // Error bars that are a bound (every walk alike, sd = 0): too large
    // undoubted, in doubt where the method said so. A bias stands.
    let alike = vec![(0.5, 0.1); 6];
    let j = judge_budget(&[alike], &[0.5], &[0.0], 0.01);
    assert_eq!(j.verdict, Verdict::SeTooLarge);
    assert_eq!(j.in_doubt(6, 0.01).verdict, Verdict::SeInDoubt);
    let off: Vec<(f64, f64)> = (0..6).map(|i| (2.0 + 0.001 * i as f64, 0.001)).collect();
    let j = judge_budget(&[off], &[1.0], &[0.0], 0.01);
    assert_eq!(j.in_doubt(6, 0.01).verdict, Verdict::Biased);
    // Coverage is judged per channel: three channels of one repeat share its
    // samples, so 7 of 10 in each (p = 0.0115 per channel) is not 21 of 30
    // independent trials (p = 1.1e-5).
    let seven: Vec<(f64, f64)> = (0..10)
        .map(|i| (1.0 + if i < 7 { 0.0 } else { 0.05 }, 0.01))
        .collect();
    let j = judge_budget(
        &[seven.clone(), seven.clone(), seven],
        &[1.0; 3],
        &[0.0; 3],
        1e-3,
    );
    assert_eq!(j.covered, [21, 30]);
    assert!(
        (j.p_coverage - 0.011_503_557_379_296_873).abs() < 1e-12,
        "{}",
        j.p_coverage
    );
}

/// One experiment of the calibration family, `int_0^1 e^x dx`, with
/// lightquad's unbiased random rules, run at `seed`: per rule and budget
/// the repeats' (value, standard error).
/// Per budget, the repeats' (value, standard error).
type Repeats = Vec<Vec<(f64, f64)>>;

fn repeats_at(seed: u64) -> Vec<(String, Repeats)> {
    let text = format!(
        r#"{{"name": "fa", "family": "calibration", "scene": {{}}, "quantities": ["exp"],
          "rules": [{{"rule": "monte-carlo"}}, {{"rule": "stratified"}}, {{"rule": "sobol"}}],
          "budgets": [16, 64, 256], "repeats": 6, "seed": {seed},
          "reference": {{"type": "closed-form"}}}}"#
    );
    let exp = lightquad::families::builtin()
        .load(serde_json::from_str(&text).expect("json"), "hash")
        .expect("valid");
    let results: Vec<_> = exp.jobs(None).into_iter().map(|j| exp.run_job(j)).collect();
    let mut out = Vec::new();
    for rule in ["monte-carlo", "stratified", "sobol"] {
        let per_budget = [16, 64, 256]
            .iter()
            .map(|&b| {
                results
                    .iter()
                    .filter(|r| r.rule == rule && r.budget == b)
                    .map(|r| {
                        let m = &r.quantities["exp"];
                        (m.value[0], m.error[0])
                    })
                    .collect()
            })
            .collect();
        out.push((rule.to_string(), per_budget));
    }
    out
}

#[test]
fn the_bias_test_raises_few_false_alarms_on_unbiased_estimators() {
    let exact = std::f64::consts::E - 1.0;
    let runs: Vec<_> = (0..200u64).into_par_iter().map(repeats_at).collect();
    // Per test at a level of 0.05 (enough calls to measure the rate), and
    // per rule over its three budgets at the reports' ALPHA, Šidák-corrected.
    let (mut tests, mut alarms, mut families, mut family_alarms) = (0, 0, 0, 0);
    for run in &runs {
        for (_, budgets) in run {
            let level = sidak(ALPHA, budgets.len());
            let mut any = false;
            for repeats in budgets {
                assert_eq!(repeats.len(), 6);
                tests += 1;
                let at_05 = judge_budget(std::slice::from_ref(repeats), &[exact], &[0.0], 0.05);
                alarms += usize::from(at_05.p_bias < 0.05);
                let j = judge_budget(std::slice::from_ref(repeats), &[exact], &[0.0], level);
                any |= j.verdict == Verdict::Biased;
            }
            families += 1;
            family_alarms += usize::from(any);
        }
    }
    let rate = alarms as f64 / tests as f64;
    let family_rate = family_alarms as f64 / families as f64;
    eprintln!(
        "bias test false alarms: {alarms} of {tests} tests at level 0.05 ({rate:.4}); \
         {family_alarms} of {families} rules over 3 budgets at alpha {ALPHA} ({family_rate:.4})"
    );
    assert_eq!(tests, 200 * 3 * 3);
    assert!(rate <= 2.0 * 0.05, "{rate}");
    assert!(family_rate <= 2.0 * ALPHA, "{family_rate}");
}
