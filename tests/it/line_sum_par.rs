//! `line_sum_par`, the shared sum on one axis with its spans on rayon's
//! threads, against closed forms (Gauss–Legendre on `cos(50 u)`, the
//! trapezoid rule and its coarser companions on `u^2`), and its promises:
//! the same bits whatever the number of threads, the same bits as
//! `product_sum` up to one span, and the error `product_sum` gives
//! (for a non-finite value, and for finite values whose sum leaves the f64
//! range).

use lightquad::error::QuadError;
use lightquad::quadrature::gauss_legendre::unit_nodes;
use lightquad::quadrature::nodes::{
    PAR_SPAN, ProductSum, line_sum_par, line_value_par, par_span, product_sum, product_value,
};
use lightquad::quadrature::product::WithError;
use lightquad::quadrature::{GaussLegendre, Rule, simpson, trapezoid};
use lightquad::value::{Rgb, Value};
use rand::SeedableRng;

/// `int_0^1 cos(50 u) du = sin(50)/50` as `HI + LO` (half of
/// `sin(50)/25 = -0.010494994148157151436575745876504901835...`, from the
/// Taylor series of `sin` in 60-digit decimal arithmetic).
const EXACT_HI: f64 = -0.010494994148157152 / 2.0;
const EXACT_LO: f64 = 5.858512174793785e-19 / 2.0;

fn in_pool<T: Send>(threads: usize, job: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool")
        .install(job)
}

fn bits(s: &ProductSum<f64>) -> [u64; 4] {
    [
        s.value.to_bits(),
        s.magnitude.to_bits(),
        s.largest.to_bits(),
        s.evaluations,
    ]
}

#[test]
fn a_million_gauss_nodes_on_cos_50u_are_compensated_to_the_nodes_own_rounding() {
    let nodes = unit_nodes(1_000_000).expect("nodes");
    let sum = line_sum_par(&nodes, |u| Ok((50.0 * u).cos())).expect("sum");
    let error = ((sum.value - EXACT_HI) - EXACT_LO).abs();
    // What is left is the nodes' own rounding (half an ulp of each u_i
    // moves its term by up to 50 w_i 2^-54 u_i, with signs that mostly
    // cancel): 3.2e-18 measured. A plain sum of the same terms is off by
    // 8.8e-16.
    assert!(error < 2e-17, "error {error:e}");
    assert_eq!(sum.evaluations, 1_000_000);
    // sum |w cos(50 u)| is Gauss-Legendre on |cos(50 u)|, whose integral
    // is (32 + sin 50)/50: on [0, 50], 1 up to pi/2, 2 for each of fifteen
    // whole half-periods to 31 pi/2, then 1 + sin 50 (sin 50 < 0); its
    // kinks cost accuracy, not 1e-8. The largest term is at most the
    // largest weight, below pi/(2 n) (the weights' asymptote).
    let magnitude = (32.0 + 50f64.sin()) / 50.0;
    assert!(
        (sum.magnitude - magnitude).abs() < 1e-8,
        "{:e}",
        sum.magnitude - magnitude
    );
    assert!(sum.largest > 0.0 && sum.largest < std::f64::consts::PI / 2e6);
}

#[test]
fn the_trapezoid_rule_and_its_companions_on_u_squared_match_euler_maclaurin() {
    // m = 8 * 2^15 + 1 points, h = 2^-18: 16 spans. For u^2 the
    // trapezoid rule's error is exactly h^2 (f'(1) - f'(0)) / 12 = h^2 / 6;
    // the 2h, 4h and 8h companions the same with their own steps.
    let m = 8 * (1 << 15) + 1;
    let nodes = trapezoid::unit_nodes(m).expect("nodes");
    assert!(nodes.len() > 8 * PAR_SPAN);
    let sum = in_pool(2, || line_sum_par(&nodes, |u| Ok(u * u))).expect("sum");
    let h = 2f64.powi(-18);
    let exact = |step: f64| 1.0 / 3.0 + step * step / 6.0;
    let close = |v: f64, step: f64| (v - exact(step)).abs() <= 2.0 * f64::EPSILON / 3.0;
    assert!(close(sum.value, h), "{:e}", sum.value - exact(h));
    assert!(close(sum.companion.expect("2h"), 2.0 * h));
    assert!(close(sum.companion4.expect("4h"), 4.0 * h));
    assert!(close(sum.companion8.expect("8h"), 8.0 * h));
}

