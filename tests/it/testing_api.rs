//! `lightquad::testing` against independent references: Pearson's
//! statistic and the expected counts by hand, the false-alarm rates of the
//! chi-square and estimator tests on correct samplers over hundreds of
//! seeds (at most twice alpha), their power on planted bugs (at least
//! 99%), orders of known rules, closed forms computed here, and an `Err`
//! naming the culprit for every bad input.

use std::f64::consts::PI;

use lightquad::QuadError;
use lightquad::domain::{Disk, Hemisphere, Pixel, SphericalCap, Triangle, Vec3};
use lightquad::rand::RngExt;
use lightquad::rand_pcg::Pcg64;
use lightquad::testing::estimator::CheckKind;
use lightquad::testing::{ChiSquare, EstimatorTest, Order, Reference};

/// Malley's cosine-weighted hemisphere sampling.
fn cosine(u: [f64; 2]) -> Option<Vec3> {
    let (r, phi) = (u[0].sqrt(), 2.0 * PI * u[1]);
    Some(Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u[0]).sqrt()))
}

/// The planted Jacobian bug: the disk's radius `u_0` where it is `sqrt(u_0)`.
fn cosine_no_jacobian(u: [f64; 2]) -> Option<Vec3> {
    let (r, phi) = (u[0], 2.0 * PI * u[1]);
    Some(Vec3::new(
        r * phi.cos(),
        r * phi.sin(),
        ((1.0 - r) * (1.0 + r)).sqrt(),
    ))
}

/// Uniform directions on the sphere.
fn sphere(u: [f64; 2]) -> Option<Vec3> {
    let z = 1.0 - 2.0 * u[0];
    let r = ((1.0 - z) * (1.0 + z)).max(0.0).sqrt();
    let phi = 2.0 * PI * u[1];
    Some(Vec3::new(r * phi.cos(), r * phi.sin(), z))
}

/// Uniform points of the triangle (0,0,0), (1,0,0), (0,1,0) by the square
/// root map, refusing a quarter of the draws (a sampler that can fail).
fn triangle(u: [f64; 2]) -> Option<Vec3> {
    if u[1] > 0.75 {
        return None;
    }
    let s = u[0].sqrt();
    let v = u[1] / 0.75;
    Some(Vec3::new(1.0 - s, s * (1.0 - v), 0.0))
}

/// Uniform points of the unit disk about the origin in the plane z = 0.
fn disk(u: [f64; 2]) -> Option<Vec3> {
    let (r, phi) = (u[0].sqrt(), 2.0 * PI * u[1]);
    Some(Vec3::new(r * phi.cos(), r * phi.sin(), 0.0))
}

#[test]
fn pearsons_statistic_and_the_expected_counts_agree_with_a_hand_computation()
-> Result<(), QuadError> {
    // Density 2 u_0 on the unit square in 4 x 1 cells: cell i expects
    // N ((i+1)^2 - i^2) / 16 samples, exactly.
    let n = 16_000;
    let test = ChiSquare::new(Pixel::unit_square())
        .cells([4, 1])
        .samples(n);
    let expected = test.expect(|p: &[f64; 2]| 2.0 * p[0])?;
    let hand: Vec<f64> = (0..4)
        .map(|i| n as f64 * ((i + 1) * (i + 1) - i * i) as f64 / 16.0)
        .collect();
    for (e, h) in expected.counts().iter().zip(&hand) {
        assert!((e - h).abs() < 1e-6, "{e} vs {h}");
    }
    // Samples from the sqrt map; Pearson's statistic from the counts here.
    let mut observed = [0.0; 4];
    let mut rng = <Pcg64 as lightquad::rand::SeedableRng>::seed_from_u64(5);
    for _ in 0..n {
        let x: f64 = rng.random::<f64>();
        let _: f64 = rng.random::<f64>();
        observed[((x.sqrt() * 4.0) as usize).min(3)] += 1.0;
    }
    let stat: f64 = (0..4)
        .map(|i| (observed[i] - hand[i]).powi(2) / hand[i])
        .sum();
    let out = expected.test(|u| Some([u[0].sqrt(), u[1]]), 5)?;
    assert!(
        (out.statistic - stat).abs() < 1e-9 * stat,
        "{} vs {stat}",
        out.statistic
    );
    assert_eq!(out.dof, 3);
    // chi-square survival with 3 dof in closed form:
    // erfc(sqrt(x/2)) + sqrt(2x/pi) e^(-x/2).
    let x = out.statistic;
    let sf =
        statrs::function::erf::erfc((x / 2.0).sqrt()) + (2.0 * x / PI).sqrt() * (-x / 2.0).exp();
    // statrs's erfc is good to about 1e-11 here.
    assert!(
        (out.p_value - sf).abs() < 1e-10,
        "{} vs {sf} at {x:?}",
        out.p_value
    );
    // mpmath at 40 digits, gammainc(3/2, x/2, inf, regularized) at this
    // seed's statistic: 0.75267540525294067657.
    assert_eq!(x, 1.2013714285714285);
    assert!((out.p_value - 0.752_675_405_252_940_7).abs() < 1e-15);
    Ok(())
}

