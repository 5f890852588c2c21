//! Property tests (proptest): laws every rule must obey, each checked against
//! an independent computation of the same quantity.
//!
//! - linearity in the integrand: `Q(a f + b g) = a Q(f) + b Q(g)`;
//! - additivity over split intervals: `int_a^c = int_a^b + int_b^c`;
//! - invariance under an affine change of variables;
//! - reproducibility from a seed.

use crate::common;
use common::*;
use lightquad::domain::{Segment, integrate_over};
use lightquad::quadrature::{AnyRule, BaseRule, Rule};
use proptest::prelude::*;

/// Every registered rule that integrates in one dimension (the laws below
/// are checked on segments).
fn rules() -> Vec<AnyRule> {
    BaseRule::defaults()
        .into_iter()
        .map(AnyRule::from)
        .filter(|r| r.dimensions().min <= 1)
        .collect()
}

/// `sum c_i t^i` by Horner's scheme.
fn poly(c: &[f64], t: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, ci| acc * t + ci)
}

/// `int_a^b sum c_i t^i dt` in closed form.
fn poly_integral(c: &[f64], a: f64, b: f64) -> f64 {
    let antiderivative = |t: f64| {
        c.iter()
            .enumerate()
            .rev()
            .fold(0.0, |acc, (i, ci)| acc * t + ci / (i as f64 + 1.0))
            * t
    };
    antiderivative(b) - antiderivative(a)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn linear_in_the_integrand(
        p in 0.5f64..8.0, q in -3.0f64..3.0, r in -2.0f64..2.0,
        a in -5.0f64..5.0, b in -5.0f64..5.0, seed in any::<u64>(), n in 16usize..600,
    ) {
        let f = move |u: [f64; 1]| (p * u[0] + q).sin();
        let g = move |u: [f64; 1]| (r * u[0]).exp();
        for rule in rules() {
            let qf = rule.integrate(n, &mut rng(seed), f).expect("finite");
            let qg = rule.integrate(n, &mut rng(seed), g).expect("finite");
            let qh = rule
                .integrate(n, &mut rng(seed), |u: [f64; 1]| a * f(u) + b * g(u))
                .expect("finite");
            let combined = a * qf.value + b * qg.value;
            let scale = a.abs() * 1.0 + b.abs() * (r.abs()).exp();
            // Fixed node sets are linear to rounding; the adaptive rule picks
            // its subdivision per integrand, so it is linear to its error.
            let tol = 1e-13 * scale
                + if rule.name() == "gauss-kronrod" {
                    a.abs() * qf.error + b.abs() * qg.error + qh.error
                } else {
                    0.0
                };
            prop_assert!(
                (qh.value - combined).abs() <= tol,
                "{}: {} vs {}", rule.name(), qh.value, combined
            );
        }
    }

    #[test]
    fn additive_over_split_intervals(
        c in proptest::collection::vec(-1.0f64..1.0, 1..20),
        a in -2.0f64..0.0, frac in 0.05f64..0.95, len in 0.1f64..3.0,
    ) {
        // Gauss–Legendre with 10 nodes is exact for degree <= 19, so both
        // sides equal the closed form.
        let (cc, b) = (a + len, a + frac * len);
        let rule = AnyRule::by_name("gauss-legendre").expect("registered");
        let whole = Segment::new(a, cc).expect("valid");
        let split = Segment::with_breaks(a, cc, vec![b]).expect("valid");
        let f = |t: f64| poly(&c, t);
        let q_whole = whole.integrate(&rule, 10, &mut rng(0), f).expect("finite");
        let q_split = split.integrate(&rule, 10, &mut rng(0), f).expect("finite");
        let exact = poly_integral(&c, a, cc);
        let scale = c.iter().map(|x| x.abs()).sum::<f64>() * 5f64.powi(c.len() as i32) * len;
        prop_assert!((q_whole.value - exact).abs() <= 1e-13 * scale);
        prop_assert!((q_split.value - exact).abs() <= 1e-13 * scale);
        prop_assert_eq!(q_split.evaluations, 2 * q_whole.evaluations);
    }

    #[test]
    fn invariant_under_affine_change_of_variables(
        a in -10.0f64..10.0, len in 0.01f64..10.0, s in 0.01f64..100.0, shift in -100.0f64..100.0,
        seed in any::<u64>(), n in 16usize..400,
    ) {
        // int_a^b f(t) dt = s int_{(a - c)/s}^{(b - c)/s} f(s tau + c) d tau
        let f = |t: f64| (0.3 * t).cos() + 0.1 * t;
        let b = a + len;
        let left = Segment::new(a, b).expect("valid");
        let right = Segment::new((a - shift) / s, (b - shift) / s).expect("valid");
        for rule in rules() {
            let ql = integrate_over(&rule, &left, n, &mut rng(seed), f).expect("finite");
            let qr = integrate_over(&rule, &right, n, &mut rng(seed), |tau: f64| s * f(s * tau + shift))
                .expect("finite");
            let scale = len * (1.0 + 0.1 * a.abs().max(b.abs()));
            prop_assert!(
                (ql.value - qr.value).abs() <= 1e-12 * scale,
                "{}: {} vs {}", rule.name(), ql.value, qr.value
            );
        }
    }

    #[test]
    fn reproducible_from_a_seed(seed in any::<u64>(), n in 16usize..2000) {
        let f = |u: [f64; 2]| (u[0] * u[1]).exp();
        let mut all = rules();
        all.push(AnyRule::by_name("product(stratified,gauss-legendre)").expect("known"));
        for rule in all {
            // Rules that do not integrate in 2-D, or need a larger budget there.
            if !rule.dimensions().contains(2) || n < rule.min_budget(2) {
                continue;
            }
            let first = rule.integrate(n, &mut rng(seed), f).expect("finite");
            let again = rule.integrate(n, &mut rng(seed), f).expect("finite");
            prop_assert_eq!(first.value.to_bits(), again.value.to_bits());
            prop_assert_eq!(first.error.to_bits(), again.error.to_bits());
            let other = rule.integrate(n, &mut rng(seed ^ 0x5555), f).expect("finite");
            prop_assert_eq!(other.value != first.value, rule.is_random(), "{}", rule.name());
        }
    }
}