/// Spans of 4096 (74 of them) and of 8192 (`par_span`, 74 again), cut into
/// runs of 1, 2, 3 and 7 workers (3 and 7 do not divide 74: runs of
/// unequal length).
#[test]
fn the_bits_do_not_depend_on_the_number_of_threads() {
    for (n, span) in [(300_001, PAR_SPAN), (600_001, 2 * PAR_SPAN)] {
        assert_eq!(par_span(n), span);
        let nodes = unit_nodes(n).expect("nodes");
        let f = |u: f64| Ok((50.0 * u).cos() * (1.0 + u).ln());
        let one = in_pool(1, || line_sum_par(&nodes, f)).expect("sum");
        for threads in [2, 3, 7] {
            let many = in_pool(threads, || line_sum_par(&nodes, f)).expect("sum");
            assert_eq!(bits(&one), bits(&many), "n = {n}, {threads} threads");
        }
    }
}

/// The bits of every field, the companions' included.
fn all_bits(s: &ProductSum<f64>) -> Vec<u64> {
    let companions = [s.companion, s.companion4, s.companion8];
    let mut all = bits(s).to_vec();
    all.extend(companions.iter().map(|c| c.map_or(u64::MAX, f64::to_bits)));
    all
}

#[test]
fn up_to_one_span_the_bits_are_product_sums() {
    let f = |u: f64| Ok((7.0 * u).sin() - u);
    // Around the few-node sums (16 and 128 nodes), a block of 256 nodes,
    // and the most one span holds.
    for n in [
        1, 15, 16, 17, 20, 63, 64, 100, 127, 128, 255, 256, 257, 1000, PAR_SPAN,
    ] {
        let gauss = unit_nodes(n).expect("nodes");
        // The trapezoid rule takes an odd number of points, at least 3.
        let trapezoid = trapezoid::unit_nodes((n - 1 + n % 2).max(3)).expect("nodes");
        for nodes in [gauss, trapezoid.into()] {
            let par = line_sum_par(&nodes, f).expect("sum");
            let serial = product_sum([nodes.as_ref()], |p: [f64; 1]| f(p[0])).expect("sum");
            assert_eq!(all_bits(&par), all_bits(&serial), "n = {n}");
        }
    }
}

/// Every field of channel `c` of `s`, as bits (the companions' included).
fn channel_bits<V: Value>(s: &ProductSum<V>, c: usize) -> Vec<u64> {
    let companions = [s.companion, s.companion4, s.companion8];
    let mut all = vec![
        s.value.channel(c).to_bits(),
        s.magnitude.channel(c).to_bits(),
        s.largest.channel(c).to_bits(),
        s.evaluations,
    ];
    all.extend(
        companions
            .iter()
            .map(|v| v.map_or(u64::MAX, |v| v.channel(c).to_bits())),
    );
    all
}