/// Fraction of `seeds` seeds whose test fails, for each sampler.
fn failures<Dom, P, S>(
    test: ChiSquare<Dom>,
    pdf: P,
    sample: S,
    seeds: u64,
) -> Result<f64, QuadError>
where
    Dom: lightquad::domain::Domain<2> + Clone,
    Dom::Point: std::fmt::Debug,
    P: Fn(&Dom::Point) -> f64,
    S: Fn([f64; 2]) -> Option<Dom::Point> + Copy,
{
    let expected = test.expect(pdf)?;
    let mut failed = 0;
    for seed in 0..seeds {
        failed += usize::from(!expected.test(sample, 1000 + seed)?.passed);
    }
    Ok(failed as f64 / seeds as f64)
}

#[test]
fn chi_square_false_alarms_stay_within_twice_alpha_on_correct_samplers() -> Result<(), QuadError> {
    let seeds = 500;
    for alpha in [0.05, 0.01] {
        let setup = |c: ChiSquare<_>| c.cells([10, 20]).samples(20_000).alpha(alpha);
        let rates = [
            (
                "cosine hemisphere",
                failures(
                    setup(ChiSquare::new(Hemisphere::uniform())),
                    |w: &Vec3| w.z / PI,
                    cosine,
                    seeds,
                )?,
            ),
            (
                "uniform sphere",
                failures(
                    ChiSquare::new(SphericalCap::sphere(Vec3::zeros(), 1.0)?)
                        .cells([10, 20])
                        .samples(20_000)
                        .alpha(alpha),
                    |_: &Vec3| 1.0 / (4.0 * PI),
                    sphere,
                    seeds,
                )?,
            ),
            (
                "unit disk",
                failures(
                    ChiSquare::new(Disk::new(Vec3::zeros(), Vec3::z(), 1.0)?)
                        .cells([10, 20])
                        .samples(20_000)
                        .alpha(alpha),
                    |_: &Vec3| 1.0 / PI,
                    disk,
                    seeds,
                )?,
            ),
            (
                "triangle, a quarter refused",
                failures(
                    ChiSquare::new(Triangle::new(Vec3::zeros(), Vec3::x(), Vec3::y())?)
                        .cells([10, 20])
                        .samples(20_000)
                        .alpha(alpha),
                    |_: &Vec3| 0.75 * 2.0,
                    triangle,
                    seeds,
                )?,
            ),
        ];
        let all = rates.iter().map(|r| r.1).sum::<f64>() / rates.len() as f64;
        println!("alpha {alpha}: false alarms {rates:?}, all {all:.4}");
        for (name, rate) in rates {
            assert!(
                rate <= 2.0 * alpha,
                "{name}: {rate} of {seeds} seeds at alpha {alpha}"
            );
        }
        // Not a test that never fails: over 2000 tests, at least half of
        // alpha (100 expected at 0.05, 20 at 0.01).
        assert!(all >= alpha / 2.0, "{all} at alpha {alpha}");
    }
    Ok(())
}

