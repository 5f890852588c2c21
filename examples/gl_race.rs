//! Gauss–Legendre integration at n = 1e6 with cached nodes, lightquad
//! against `bilby` and `gauss-quad`, timed in interleaved rounds.
//!
//! `cargo run --release --example gl_race -- [ROUNDS] [--serial | --parallel] [--n N] [--calls C]`
//! (in any order; ROUNDS default 41; `--serial` leaves out the three
//! parallel contenders, `--parallel` times them alone; N nodes, default
//! 1e6, 1 to 1e7; C calls a timing, default 1, so that a few-node call,
//! some 50 ns, is timed in batches well above the clock's resolution)
//!
//! `lightquad rule` is the same integral through [`Rule::integrate`] with
//! the error estimate off (as the peers have none), what a user calls;
//! `lightquad` is the sum alone (`product_sum`), `lightquad fixed` the
//! rule prepared once ([`FixedOrder`]), as the peers' are, and `lightquad
//! fixed par` its nodes shared among the threads
//! ([`FixedOrder::par_integrate`]); `lightquad par` is `line_sum_par`, the
//! whole sum (with what an error estimate reads). Up to 100 nodes
//! `lightquad estimate` times the rule with its estimate on too.
//!
//! The same integral as `cargo bench --bench quadrature -- gl_integrate`:
//! `int_{-1}^{1} cos(50 x) dx`. On a shared machine whose speed drifts
//! from one second to the next, criterion's groups, timed one after
//! another, can differ by more than the few percent between these
//! integrators. Here every round times each contender once, in an order
//! rotated from round to round and reversed every other round (so no
//! contender always follows the same one, whose traces in the caches it
//! would inherit), and the figures compared are medians over rounds of
//! each round's ratio of two contenders' times: a slow stretch of the
//! machine slows both sides of a ratio alike.
//!
//! Two settings: the interval's bounds through `black_box` (a run-time
//! interval, the usual case) and, marked `const`, compile-time constants,
//! where bilby's inlined map `x = (b - a)/2 t + (a + b)/2` folds to `t + 0`
//! (gauss-quad's `0.5 ((b - a) t + (b + a))` only to `0.5 (2 t + 0)`).
//!
//! Prints a table: the median and the least time of each contender and the
//! error of its value against `sin(50)/25` (to about 32 digits, as a pair
//! of `f64`s: one `f64` is 1.7e-18 off), then the paired ratios (median,
//! a 95% interval of the median, and quartiles). `plain loop` is the peers' loop
//! (`s += w f(x)`) on lightquad's own nodes: lightquad's time over it is
//! what the compensated sum, `sum |w f|`, the largest term and the finite
//! checks cost.

use std::hint::black_box;
use std::num::NonZeroUsize;
use std::time::Instant;

use lightquad::quadrature::gauss_legendre::{FixedOrder, TABLE_MAX_ORDER, unit_nodes};
use lightquad::quadrature::nodes::{line_sum_par, product_sum};
use lightquad::quadrature::{GaussLegendre, Rule};
use rand::SeedableRng;

/// Nodes unless `--n` says otherwise.
const N: usize = 1_000_000;

/// Most nodes `--n` takes.
const MAX_N: usize = 10_000_000;

/// Most rounds (some 90 ms each).
const MAX_ROUNDS: usize = 10_000;

/// Most calls a timing.
const MAX_CALLS: usize = 10_000_000;

/// `int_{-1}^{1} cos(50 x) dx = sin(50)/25` as `HI + LO`, from the Taylor
/// series of `sin` in 60-digit decimal arithmetic (Python's `decimal`):
/// `-0.010494994148157151436575745876504901835...`.
const EXACT_HI: f64 = -0.010494994148157152;
const EXACT_LO: f64 = 5.858512174793785e-19;

fn integrand(x: f64) -> f64 {
    (50.0 * x).cos()
}

/// The element of rank `round((len - 1) q)` of `v` (sorted in place): the
/// median for `q = 0.5` and an odd length.
fn quantile(v: &mut [f64], q: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * q).round() as usize]
}