#[test]
fn a_value_of_three_or_six_channels_is_summed_as_its_channels_alone() {
    // Every channel of a value is summed by the same operations as a
    // scalar: the same bits as line_sum_par of that channel on its own,
    // for every field, across 9 spans, with and without companions; and
    // within rounding of the serial sum, which stores no spans.
    let channel = |u: f64, c: usize| match c {
        0 => u * u,
        1 => (50.0 * u).cos(),
        2 => -(3.0 * u).exp(),
        3 => 1.0 / (1.0 + u),
        4 => (1e3 * u).sin() * 1e-9,
        _ => -u,
    };
    let gauss = unit_nodes(8 * PAR_SPAN + 77).expect("nodes");
    let trapezoid = trapezoid::unit_nodes(8 * PAR_SPAN + 1).expect("nodes");
    for nodes in [gauss, trapezoid.into()] {
        let rgb = |u: f64| Rgb::new(channel(u, 0), channel(u, 1), channel(u, 2));
        let three = in_pool(2, || line_sum_par(&nodes, |u| Ok(rgb(u)))).expect("sum");
        let six = in_pool(3, || {
            line_sum_par(&nodes, |u| {
                Ok(WithError {
                    value: rgb(u),
                    error: Rgb::new(channel(u, 3), channel(u, 4), channel(u, 5)),
                })
            })
        })
        .expect("sum");
        for c in 0..6 {
            let alone = line_sum_par(&nodes, |u| Ok(channel(u, c))).expect("sum");
            assert_eq!(
                channel_bits(&six, c),
                channel_bits(&alone, 0),
                "channel {c} of 6"
            );
            if c < 3 {
                assert_eq!(
                    channel_bits(&three, c),
                    channel_bits(&alone, 0),
                    "channel {c} of 3"
                );
            }
        }
        // Against the serial sum, which keeps no spans: the same largest
        // term, and every sum within rounding of its (the spans' lanes
        // restart, so the last bits may differ).
        let serial = product_sum([nodes.as_ref()], |p: [f64; 1]| {
            let u = p[0];
            Ok(WithError {
                value: rgb(u),
                error: Rgb::new(channel(u, 3), channel(u, 4), channel(u, 5)),
            })
        })
        .expect("sum");
        let near = |a: f64, b: f64, scale: f64| (a - b).abs() <= 1e-14 * scale;
        for c in 0..6 {
            let scale = serial.magnitude.channel(c);
            assert_eq!(
                six.largest.channel(c),
                serial.largest.channel(c),
                "channel {c}"
            );
            assert!(near(six.magnitude.channel(c), scale, scale), "channel {c}");
            for (par, ser) in [
                (Some(six.value), Some(serial.value)),
                (six.companion, serial.companion),
                (six.companion4, serial.companion4),
                (six.companion8, serial.companion8),
            ] {
                assert_eq!(par.is_some(), ser.is_some());
                if let (Some(par), Some(ser)) = (par, ser) {
                    assert!(near(par.channel(c), ser.channel(c), scale), "channel {c}");
                }
            }
        }
        // And the value against its closed form: int_0^1 u^2 du = 1/3.
        assert!(
            (three.value.x - 1.0 / 3.0).abs() < 1e-9,
            "{:e}",
            three.value.x
        );
    }
}

#[test]
fn the_largest_term_and_the_magnitude_are_those_of_every_span() {
    // 100_000 Gauss nodes, several spans, on exp(-20 u): the largest
    // term w_i e^{-20 u_i} lies near u = 1/40 (node 1e4 or so), in an
    // early span, far from the last.
    let nodes = unit_nodes(100_000).expect("nodes");
    let f = |u: f64| (-20.0 * u).exp();
    let sum = in_pool(2, || line_sum_par(&nodes, |u| Ok(f(u)))).expect("sum");
    let terms = nodes.u.iter().zip(&nodes.w).map(|(&u, w)| w * f(u));
    let (index, largest) =
        terms.clone().enumerate().fold(
            (0, 0.0),
            |(i, m), (j, t)| if t > m { (j, t) } else { (i, m) },
        );
    assert!(
        index + 4 * PAR_SPAN < nodes.len(),
        "the largest term is at node {index}"
    );
    assert_eq!(sum.largest, largest);
    // sum |w f| = sum w f here, int_0^1 e^{-20 u} du = (1 - e^-20)/20.
    let exact = -(-20f64).exp_m1() / 20.0;
    assert!((sum.magnitude - exact).abs() < 1e-14 * exact);
    assert!((sum.value - exact).abs() < 4.0 * f64::EPSILON * exact);
    let plain: f64 = lightquad::sum::sum_f64(terms);
    assert!((sum.magnitude - plain).abs() < 1e-14 * exact);
}