#[test]
fn chi_square_catches_the_planted_bugs_in_nearly_every_seed() -> Result<(), QuadError> {
    let seeds = 200;
    let test = || {
        ChiSquare::new(Hemisphere::uniform())
            .cells([10, 20])
            .samples(20_000)
    };
    // A failed test is a caught bug.
    let no_cos = failures(test(), |_: &Vec3| 1.0 / PI, cosine, seeds)?;
    let no_jacobian = failures(test(), |w: &Vec3| w.z / PI, cosine_no_jacobian, seeds)?;
    // A subtler density bug, reported: cos^1.1 (normalised) for cos.
    let subtle = failures(
        test(),
        |w: &Vec3| 2.1 / (2.0 * PI) * w.z.powf(1.1),
        cosine,
        seeds,
    )?;
    // The subtle one with 10 times the samples, 40 x 80 cells.
    let subtle_big = failures(
        ChiSquare::new(Hemisphere::uniform()).samples(200_000),
        |w: &Vec3| 2.1 / (2.0 * PI) * w.z.powf(1.1),
        cosine,
        100,
    )?;
    println!(
        "caught in: pdf without cos {no_cos}, sampler without Jacobian {no_jacobian}, cos^1.1 \
         {subtle} (2e4 samples), {subtle_big} (2e5 samples, 100 seeds)"
    );
    assert!(
        no_cos >= 0.99 && no_jacobian >= 0.99 && subtle_big >= 0.99,
        "{no_cos}, {no_jacobian}, {subtle_big}"
    );
    Ok(())
}

/// The sky `1 + w_x` by `samples` cosine-weighted directions, with its
/// standard error (`pi`: the gradient integrates to 0); `pdf` the density
/// the estimator divides by.
fn sky(samples: usize, rng: &mut Pcg64, pdf: fn(&Vec3) -> f64) -> (f64, f64) {
    let xs: Vec<f64> = (0..samples)
        .map(|_| {
            let w = cosine([rng.random(), rng.random()]).unwrap_or_else(Vec3::z);
            (1.0 + w.x) * w.z / pdf(&w)
        })
        .collect();
    let mean = xs.iter().sum::<f64>() / samples as f64;
    let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (samples - 1) as f64;
    (mean, (var / samples as f64).sqrt())
}

/// Over `seeds` seeds of a test of `repeats` draws at `alpha`: the
/// fraction where any check fails on the correct sky estimator, and per
/// check, and the fraction where the planted bias (the pdf without cos) is
/// caught.
fn estimator_rates(
    repeats: usize,
    seeds: u64,
    alpha: f64,
) -> Result<(f64, [f64; 3], f64), QuadError> {
    let kinds = [CheckKind::Mean, CheckKind::Variance, CheckKind::Coverage];
    let (mut any, mut by_kind, mut caught) = (0, [0; 3], 0);
    for seed in 0..seeds {
        let test = EstimatorTest::new(repeats).seed(seed).alpha(alpha);
        let out = test.run(PI, |rng| sky(64, rng, |w| w.z / PI))?;
        any += usize::from(!out.passed);
        for (k, kind) in kinds.iter().enumerate() {
            by_kind[k] += usize::from(out.check(*kind, 0).is_some_and(|c| !c.passed));
        }
        let bad = test.run(PI, |rng| sky(64, rng, |_| 1.0 / PI))?;
        caught += usize::from(!bad.passed);
    }
    let rate = |k: usize| k as f64 / seeds as f64;
    Ok((rate(any), by_kind.map(rate), rate(caught)))
}

#[test]
fn estimator_test_false_alarms_stay_within_twice_alpha_and_it_catches_a_bias()
-> Result<(), QuadError> {
    let alpha = 0.05;
    let level = lightquad::testing::sidak(alpha, 3);
    for repeats in [100, 400] {
        let (any, [mean, variance, coverage], caught) = estimator_rates(repeats, 500, alpha)?;
        println!(
            "estimator test of {repeats} repeats at alpha {alpha}, 500 seeds: false alarms {any} \
             (any check); mean {mean}, variance {variance}, coverage {coverage} (each at level \
             {level:.4}); planted bias caught in {caught}"
        );
        assert!(any <= 2.0 * alpha, "{any}");
        assert!(mean <= 2.0 * level, "{mean}");
        assert!(caught >= 0.99, "{caught}");
        // Not checks that never fail: some false alarms over 500 seeds.
        assert!(any >= alpha / 2.0, "{any}");
        if repeats >= 400 {
            // Each check at its level once the repeats are many.
            assert!(
                variance <= 2.0 * level && coverage <= 2.0 * level,
                "{variance}, {coverage}"
            );
        }
    }
    Ok(())
}