/// A 95% confidence interval of the median of `v` (sorted in place) that
/// assumes nothing of the distribution: the order statistics of 1-based
/// ranks `floor(n/2 - 1.96 sqrt(n)/2)` and `ceil(1 + n/2 + 1.96 sqrt(n)/2)`
/// (Conover, *Practical Nonparametric Statistics*: the normal approximation
/// to the binomial count of samples below the median; rounds taken as
/// independent). None below 6 rounds, where even the least and the
/// largest value bracket the median with probability under 0.95.
fn median_interval(v: &mut [f64]) -> Option<(f64, f64)> {
    if v.len() < 6 {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len() as f64;
    let half = 1.96 * n.sqrt() / 2.0;
    let low = ((n / 2.0 - half).floor() as usize).max(1);
    let high = ((1.0 + n / 2.0 + half).ceil() as usize).min(v.len());
    Some((v[low - 1], v[high - 1]))
}

/// A time in milliseconds, written in ms or, below 0.01 ms, in ns.
fn duration(ms: f64) -> String {
    if ms >= 0.01 {
        format!("{ms:.3} ms")
    } else {
        format!("{:.1} ns", ms * 1e6)
    }
}

type Contender<'a> = (&'static str, Box<dyn FnMut() -> f64 + 'a>);

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // `[ROUNDS] [--serial | --parallel]`, in either order. `--serial`:
    // without the two that use every core, whose idle rayon threads spin a
    // while after each call and take a core from whatever is timed next on
    // a two-core machine; `--parallel`: those two alone.
    let (mut rounds, mut only, mut n): (Option<usize>, Option<bool>, Option<usize>) =
        (None, None, None);
    let mut calls: Option<usize> = None;
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--serial" | "--parallel" if only.is_none() => only = Some(arg == "--parallel"),
            "--n" if n.is_none() => {
                let value = args
                    .next()
                    .ok_or("--n: expected a number of nodes after it")?;
                n = Some(value.parse().map_err(|e| format!("--n {value:?}: {e}"))?)
            }
            "--calls" if calls.is_none() => {
                let value = args
                    .next()
                    .ok_or("--calls: expected a number of calls after it")?;
                calls = Some(
                    value
                        .parse()
                        .map_err(|e| format!("--calls {value:?}: {e}"))?,
                )
            }
            _ if rounds.is_none() && !arg.starts_with('-') => {
                rounds = Some(arg.parse().map_err(|e| format!("ROUNDS {arg:?}: {e}"))?)
            }
            _ => {
                return Err(format!(
                    "{arg:?}: expected [ROUNDS] [--serial | --parallel] [--n N] [--calls C]: one number, one of the two flags, one --n, one --calls"
                )
                .into());
            }
        }
    }
    let rounds = rounds.unwrap_or(41);
    if !(1..=MAX_ROUNDS).contains(&rounds) {
        return Err(format!("ROUNDS {rounds}: expected 1 to {MAX_ROUNDS}").into());
    }
    let n = n.unwrap_or(N);
    if !(1..=MAX_N).contains(&n) {
        return Err(format!("--n {n}: expected 1 to {MAX_N} nodes").into());
    }
    let calls = calls.unwrap_or(1);
    if !(1..=MAX_CALLS).contains(&calls) {
        return Err(format!("--calls {calls}: expected 1 to {MAX_CALLS}").into());
    }
    let nodes = unit_nodes(n)?;
    let mut rng = rand_pcg::Pcg64::seed_from_u64(1);
    let mut rng_estimate = rand_pcg::Pcg64::seed_from_u64(1);
    let bare = GaussLegendre {
        error_estimate: false,
    };
    let fixed = FixedOrder::new(n)?;
    let bil = bilby::GaussLegendre::new(n)?;
    let gq = gauss_quad::GaussLegendre::new(NonZeroUsize::new(n).ok_or("n = 0")?);
    let (a, b) = (-1.0f64, 1.0f64);
    let contenders: Vec<Contender> = vec![
        (
            "lightquad",
            Box::new(|| {
                let (a, b) = (black_box(a), black_box(b));
                let h = b - a;
                product_sum([nodes.as_ref()], |u: [f64; 1]| Ok(integrand(a + h * u[0])))
                    .map_or(f64::NAN, |s| s.value * h)
            }),
        ),
        (
            "lightquad rule",
            Box::new(|| {
                let (a, b) = (black_box(a), black_box(b));
                let h = b - a;
                bare.integrate(n, &mut rng, |u: [f64; 1]| integrand(a + h * u[0]))
                    .map_or(f64::NAN, |e| e.value * h)
            }),
        ),
        (
            "lightquad fixed",
            Box::new(|| {
                fixed
                    .integrate(black_box(a), black_box(b), integrand)
                    .unwrap_or(f64::NAN)
            }),
        ),
        (
            "lightquad estimate",
            Box::new(|| {
                let (a, b) = (black_box(a), black_box(b));
                let h = b - a;
                GaussLegendre::default()
                    .integrate(n, &mut rng_estimate, |u: [f64; 1]| integrand(a + h * u[0]))
                    .map_or(f64::NAN, |e| e.value * h)
            }),
        ),
        (
            "bilby",
            Box::new(|| bil.rule().integrate(black_box(a), black_box(b), integrand)),
        ),
        (
            "gauss-quad",
            Box::new(|| gq.integrate(black_box(a), black_box(b), integrand)),
        ),
        (
            "plain loop",
            Box::new(|| {
                // The peers' loop on lightquad's own nodes: one plain
                // addition a term, nothing else.
                let (a, b) = (black_box(a), black_box(b));
                let h = b - a;
                let mut s = 0.0;
                for (&u, &w) in nodes.u.iter().zip(&nodes.w) {
                    s += w * integrand(a + h * u);
                }
                s * h
            }),
        ),
        (
            "lightquad par",
            Box::new(|| {
                let (a, b) = (black_box(a), black_box(b));
                let h = b - a;
                line_sum_par(&nodes, |u| Ok(integrand(a + h * u))).map_or(f64::NAN, |s| s.value * h)
            }),
        ),
        (
            "lightquad fixed par",
            Box::new(|| {
                fixed
                    .par_integrate(black_box(a), black_box(b), integrand)
                    .unwrap_or(f64::NAN)
            }),
        ),
        (
            "gauss-quad par",
            Box::new(|| gq.par_integrate(black_box(a), black_box(b), integrand)),
        ),
        (
            "lightquad const",
            Box::new(|| {
                product_sum([nodes.as_ref()], |u: [f64; 1]| {
                    Ok(integrand(2.0 * u[0] - 1.0))
                })
                .map_or(f64::NAN, |s| s.value * 2.0)
            }),
        ),
        (
            "bilby const",
            Box::new(|| bil.rule().integrate(-1.0, 1.0, integrand)),
        ),
        (
            "gauss-quad const",
            Box::new(|| gq.integrate(-1.0, 1.0, integrand)),
        ),
    ];
    let all: Vec<&str> = contenders.iter().map(|(name, _)| *name).collect();
    let mut contenders: Vec<Contender> = contenders
        .into_iter()
        .filter(|(name, _)| only.is_none_or(|par| name.ends_with(" par") == par))
        .filter(|(name, _)| *name != "lightquad estimate" || n <= TABLE_MAX_ORDER)
        .collect();
    // One untimed call each: nodes and code paged in.
    for (_, f) in &mut contenders {
        black_box(f());
    }
    let k = contenders.len();
    let mut times: Vec<Vec<f64>> = (0..k).map(|_| Vec::with_capacity(rounds)).collect();
    let mut values = vec![0.0; k];
    for r in 0..rounds {
        for j in 0..k {
            let i = if r % 2 == 0 {
                (j + r) % k
            } else {
                (k - 1 - j + r) % k
            };
            let f = &mut contenders[i].1;
            let start = Instant::now();
            for _ in 0..calls {
                values[i] = black_box(f());
            }
            times[i].push(start.elapsed().as_secs_f64() * 1e3 / calls as f64);
        }
    }
    println!("{n} nodes, {rounds} rounds, {calls} calls a timing");
    println!("| contender | median | least | error |");
    println!("|---|---:|---:|---:|");
    for (i, (name, _)) in contenders.iter().enumerate() {
        let mut t = times[i].clone();
        println!(
            "| {name} | {} | {} | {:.1e} |",
            duration(quantile(&mut t, 0.5)),
            duration(quantile(&mut t, 0.0)),
            ((values[i] - EXACT_HI) - EXACT_LO).abs()
        );
    }
    println!();
    println!("| ratio, paired by round | median | 95% interval of the median | quartiles |");
    println!("|---|---:|---:|---:|");
    let index = |name: &str| contenders.iter().position(|(n, _)| *n == name);
    for (num, den) in [
        ("lightquad rule", "bilby"),
        ("lightquad rule", "gauss-quad"),
        ("lightquad rule", "lightquad"),
        ("lightquad fixed", "bilby"),
        ("lightquad fixed", "gauss-quad"),
        ("lightquad fixed", "lightquad rule"),
        ("lightquad estimate", "lightquad rule"),
        ("lightquad", "bilby"),
        ("lightquad", "gauss-quad"),
        ("lightquad", "plain loop"),
        ("plain loop", "bilby"),
        ("lightquad fixed", "plain loop"),
        ("lightquad fixed par", "gauss-quad par"),
        ("lightquad fixed par", "lightquad par"),
        ("lightquad par", "gauss-quad par"),
        ("lightquad par", "bilby"),
        ("lightquad par", "lightquad"),
        ("lightquad const", "bilby const"),
        ("lightquad const", "gauss-quad const"),
        ("lightquad", "lightquad const"),
        ("bilby", "bilby const"),
        ("gauss-quad", "gauss-quad const"),
    ] {
        if !(all.contains(&num) && all.contains(&den)) {
            return Err(format!("ratio {num} / {den}: no such contender").into());
        }
        // A pair with a side left out by --serial or --parallel.
        let (Some(i), Some(j)) = (index(num), index(den)) else {
            continue;
        };
        let mut ratio: Vec<f64> = times[i].iter().zip(&times[j]).map(|(x, y)| x / y).collect();
        let interval = median_interval(&mut ratio)
            .map_or("– (under 6 rounds)".into(), |(l, h)| {
                format!("{l:.4} – {h:.4}")
            });
        println!(
            "| {num} / {den} | {:.4} | {interval} | {:.3} – {:.3} |",
            quantile(&mut ratio, 0.5),
            quantile(&mut ratio, 0.25),
            quantile(&mut ratio, 0.75)
        );
    }
    Ok(())
}