#[test]
fn a_panic_after_an_earlier_failure_gives_the_failure_and_before_it_the_panic() {
    let nodes = unit_nodes(200_000).expect("nodes");
    // A NaN in span 1, a panic from span 3 on: the serial sum stops at
    // the NaN and never reaches the panic, whichever spans ran at once.
    let nan_at = nodes.u[PAR_SPAN + 5];
    let panic_from = nodes.u[3 * PAR_SPAN];
    let f = |u: f64| {
        if u >= panic_from {
            panic!("integrand panicked at {u}");
        }
        Ok(if u == nan_at { f64::NAN } else { u })
    };
    for threads in [1, 2, 4] {
        match in_pool(threads, || line_sum_par(&nodes, f)) {
            Err(QuadError::NonFiniteIntegrand { point, .. }) => {
                assert_eq!(point, vec![nan_at], "{threads} threads")
            }
            other => panic!("{threads} threads: expected the NaN, got {other:?}"),
        }
    }
    // With the panic first and the NaN after it, the panic is what the
    // caller sees.
    let g = |u: f64| {
        if u == nodes.u[PAR_SPAN + 5] {
            panic!("integrand panicked at {u}");
        }
        Ok(if u >= panic_from { f64::NAN } else { u })
    };
    for threads in [1, 2, 4] {
        let caught = std::panic::catch_unwind(|| in_pool(threads, || line_sum_par(&nodes, g)));
        let payload = caught.expect_err("the panic reaches the caller");
        let message = payload
            .downcast_ref::<String>()
            .expect("a formatted message");
        assert!(message.starts_with("integrand panicked at"), "{message}");
    }
}

/// A value of no channels, which `Value` allows.
#[derive(Clone, Copy, Debug)]
struct Nothing;

impl Value for Nothing {
    const CHANNELS: usize = 0;
    fn zero() -> Self {
        Nothing
    }
    fn channel(&self, i: usize) -> f64 {
        unreachable!("channel {i} of a value of none")
    }
    fn from_fn(_: impl FnMut(usize) -> f64) -> Self {
        Nothing
    }
    fn map(self, _: impl Fn(f64) -> f64) -> Self {
        Nothing
    }
    fn zip(self, _: Self, _: impl Fn(f64, f64) -> f64) -> Self {
        Nothing
    }
    fn all_finite(&self) -> bool {
        true
    }
}

#[test]
fn a_value_of_no_channels_is_evaluated_at_every_node() {
    // Across several spans, as product_sum: every node evaluated once, and
    // the integrand's error at the first node that gives one.
    let nodes = unit_nodes(3 * PAR_SPAN + 5).expect("nodes");
    let calls = std::sync::atomic::AtomicUsize::new(0);
    let sum = line_sum_par(&nodes, |_| {
        calls.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        Ok(Nothing)
    })
    .expect("sum");
    assert_eq!(sum.evaluations as usize, nodes.len());
    assert_eq!(calls.into_inner(), nodes.len());
    let bad = nodes.u[2 * PAR_SPAN + 1];
    let failed = line_sum_par(&nodes, |u| {
        if u >= bad {
            Err(QuadError::invalid("integrand", u, "below the bad node"))
        } else {
            Ok(Nothing)
        }
    });
    let serial = product_sum([nodes.as_ref()], |p: [f64; 1]| {
        if p[0] >= bad {
            Err(QuadError::invalid("integrand", p[0], "below the bad node"))
        } else {
            Ok(Nothing)
        }
    });
    assert_eq!(format!("{failed:?}"), format!("{serial:?}"));
    assert!(failed.is_err());
}

/// A panic payload whose own `Drop` panics, counting its drops.
struct Bomb;

static BOMBS_DROPPED: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

impl Drop for Bomb {
    fn drop(&mut self) {
        BOMBS_DROPPED.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
        panic!("a panic payload's own drop panicked");
    }
}