#[test]
fn the_variance_check_flags_error_bars_half_their_size() -> Result<(), QuadError> {
    let test = EstimatorTest::new(400).seed(9);
    let honest = test.run(PI, |rng| sky(64, rng, |w| w.z / PI))?;
    honest.assert_passed();
    let halved = test.run(PI, |rng| {
        let (v, s) = sky(64, rng, |w| w.z / PI);
        (v, s / 2.0)
    })?;
    assert!(!halved.passed);
    let variance = halved
        .check(CheckKind::Variance, 0)
        .ok_or(QuadError::invalid("variance", "none", "a check"))?;
    let coverage = halved
        .check(CheckKind::Coverage, 0)
        .ok_or(QuadError::invalid("coverage", "none", "a check"))?;
    assert!(!variance.passed && !coverage.passed, "{halved}");
    // The mean check does not depend on the error bars.
    assert!(halved.check(CheckKind::Mean, 0).is_some_and(|c| c.passed));
    // A stated variance: one draw of 2u has variance 1/3; stated 1/4 is wrong.
    let one = |rng: &mut Pcg64| 2.0 * rng.random::<f64>();
    EstimatorTest::new(2000)
        .variance(vec![1.0 / 3.0])
        .run(1.0, one)?
        .assert_passed();
    assert!(
        !EstimatorTest::new(2000)
            .variance(vec![0.25])
            .run(1.0, one)?
            .passed
    );
    Ok(())
}

#[test]
fn orders_of_known_rules_and_their_intervals() -> Result<(), QuadError> {
    use lightquad::quadrature::{Rule, Simpson};
    // Monte Carlo: -1/2, the interval covering it.
    let mc = Order::measure(&[16, 64, 256, 1024, 4096], 64, 3, 1.0 / 3.0, |n, rng| {
        (0..n).map(|_| rng.random::<f64>().powi(2)).sum::<f64>() / n as f64
    })?;
    mc.assert_near(-0.5, 0.1);
    assert!(mc.interval[0] < -0.5 && -0.5 < mc.interval[1], "{mc}");
    // Simpson on e^x: -4 (a deterministic rule, one repeat).
    let simpson = Order::measure(&[33, 65, 129, 257], 1, 0, 1f64.exp() - 1.0, |n, rng| {
        Simpson
            .integrate(n, rng, |u: [f64; 1]| u[0].exp())
            .map_or(f64::NAN, |e| e.value)
    })?;
    simpson.assert_near(-4.0, 0.1);
    assert!(simpson.check(-2.0, 0.5).is_err());
    Ok(())
}

/// `result` is an error whose message holds every one of `words`.
fn refused<T: std::fmt::Debug>(result: Result<T, QuadError>, words: &[&str]) {
    match result {
        Ok(v) => panic!("accepted: {v:?}"),
        Err(e) => {
            let m = e.to_string();
            for w in words {
                assert!(m.contains(w), "`{m}` lacks `{w}`");
            }
        }
    }
}

