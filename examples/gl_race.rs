//! Gauss–Legendre integration at n = 1e6 with cached nodes, lightquad
//! against `bilby` and `gauss-quad`, timed in interleaved rounds.
//!
//! `cargo run --release --example gl_race -- [ROUNDS]` (default 41)
//!
//! The same integral as `cargo bench --bench quadrature -- gl_integrate`:
//! `int_{-1}^{1} cos(50 x) dx`. On a shared machine whose speed drifts
//! from one second to the next, criterion's groups, timed one after
//! another, can differ by more than the few percent between these
//! integrators. Here every round times each contender once, in an order
//! rotated from round to round, and the figure compared is the median over
//! rounds of each round's ratio `lightquad / peer`: a slow stretch of the
//! machine slows both sides of a ratio alike.
//!
//! Two settings: the interval's bounds through `black_box` (a run-time
//! interval, the usual case) and, marked `const`, compile-time constants,
//! where the peers' inlined map `x = (b - a)/2 t + (a + b)/2` folds to
//! `t + 0`. Prints a table: the median and the least time of each
//! contender and the error of its value against `sin(50)/25`, then the
//! paired ratios (median and quartiles). `plain loop` is the peers' loop
//! (`s += w f(x)`) on lightquad's own nodes: lightquad's time over it is
//! what the compensated sum, `sum |w f|`, the largest term and the finite
//! checks cost.

use std::hint::black_box;
use std::num::NonZeroUsize;
use std::time::Instant;

use lightquad::quadrature::gauss_legendre::unit_nodes;
use lightquad::quadrature::nodes::product_sum;

const N: usize = 1_000_000;

fn integrand(x: f64) -> f64 {
    (50.0 * x).cos()
}

/// The `q`-quantile of `v` (sorted in place), by the nearest rank.
fn quantile(v: &mut [f64], q: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * q).round() as usize]
}

type Contender<'a> = (&'static str, Box<dyn Fn() -> f64 + 'a>);

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let rounds: usize = match std::env::args().nth(1) {
        Some(s) => s.parse().map_err(|e| format!("ROUNDS {s:?}: {e}"))?,
        None => 41,
    };
    if rounds == 0 {
        return Err("ROUNDS: expected at least 1".into());
    }
    let nodes = unit_nodes(N)?;
    let bil = bilby::GaussLegendre::new(N)?;
    let gq = gauss_quad::GaussLegendre::new(NonZeroUsize::new(N).ok_or("n = 0")?);
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
    // One untimed call each: nodes and code paged in.
    for (_, f) in &contenders {
        black_box(f());
    }
    let k = contenders.len();
    let mut times = vec![Vec::with_capacity(rounds); k];
    let mut values = vec![0.0; k];
    for r in 0..rounds {
        for j in 0..k {
            let i = (j + r) % k;
            let start = Instant::now();
            values[i] = black_box((contenders[i].1)());
            times[i].push(start.elapsed().as_secs_f64() * 1e3);
        }
    }
    let exact = (50.0f64).sin() / 25.0;
    println!("{N} nodes, {rounds} rounds");
    println!("| contender | median | least | error |");
    println!("|---|---:|---:|---:|");
    for (i, (name, _)) in contenders.iter().enumerate() {
        let mut t = times[i].clone();
        println!(
            "| {name} | {:.3} ms | {:.3} ms | {:.1e} |",
            quantile(&mut t, 0.5),
            quantile(&mut t, 0.0),
            (values[i] - exact).abs()
        );
    }
    println!();
    println!("| ratio, paired by round | median | quartiles |");
    println!("|---|---:|---:|");
    for (num, den) in [
        (0, 1),
        (0, 2),
        (0, 3),
        (4, 5),
        (4, 6),
        (0, 4),
        (1, 5),
        (2, 6),
    ] {
        let mut ratio: Vec<f64> = times[num]
            .iter()
            .zip(&times[den])
            .map(|(x, y)| x / y)
            .collect();
        println!(
            "| {} / {} | {:.3} | {:.3} – {:.3} |",
            contenders[num].0,
            contenders[den].0,
            quantile(&mut ratio, 0.5),
            quantile(&mut ratio, 0.25),
            quantile(&mut ratio, 0.75)
        );
    }
    Ok(())
}