#[test]
fn a_later_panic_whose_payload_panics_when_dropped_does_not_escape_the_error() {
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::time::{Duration, Instant};
    // 49 spans. A NaN at the last node of span 0, which waits there until
    // a span of the second half, on the other thread, has panicked with a
    // `Bomb`: the caller gets the NaN, and the bombs are dropped without
    // their panics escaping.
    let nodes = unit_nodes(200_000).expect("nodes");
    let nan_at = nodes.u[PAR_SPAN - 1];
    let bombs_from = nodes.u[nodes.len() / 2];
    let thrown = AtomicUsize::new(0);
    let f = |u: f64| {
        if u >= bombs_from {
            thrown.fetch_add(1, Ordering::SeqCst);
            std::panic::panic_any(Bomb);
        }
        if u == nan_at {
            let start = Instant::now();
            while thrown.load(Ordering::SeqCst) == 0 && start.elapsed() < Duration::from_secs(20) {
                std::thread::yield_now();
            }
            return Ok(f64::NAN);
        }
        Ok(u)
    };
    let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        in_pool(2, || line_sum_par(&nodes, f))
    }));
    match outcome {
        Ok(Err(QuadError::NonFiniteIntegrand { point, .. })) => assert_eq!(point, vec![nan_at]),
        Ok(other) => panic!("expected the NaN, got {other:?}"),
        Err(_) => panic!("a panic escaped line_sum_par, which had an error to return"),
    }
    let thrown_first = thrown.swap(0, Ordering::SeqCst);
    assert!(thrown_first >= 1, "no span of the second half ran");
    // The same with a panic in place of the NaN: that panic reaches the
    // caller (had a bomb been dropped as it unwound, the process would
    // have aborted).
    let g = |u: f64| {
        if u == nan_at {
            let _ = f(u);
            panic!("integrand panicked at {u}");
        }
        f(u)
    };
    let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        in_pool(2, || line_sum_par(&nodes, g))
    }));
    let payload = outcome.expect_err("the panic reaches the caller");
    let message = payload
        .downcast_ref::<String>()
        .expect("a formatted message");
    assert!(message.starts_with("integrand panicked at"), "{message}");
    let thrown_second = thrown.load(Ordering::SeqCst);
    assert!(thrown_second >= 1, "no span of the second half ran");
    assert_eq!(
        BOMBS_DROPPED.load(Ordering::SeqCst),
        thrown_first + thrown_second,
        "every bomb dropped once"
    );
}

#[test]
fn a_nan_in_a_late_span_is_reported_at_the_first_node_where_it_occurs() {
    let nodes = unit_nodes(200_000).expect("nodes");
    // NaN from u > 0.7 on (span 8 or so of 13), an error returned by the
    // integrand from u > 0.9: the NaN, at the first node past 0.7, is what
    // a serial sum meets first.
    let first = *nodes.u.iter().find(|&&u| u > 0.7).expect("a node past 0.7");
    let f = |u: f64| {
        if u > 0.9 {
            Err(QuadError::invalid("u", u, "at most 0.9"))
        } else if u > 0.7 {
            Ok(f64::NAN)
        } else {
            Ok(u)
        }
    };
    for threads in [1, 2, 4] {
        match in_pool(threads, || line_sum_par(&nodes, f)) {
            Err(QuadError::NonFiniteIntegrand { point, value }) => {
                assert_eq!(point, vec![first], "{threads} threads");
                assert_eq!(value, "NaN");
            }
            other => panic!("{threads} threads: expected the NaN at {first}, got {other:?}"),
        }
    }
    // The integrand's own error, where it comes first.
    let g = |u: f64| {
        if u > 0.5 {
            Err(QuadError::invalid("u", u, "at most 0.5"))
        } else {
            Ok(u)
        }
    };
    let serial = product_sum([nodes.as_ref()], |p: [f64; 1]| g(p[0]));
    let par = in_pool(2, || line_sum_par(&nodes, g));
    assert_eq!(
        format!("{:?}", par.expect_err("an error")),
        format!("{:?}", serial.expect_err("an error"))
    );
}