#[test]
fn bad_input_is_an_error_naming_the_point_or_the_setting() -> Result<(), QuadError> {
    let h = || {
        ChiSquare::new(Hemisphere::uniform())
            .cells([4, 8])
            .samples(2000)
    };
    // A density that is NaN, negative or infinite somewhere the cubature looks.
    refused(
        h().run(|_: &Vec3| f64::NAN, cosine, 0),
        &["pdf at a cubature node", "NaN"],
    );
    refused(
        h().run(|w: &Vec3| w.x / PI, cosine, 0),
        &["pdf at a cubature node", "-"],
    );
    refused(
        h().run(
            |w: &Vec3| if w.z > 0.5 { f64::INFINITY } else { 1.0 },
            cosine,
            0,
        ),
        &["pdf", "inf"],
    );
    // Infinite exactly at a point the sampler returns, nowhere else.
    refused(
        h().run(
            |w: &Vec3| if w.z == 1.0 { f64::INFINITY } else { w.z / PI },
            |_| Some(Vec3::z()),
            0,
        ),
        &["pdf at sample 0", "inf"],
    );
    // A sampler returning a point below the horizon, or off the sphere.
    refused(
        h().run(|w: &Vec3| w.z / PI, |_| Some(-Vec3::z()), 0),
        &["sample 0", "a point of the domain"],
    );
    refused(
        h().run(|w: &Vec3| w.z / PI, |_| Some(Vec3::new(0.0, 0.0, 2.0)), 0),
        &["sample 0"],
    );
    refused(
        h().run(
            |w: &Vec3| w.z / PI,
            |_| Some(Vec3::new(f64::NAN, 0.0, 1.0)),
            0,
        ),
        &["sample 0"],
    );
    // Settings.
    refused(
        h().samples(0).run(|w: &Vec3| w.z / PI, cosine, 0),
        &["samples", "0"],
    );
    refused(
        h().cells([0, 5]).run(|w: &Vec3| w.z / PI, cosine, 0),
        &["cells[0]"],
    );
    refused(
        h().cells([1, 1]).run(|w: &Vec3| w.z / PI, cosine, 0),
        &["cells", "1 x 1"],
    );
    refused(
        h().samples(8).run(|w: &Vec3| w.z / PI, cosine, 0),
        &["samples = 8", "at least 2 bins"],
    );
    refused(
        h().alpha(0.0).run(|w: &Vec3| w.z / PI, cosine, 0),
        &["alpha"],
    );
    refused(
        h().alpha(f64::NAN).run(|w: &Vec3| w.z / PI, cosine, 0),
        &["alpha"],
    );
    refused(h().tests(0).run(|w: &Vec3| w.z / PI, cosine, 0), &["tests"]);
    refused(
        h().cubature_tolerance(-1.0)
            .run(|w: &Vec3| w.z / PI, cosine, 0),
        &["cubature_tolerance"],
    );
    // Estimator tests.
    let t = EstimatorTest::new(10);
    refused(EstimatorTest::new(1).run(1.0, |_| 1.0), &["repeats"]);
    refused(EstimatorTest::new(0).run(1.0, |_| 1.0), &["repeats"]);
    refused(t.run(1.0, |_| f64::NAN), &["repeat 0", "value[0]", "NaN"]);
    refused(
        t.run(1.0, |_| [1.0, 2.0]),
        &["repeat 0", "2 channels", "1 channels"],
    );
    refused(
        t.run(1.0, |_| (1.0, -0.1)),
        &["repeat 0", "standard error[0]"],
    );
    refused(t.run(f64::INFINITY, |_| 1.0), &["reference[0]"]);
    refused(
        t.run(Reference::from(1.0).within(f64::NAN), |_| 1.0),
        &["reference accuracy[0]"],
    );
    refused(
        t.clone().variance(vec![1.0, 2.0]).run(1.0, |_| 1.0),
        &["variance", "2 channels"],
    );
    refused(
        t.clone().variance(vec![-1.0]).run(1.0, |_| 1.0),
        &["variance[0]"],
    );
    // Orders.
    refused(Order::fit(&[(1.0, 1.0)]), &["points"]);
    refused(Order::fit(&[(1.0, 0.0), (2.0, 0.0)]), &["points"]);
    refused(
        Order::measure(&[1, 2], 1, 0, 0.0, |_, _| f64::NAN),
        &["budget 1, repeat 0"],
    );
    refused(Order::measure(&[1], 1, 0, 0.0, |_, _| 1.0), &["budgets"]);
    Ok(())
}

#[test]
fn a_constant_estimator_and_exact_values_do_not_divide_by_zero() -> Result<(), QuadError> {
    // Every repeat exactly the reference: t = 0/0 is no bias.
    EstimatorTest::new(10)
        .run(2.0, |_| (2.0, 0.0))?
        .assert_passed();
    // Every repeat the same wrong value: a bias, p = 0, no NaN.
    let off = EstimatorTest::new(10).run(2.0, |_| 3.0)?;
    assert!(!off.passed && off.checks[0].p_value == 0.0, "{off}");
    Ok(())
}

#[test]
fn hostile_settings_and_values_are_errors_or_failures_never_passes() -> Result<(), QuadError> {
    // A reference whose accuracy has another channel count.
    let bad_ref = Reference {
        value: vec![1.0, 2.0],
        accuracy: vec![],
    };
    refused(
        EstimatorTest::new(10).run(bad_ref, |_| [1.0, 2.0]),
        &["reference accuracy", "0 channels"],
    );
    // A suite of absurdly many tests: refused, not wrapped.
    refused(
        EstimatorTest::new(10).tests(usize::MAX).run(1.0, |_| 1.0),
        &["tests"],
    );
    refused(
        ChiSquare::new(Pixel::unit_square())
            .tests(usize::MAX)
            .run(|_: &[f64; 2]| 1.0, Some, 0),
        &["tests"],
    );
    // Šidák at a tiny alpha is not 0: -expm1(ln(1 - a) / m) = a / m to first order.
    let level = lightquad::testing::sidak(1e-17, 2);
    assert!((level - 5e-18).abs() < 1e-30, "{level}");
    // A bias in values near 1e160 is found (their squares overflowed).
    let big = EstimatorTest::new(1000).run(1e160, |r| 2e160 * (0.5 + r.random::<f64>()))?;
    assert!(!big.passed, "{big}");
    let scaled = EstimatorTest::new(1000).run(1.0, |r| 2.0 * (0.5 + r.random::<f64>()))?;
    let (a, b) = (big.checks[0].statistic, scaled.checks[0].statistic);
    assert!((a - b).abs() < 1e-9 * b.abs(), "{a} vs {b}");
    // Values near 1e300 with honest error bars: figures finite.
    let huge = EstimatorTest::new(400).run(1e300, |r| {
        (1e300 * (0.5 + r.random::<f64>()), 1e300 / 12f64.sqrt())
    })?;
    assert!(
        huge.checks
            .iter()
            .all(|c| c.statistic.is_finite() && c.p_value.is_finite()),
        "{huge}"
    );
    // An order through an error that overflowed, or an exact 0: an error, not a silent drop.
    refused(
        Order::measure(&[16, 64, 256, 1024], 1, 0, 0.0, |n, _| {
            if n == 1024 {
                1e200 * 1e200
            } else {
                1.0 / n as f64
            }
        }),
        &["budget 1024"],
    );
    refused(
        Order::fit(&[(1.0, 1.0), (2.0, 0.5), (4.0, 0.0), (8.0, 0.125)]),
        &["points[2]"],
    );
    // Samples where the density is 0 fail the test.
    let pdf = |p: &[f64; 2]| if p[0] < 0.75 { 4.0 / 3.0 } else { 0.0 };
    let split = |u: [f64; 2]| {
        Some(if u[0] < 2.0 / 3.0 {
            [u[0] * 0.75, u[1]]
        } else {
            [0.75 + 0.75 * (u[0] - 2.0 / 3.0), u[1]]
        })
    };
    let out = ChiSquare::new(Pixel::unit_square())
        .cells([2, 1])
        .samples(100_000)
        .run(pdf, split, 0)?;
    assert!(!out.passed && out.zero_density > 30_000, "{out}");
    assert!(out.to_string().contains("where the pdf is 0"), "{out}");
    // Pooled counts are not shown as a cell's.
    let none = ChiSquare::new(Pixel::unit_square())
        .cells([4, 4])
        .samples(10_000)
        .run(|_: &[f64; 2]| 1.0, |_| None, 0)?;
    assert!(!none.passed);
    assert!(
        none.worst
            .iter()
            .all(|c| c.index.is_none() || c.observed == 0.0),
        "{none}"
    );
    // A density integrating to 0 or to infinity: named as the pdf.
    refused(
        ChiSquare::new(Pixel::unit_square())
            .cells([4, 4])
            .samples(10_000)
            .run(|_: &[f64; 2]| 0.0, Some, 0),
        &["pdf", "not 0"],
    );
    refused(
        ChiSquare::new(Pixel::unit_square())
            .cells([4, 4])
            .samples(10_000)
            .run(|_: &[f64; 2]| 1e308, Some, 0),
        &["pdf", "finite"],
    );
    // Cubature work beyond the limit.
    refused(
        ChiSquare::new(Pixel::unit_square())
            .cells([1 << 20, 4])
            .cubature_boxes(64)
            .run(|_: &[f64; 2]| 1.0, Some, 0),
        &["cubature_boxes"],
    );
    Ok(())
}