/// `int_0^1 f64::MAX du = f64::MAX`, representable, but the sum of `w_i
/// f64::MAX` passes it on the way (the weights sum to 1 only to within
/// rounding): 1e5 Gauss nodes summed to NaN and came back `Ok(NaN)`. Now
/// the lanes' total finds it, serial and parallel, with the companions of a
/// composite rule, and `sum |w f|` stays finite; where a sum does leave the
/// range (the odometer's single running sum in two dimensions, a composite
/// rule's `4h` companion, all in one lane) it is an error naming it; and a
/// rule's `try_integrate` finds the integral.
#[test]
fn sums_of_values_near_f64_max_are_found_or_an_error_never_a_nan() {
    let near_max = |v: f64| (f64::MAX * (1.0 - 1e-12)..=f64::MAX).contains(&v);
    let found = |r: Result<ProductSum<f64>, QuadError>, what: &str| {
        let s = r.unwrap_or_else(|e| panic!("{what}: {e}"));
        assert!(near_max(s.value), "{what}: {:e}", s.value);
        assert!(near_max(s.magnitude), "{what}: {:e}", s.magnitude);
        for c in [s.companion, s.companion4, s.companion8]
            .into_iter()
            .flatten()
        {
            assert!(near_max(c), "{what}: companion {c:e}");
        }
    };
    for n in (1..=17).chain([50, 127, 128, 1000, 100_000, 1_000_000]) {
        let nodes = unit_nodes(n).expect("nodes");
        found(
            product_sum([nodes.as_ref()], |_: [f64; 1]| Ok(f64::MAX)),
            &format!("{n} nodes"),
        );
        for threads in [1, 2] {
            found(
                in_pool(threads, || line_sum_par(&nodes, |_| Ok(f64::MAX))),
                &format!("{n} nodes, {threads} threads"),
            );
        }
    }
    let composite = trapezoid::unit_nodes(8 * (1 << 15) + 1).expect("nodes");
    found(
        in_pool(2, || line_sum_par(&composite, |_| Ok(f64::MAX))),
        "trapezoid",
    );
    // The trapezoid rule's own sum on one axis is always found; its `4h`
    // and `8h` companions put every term in one lane, whose running sum can
    // pass `f64::MAX`: found, or an error that names that companion.
    for m in [1001, 100_001, 1_000_001] {
        let composite = trapezoid::unit_nodes(m).expect("nodes");
        let serial = product_sum([&composite], |_: [f64; 1]| Ok(f64::MAX));
        for (sum, what) in [
            (serial, "serial"),
            (line_sum_par(&composite, |_| Ok(f64::MAX)), "parallel"),
        ] {
            let what = format!("trapezoid, {m} nodes, {what}");
            match sum {
                Ok(s) => found(Ok(s), &what),
                Err(QuadError::SumOutOfRange { sum, value, .. }) => {
                    assert!(["companion4", "companion8"].contains(&sum), "{what}: {sum}");
                    assert_eq!(value, "inf", "{what}");
                }
                Err(e) => panic!("{what}: {e}"),
            }
        }
    }
    let few = unit_nodes(1000).expect("nodes");
    match product_sum([few.as_ref(), few.as_ref()], |_: [f64; 2]| Ok(f64::MAX)) {
        Err(e @ QuadError::SumOutOfRange { sum: "value", .. }) => {
            assert!(e.to_string().contains("(`value`) overflows f64"), "{e}")
        }
        other => panic!("1000 x 1000 nodes: expected SumOutOfRange, got {other:?}"),
    }
    let mut rng = rand_pcg::Pcg64::seed_from_u64(1);
    let e = GaussLegendre::default()
        .try_integrate(100_000, &mut rng, |_: [f64; 1]| Ok(f64::MAX))
        .expect("a rule scales the integrand");
    assert!(near_max(e.value), "{:e}", e.value);
}

/// A value with its error estimate whose error is infinite at some nodes
/// (an inner rule with no estimate): the summed error is `+inf`, on one
/// thread and on several, serial or in spans, and the value is the
/// closed form `int_0^1 cos(50 u) du = sin(50)/50`. (TwoSum's carry of an
/// infinite term is NaN; the error channel was NaN.)
#[test]
fn an_infinite_error_at_some_nodes_sums_to_an_infinite_error() {
    let nodes = unit_nodes(3 * PAR_SPAN + 5).expect("nodes");
    let exact = EXACT_HI + EXACT_LO;
    let f = |u: f64| {
        Ok(WithError {
            value: (50.0 * u).cos(),
            error: if u > 0.7 { f64::INFINITY } else { 1e-3 },
        })
    };
    for sum in [
        product_sum([&nodes], |[u]| f(u)).expect("serial"),
        in_pool(1, || line_sum_par(&nodes, f)).expect("one thread"),
        in_pool(3, || line_sum_par(&nodes, f)).expect("three threads"),
    ] {
        assert!(
            (sum.value.value - exact).abs() < 1e-17,
            "{:e}",
            sum.value.value
        );
        assert_eq!(sum.value.error, f64::INFINITY);
    }
}

/// `line_value_par`, the value alone across threads: `line_sum_par`'s
/// value bit for bit on one to four threads, below, at and above one span
/// (the closed form `sin(50)/50` bounds that sum); the same error for a
/// NaN in a late span, for finite values near `f64::MAX` (found, as the
/// whole sum finds them) and for an infinite error beside finite values
/// (summed, not taken again: `WithError` reads the value).
#[test]
fn the_value_alone_is_the_whole_sums_bit_for_bit_with_its_errors() {
    for n in [5, 200, PAR_SPAN, PAR_SPAN + 1, 3 * PAR_SPAN + 5, 200_000] {
        let nodes = unit_nodes(n).expect("nodes");
        let f = |u: f64| Ok((50.0 * u).cos());
        let whole = line_sum_par(&nodes, f).expect("finite");
        for threads in [1, 2, 4] {
            let value = in_pool(threads, || line_value_par(&nodes, f)).expect("finite");
            assert_eq!(
                value.to_bits(),
                whole.value.to_bits(),
                "{n} nodes, {threads} threads"
            );
        }
        // Converged from 200 nodes: within the nodes' own rounding, `|f'|
        // = 50` times some `6 u` of node error, and the sum's `4 u`.
        let u = f64::EPSILON / 2.0;
        if n >= 200 {
            let error = (whole.value - EXACT_HI - EXACT_LO).abs();
            assert!(error < 50.0 * 6.0 * u + 4.0 * u, "{n}: error {error:e}");
        }
        let near_max = in_pool(2, || line_value_par(&nodes, |_| Ok(f64::MAX)));
        let expected = line_sum_par(&nodes, |_| Ok(f64::MAX)).map(|s| s.value);
        assert_eq!(near_max, expected, "{n} nodes, f64::MAX");
        let infinite_error = |u: f64| {
            Ok(WithError {
                value: u,
                error: f64::INFINITY,
            })
        };
        let calls = std::sync::atomic::AtomicUsize::new(0);
        let counted = |u: f64| {
            calls.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            infinite_error(u)
        };
        let value = in_pool(2, || line_value_par(&nodes, counted)).expect("finite value");
        let whole = line_sum_par(&nodes, infinite_error)
            .expect("finite value")
            .value;
        assert_eq!(value.value.to_bits(), whole.value.to_bits(), "{n} nodes");
        assert_eq!(calls.into_inner(), n, "{n} nodes: every node once");
    }
    // `f64::MAX` on composite nodes, whose coarser companions hold every
    // term in one lane: the value as `product_value` finds it, never a
    // companion's error.
    for m in (129..=4097).step_by(2).chain([100_001]) {
        for (rule, nodes) in [
            ("trapezoid", trapezoid::unit_nodes(m).expect("nodes")),
            ("simpson", simpson::unit_nodes(m).expect("nodes")),
        ] {
            let par = in_pool(2, || line_value_par(&nodes, |_| Ok(f64::MAX)));
            let serial = product_value([&nodes], |_: [f64; 1]| Ok(f64::MAX));
            match (&par, &serial) {
                (Ok(p), Ok(s)) if m <= PAR_SPAN => assert_eq!(p, s, "{rule}, {m} nodes"),
                (Ok(p), Ok(_)) => assert!(*p >= f64::MAX * (1.0 - 1e-12), "{rule}, {m}: {p:e}"),
                (Err(p), Err(s)) => {
                    assert_eq!(p, s, "{rule}, {m} nodes");
                    assert!(
                        matches!(p, QuadError::SumOutOfRange { sum: "value", .. }),
                        "{rule}, {m} nodes: {p}"
                    );
                }
                _ => panic!("{rule}, {m} nodes: {par:?} against {serial:?}"),
            }
        }
    }
    let nodes = unit_nodes(200_000).expect("nodes");
    let first = *nodes.u.iter().find(|&&u| u > 0.7).expect("a node past 0.7");
    let nan_late = |u: f64| Ok(if u > 0.7 { f64::NAN } else { u });
    for threads in [1, 2] {
        match in_pool(threads, || line_value_par(&nodes, nan_late)) {
            Err(QuadError::NonFiniteIntegrand { point, .. }) => {
                assert_eq!(point, vec![first], "{threads} threads")
            }
            other => panic!("{threads} threads: expected the NaN at {first}, got {other:?}"),
        }
    }
}
