//! Chi-square goodness of fit of a sampler against its density over a
//! domain, as renderers test their sampling routines (Mitsuba 3's
//! `chi2.py`, pbrt-v4's sampling tests), with the domain's own map.
//!
//! The domain's parameterization `u in [0, 1]^2` is cut into `n_0 x n_1`
//! cells; a sampled point `p` falls in the cell of `invert(p)`. A cell's
//! expected count is `N int_cell pdf(map(u)) |J(u)| du` by adaptive
//! Genz–Malik cubature of each of its `k x k` boxes; the samples the
//! sampler refuses (`None`) are one more bin, expecting `N (1 - int pdf)`.
//! Bins expecting fewer than [`MIN_EXPECTED`] samples are pooled, and
//! Pearson's statistic is judged against chi-square with one degree of
//! freedom fewer than the bins. Beside it, the test of the density's
//! integral against the fraction `k / N` of draws that gave a sample:
//! `z = max(|k / N - int pdf| - tol, 0) / sqrt(p (1 - p) / N)`, two-sided
//! normal, `tol` the integral's tolerance (default `10^-3`, as Mitsuba 3's
//! harness allows; cubature across a silhouette, where the density jumps,
//! can miss by `10^-4` with an error estimate that does not say so). A
//! density that does not integrate to the chance of a sample fails it.
//!
//! A sample where the density is 0 fails the test outright (the density
//! says it cannot be drawn; an estimator would divide by it).
//!
//! Both tests are made at `alpha` Šidák-corrected over `tests` (the
//! integral's, which forgives its tolerance, rarely rejects a correct
//! sampler), so a correct sampler fails one of `tests` such calls with
//! probability about `alpha`: `tests/it/testing_api.rs` measures it over
//! 2000 tests of four samplers and asserts it within `[alpha / 2, 2
//! alpha]` (`-- --nocapture` prints it).

use std::fmt;

use rand::{RngExt, SeedableRng};
use statrs::distribution::{ChiSquared, ContinuousCDF, Normal};

use crate::domain::Domain;
use crate::error::QuadError;
use crate::quadrature::{GenzMalik, Rule};

use super::{check_alpha, check_count, sidak};

/// Bins expecting fewer samples than this are pooled into one.
pub const MIN_EXPECTED: f64 = 5.0;

/// The most cells a test may have.
pub const MAX_CELLS: usize = 1 << 22;

/// The most cubature boxes in all (cells times boxes per cell).
pub const MAX_BOXES: usize = 1 << 24;

/// The most tests a suite may declare.
pub const MAX_TESTS: usize = 1 << 40;

/// The most samples a test may draw.
pub const MAX_SAMPLES: usize = 1 << 36;

/// Worst cells reported on a failure.
const WORST: usize = 5;

/// A chi-square test of samplers over `domain`, with its settings; see the
/// [module](self).
///
/// ```
/// use lightquad::domain::Hemisphere;
/// use lightquad::testing::ChiSquare;
/// use lightquad::domain::Vec3;
/// use std::f64::consts::PI;
///
/// // Cosine-weighted hemisphere sampling (Malley's method) against cos(theta) / pi.
/// let sample = |u: [f64; 2]| {
///     let (r, phi) = (u[0].sqrt(), 2.0 * PI * u[1]);
///     Some(Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u[0]).sqrt()))
/// };
/// let test = ChiSquare::new(Hemisphere::uniform()).samples(200_000);
/// let outcome = test.run(|w: &Vec3| w.z / PI, sample, 1)?;
/// assert!(outcome.passed, "{outcome}");
/// // The same samples against the uniform density 1 / (2 pi): caught.
/// let outcome = test.run(|_: &Vec3| 1.0 / (2.0 * PI), sample, 1)?;
/// assert!(!outcome.passed);
/// # Ok::<(), lightquad::QuadError>(())
/// ```
#[derive(Debug, Clone)]
pub struct ChiSquare<Dom> {
    domain: Dom,
    cells: [usize; 2],
    samples: usize,
    alpha: f64,
    tests: usize,
    boxes: usize,
    tolerance: f64,
    integral_tolerance: f64,
}

impl<Dom: Domain<2>> ChiSquare<Dom> {
    /// A test over `domain` with `40 x 80` cells, `10^6` samples, `alpha =
    /// 0.01`, one test, `2 x 2` cubature boxes per cell and a cubature
    /// tolerance of `10^-3` samples per cell.
    pub fn new(domain: Dom) -> Self {
        ChiSquare {
            domain,
            cells: [40, 80],
            samples: 1_000_000,
            alpha: 0.01,
            tests: 1,
            boxes: 2,
            tolerance: 1e-3,
            integral_tolerance: 1e-3,
        }
    }

    /// Cells along `u_0` and along `u_1` of the domain's map.
    pub fn cells(mut self, cells: [usize; 2]) -> Self {
        self.cells = cells;
        self
    }

    /// Samples drawn per test.
    pub fn samples(mut self, samples: usize) -> Self {
        self.samples = samples;
        self
    }

    /// The chance that a correct sampler fails one of the [`tests`](Self::tests).
    pub fn alpha(mut self, alpha: f64) -> Self {
        self.alpha = alpha;
        self
    }

    /// How many tests the suite makes with this `alpha` (Šidák).
    pub fn tests(mut self, tests: usize) -> Self {
        self.tests = tests;
        self
    }

    /// Cubature boxes per cell along each axis (a feature of the density
    /// smaller than a box may be missed by its first 17 nodes).
    pub fn cubature_boxes(mut self, boxes: usize) -> Self {
        self.boxes = boxes;
        self
    }

    /// The absolute error, in samples, that the cubature of one cell aims at.
    pub fn cubature_tolerance(mut self, samples: f64) -> Self {
        self.tolerance = samples;
        self
    }

    /// How far the density's integral may be from the fraction of draws
    /// that gave a sample beyond their noise (absolute).
    pub fn integral_tolerance(mut self, tolerance: f64) -> Self {
        self.integral_tolerance = tolerance;
        self
    }

    /// The domain.
    pub fn domain(&self) -> &Dom {
        &self.domain
    }

    /// The per-test level: `alpha` Šidák-corrected over `tests`.
    pub fn level(&self) -> f64 {
        sidak(self.alpha, self.tests)
    }

    /// Checks the settings, naming the one that is wrong.
    fn check(&self) -> Result<(), QuadError> {
        let [a, b] = self.cells;
        check_count("cells[0]", a, 1, MAX_CELLS)?;
        check_count("cells[1]", b, 1, MAX_CELLS)?;
        if a.saturating_mul(b) < 2 || a.saturating_mul(b) > MAX_CELLS {
            return Err(QuadError::invalid(
                "cells",
                format!("{a} x {b}"),
                format!("2 to {MAX_CELLS} cells in all"),
            ));
        }
        check_count("samples", self.samples, 1, MAX_SAMPLES)?;
        check_alpha(self.alpha)?;
        check_count("tests", self.tests, 1, MAX_TESTS)?;
        check_count("cubature_boxes", self.boxes, 1, 64)?;
        let boxes = (a * b).saturating_mul(self.boxes * self.boxes);
        if boxes > MAX_BOXES {
            return Err(QuadError::invalid(
                "cubature_boxes",
                self.boxes,
                format!(
                    "at most {MAX_BOXES} boxes in all with the {a} x {b} cells (here {boxes}): \
                     fewer cells or boxes"
                ),
            ));
        }
        if !(self.integral_tolerance.is_finite() && (0.0..1.0).contains(&self.integral_tolerance)) {
            return Err(QuadError::invalid(
                "integral_tolerance",
                self.integral_tolerance,
                "a finite number in [0, 1)",
            ));
        }
        if !(self.tolerance.is_finite() && self.tolerance > 0.0) {
            return Err(QuadError::invalid(
                "cubature_tolerance",
                self.tolerance,
                "a finite number of samples > 0",
            ));
        }
        Ok(())
    }

    /// Each cell's expected count under `pdf` (a density in the domain's
    /// measure: area, solid angle), ready to test samplers against.
    pub fn expect<P>(self, pdf: P) -> Result<Expected<Dom, P>, QuadError>
    where
        Dom::Point: fmt::Debug,
        P: Fn(&Dom::Point) -> f64,
    {
        self.check()?;
        let [a, b] = self.cells;
        let mut counts = vec![0.0; a * b];
        let mut cubature_error = 0.0;
        for (k, count) in counts.iter_mut().enumerate() {
            let (e, err) = self.cell_integral(&pdf, [k / b, k % b])?;
            *count = e;
            cubature_error += err;
        }
        let expected = Expected {
            test: self,
            pdf,
            counts,
            cubature_error,
        };
        expected.check_bins()?;
        Ok(expected)
    }

    /// `N int_cell pdf |J| du` of cell `[i, j]` and its error estimate, by
    /// Genz–Malik on each of its boxes.
    fn cell_integral<P>(&self, pdf: &P, [i, j]: [usize; 2]) -> Result<(f64, f64), QuadError>
    where
        Dom::Point: fmt::Debug,
        P: Fn(&Dom::Point) -> f64,
    {
        let n = self.samples as f64;
        let k = self.boxes;
        let size = [
            1.0 / (self.cells[0] * k) as f64,
            1.0 / (self.cells[1] * k) as f64,
        ];
        let boxes = (k * k) as f64;
        let cubature = GenzMalik {
            abs_tol: self.tolerance / (n * boxes),
            rel_tol: 0.0,
        };
        let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
        let (mut value, mut error) = (0.0, 0.0);
        for b in 0..k * k {
            let lo = [
                (i * k + b / k) as f64 * size[0],
                (j * k + b % k) as f64 * size[1],
            ];
            let est = cubature.try_integrate(20_000, &mut rng, |v: [f64; 2]| {
                let u = [lo[0] + size[0] * v[0], lo[1] + size[1] * v[1]];
                let (p, jacobian) = self.domain.map(u);
                Ok(density(pdf, &p, "a cubature node")? * jacobian * size[0] * size[1])
            })?;
            value += est.value;
            error += est.error.abs();
        }
        Ok((value * n, error * n))
    }

    /// One test: the expected counts under `pdf`, then [`Expected::test`].
    pub fn run<P, S>(&self, pdf: P, sample: S, seed: u64) -> Result<Outcome, QuadError>
    where
        Self: Clone,
        Dom::Point: fmt::Debug,
        P: Fn(&Dom::Point) -> f64,
        S: FnMut([f64; 2]) -> Option<Dom::Point>,
    {
        self.clone().expect(pdf)?.test(sample, seed)
    }
}

/// `pdf(p)`, an error naming `p` (`what`) where it is negative or not finite.
fn density<P, T: fmt::Debug>(pdf: &P, p: &T, what: &str) -> Result<f64, QuadError>
where
    P: Fn(&T) -> f64,
{
    let d = pdf(p);
    if d.is_finite() && d >= 0.0 {
        Ok(d)
    } else {
        Err(QuadError::invalid(
            format!("pdf at {what} {p:?}"),
            d,
            "a finite density >= 0",
        ))
    }
}

/// A [`ChiSquare`] test with its cells' expected counts under a density:
/// test as many samplers (or seeds) against it as wanted.
#[derive(Debug, Clone)]
pub struct Expected<Dom, P> {
    test: ChiSquare<Dom>,
    pdf: P,
    counts: Vec<f64>,
    cubature_error: f64,
}

impl<Dom: Domain<2>, P: Fn(&Dom::Point) -> f64> Expected<Dom, P>
where
    Dom::Point: fmt::Debug,
{
    /// Each cell's expected count, cell `[i, j]` at `i n_1 + j`.
    pub fn counts(&self) -> &[f64] {
        &self.counts
    }

    /// `N int pdf` over the domain, in samples.
    pub fn total(&self) -> f64 {
        self.counts.iter().sum()
    }

    /// The sum of the cells' cubature error estimates, in samples.
    pub fn cubature_error(&self) -> f64 {
        self.cubature_error
    }

    /// Checks that at least two bins expect [`MIN_EXPECTED`] samples or
    /// more (pooling the rest), so the statistic has a degree of freedom.
    fn check_bins(&self) -> Result<(), QuadError> {
        let n = self.test.samples as f64;
        if !self.total().is_finite() {
            return Err(QuadError::invalid(
                "pdf",
                format!("an integral of {:e} over the domain", self.total() / n),
                "a density whose integral over the domain is finite (at most 1)",
            ));
        }
        if self.total() < MIN_EXPECTED && self.total() < 1e-6 * n {
            return Err(QuadError::invalid(
                "pdf",
                format!("an integral of {:e} over the domain", self.total() / n),
                "a density whose integral over the domain, the chance of a sample, is not 0",
            ));
        }
        let refused = (n - self.total()).max(0.0);
        let big = self
            .counts
            .iter()
            .chain(std::iter::once(&refused))
            .filter(|e| **e >= MIN_EXPECTED)
            .count();
        let pooled: f64 = self
            .counts
            .iter()
            .chain(std::iter::once(&refused))
            .filter(|e| **e < MIN_EXPECTED)
            .sum();
        let bins = big + usize::from(pooled >= MIN_EXPECTED);
        if bins >= 2 {
            return Ok(());
        }
        let [a, b] = self.test.cells;
        Err(QuadError::invalid(
            "samples",
            self.test.samples,
            format!(
                "enough samples that at least 2 bins of the {a} x {b} cells expect \
                 {MIN_EXPECTED} or more (here {bins}): more samples or fewer cells"
            ),
        ))
    }

    /// Draws the test's samples from `sample` at uniform `u` of a
    /// generator seeded with `seed`, bins them and judges the counts.
    /// A sample off the domain or where the density is negative or not
    /// finite is an error naming it.
    pub fn test<S>(&self, mut sample: S, seed: u64) -> Result<Outcome, QuadError>
    where
        S: FnMut([f64; 2]) -> Option<Dom::Point>,
    {
        let [a, b] = self.test.cells;
        let mut observed = vec![0u64; a * b];
        let mut missed = 0u64;
        let mut zero: Option<(usize, String)> = None;
        let mut zeros = 0usize;
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
        for k in 0..self.test.samples {
            let u = [rng.random::<f64>(), rng.random::<f64>()];
            let Some(p) = sample(u) else {
                missed += 1;
                continue;
            };
            let Some(v) = self.test.domain.invert(&p) else {
                return Err(QuadError::invalid(
                    format!("sample {k} (u = {u:?})"),
                    format!("{p:?}"),
                    "a point of the domain (its invert found none)",
                ));
            };
            if density(&self.pdf, &p, &format!("sample {k}"))? == 0.0 {
                zeros += 1;
                zero.get_or_insert_with(|| (k, format!("{p:?}")));
            }
            let i = ((v[0] * a as f64) as usize).min(a - 1);
            let j = ((v[1] * b as f64) as usize).min(b - 1);
            observed[i * b + j] += 1;
        }
        let mut out = self.judge(&observed, missed);
        out.zero_density = zeros;
        out.first_zero = zero.map(|(k, p)| format!("sample {k} at {p}"));
        out.passed &= zeros == 0;
        Ok(out)
    }

    /// The chi-square and integral tests of the observed counts.
    fn judge(&self, observed: &[u64], missed: u64) -> Outcome {
        let n = self.test.samples as f64;
        let total = self.total();
        let mut bins: Vec<Bin> = self
            .counts
            .iter()
            .zip(observed)
            .enumerate()
            .map(|(k, (&e, &o))| Bin {
                holds: Holds::Cell(k),
                merged: false,
                expected: e,
                observed: o as f64,
            })
            .collect();
        bins.push(Bin {
            holds: Holds::Refused,
            merged: false,
            expected: (n - total).max(0.0),
            observed: missed as f64,
        });
        let (statistic, dof, worst) = pearson(bins);
        let p_value = match ChiSquared::new(dof as f64) {
            Ok(d) if statistic.is_finite() => d.sf(statistic),
            _ => 0.0,
        };
        let successes = self.test.samples as u64 - missed;
        let p_integral = integral_p(
            total / n,
            self.test.integral_tolerance,
            successes,
            self.test.samples,
        );
        let level = self.test.level();
        let worst = worst
            .into_iter()
            .map(|bin| self.cell(bin))
            .collect::<Vec<_>>();
        Outcome {
            passed: p_value > level && p_integral > level && dof > 0,
            zero_density: 0,
            first_zero: None,
            statistic,
            dof,
            p_value,
            level,
            pdf_integral: total / n,
            success_fraction: successes as f64 / n,
            p_integral,
            integral_tolerance: self.test.integral_tolerance,
            cubature_error: self.cubature_error,
            samples: self.test.samples,
            worst,
        }
    }

    /// A bin as the report names it.
    fn cell(&self, bin: Bin) -> Cell {
        let Holds::Cell(k) = bin.holds else {
            return Cell {
                index: None,
                u: [[0.0; 2]; 2],
                centre: "draws the sampler refused (None)".into(),
                observed: bin.observed,
                expected: bin.expected,
            };
        };
        let [a, b] = self.test.cells;
        let (i, j) = (k / b, k % b);
        let u = [
            [i as f64 / a as f64, (i + 1) as f64 / a as f64],
            [j as f64 / b as f64, (j + 1) as f64 / b as f64],
        ];
        let mid = [(u[0][0] + u[0][1]) / 2.0, (u[1][0] + u[1][1]) / 2.0];
        Cell {
            index: Some([i, j]),
            u,
            centre: format!("{:?}", self.test.domain.map(mid).0),
            observed: bin.observed,
            expected: bin.expected,
        }
    }
}

/// What a bin of the statistic holds.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Holds {
    /// One cell, by index.
    Cell(usize),
    /// The draws the sampler refused.
    Refused,
    /// The cells expecting fewer than [`MIN_EXPECTED`].
    Pool,
}

/// One bin of the statistic.
#[derive(Debug, Clone, Copy)]
struct Bin {
    holds: Holds,
    /// True where the pooled bins joined it (their counts are in it).
    merged: bool,
    expected: f64,
    observed: f64,
}

impl Bin {
    /// `(o - e)^2 / e`; infinite for samples where none are expected.
    fn term(&self) -> f64 {
        let d = self.observed - self.expected;
        if self.expected > 0.0 {
            d * d / self.expected
        } else if self.observed > 0.0 {
            f64::INFINITY
        } else {
            0.0
        }
    }
}

/// Pearson's statistic over `bins` with those expecting fewer than
/// [`MIN_EXPECTED`] pooled (a pool still short of it joins the smallest
/// kept bin), its degrees of freedom (kept bins less one) and the worst
/// kept bins, largest term first. A bin with samples and no expectation
/// makes the statistic infinite and is among the worst.
fn pearson(bins: Vec<Bin>) -> (f64, usize, Vec<Bin>) {
    let (mut kept, small): (Vec<Bin>, Vec<Bin>) =
        bins.into_iter().partition(|b| b.expected >= MIN_EXPECTED);
    let impossible: Vec<Bin> = small
        .iter()
        .filter(|b| b.expected <= 0.0 && b.observed > 0.0)
        .copied()
        .collect();
    let pool = small
        .iter()
        .fold((0.0, 0.0), |(e, o), b| (e + b.expected, o + b.observed));
    if pool.0 >= MIN_EXPECTED {
        kept.push(Bin {
            holds: Holds::Pool,
            merged: false,
            expected: pool.0,
            observed: pool.1,
        });
    } else if let Some(smallest) = kept
        .iter_mut()
        .min_by(|x, y| x.expected.total_cmp(&y.expected))
    {
        smallest.expected += pool.0;
        smallest.observed += pool.1;
        smallest.merged = pool.0 > 0.0 || pool.1 > 0.0;
    }
    let mut statistic: f64 = kept.iter().map(Bin::term).sum();
    if !impossible.is_empty() {
        statistic = f64::INFINITY;
    }
    let dof = kept.len().saturating_sub(1);
    let mut worst: Vec<Bin> = impossible;
    let mut rest: Vec<Bin> = kept
        .into_iter()
        .filter(|b| b.holds != Holds::Pool && !b.merged)
        .collect();
    rest.sort_by(|x, y| y.term().total_cmp(&x.term()));
    worst.extend(rest);
    worst.truncate(WORST);
    (statistic, dof, worst)
}

/// The two-sided p-value of `successes` in `samples` draws against the
/// chance `integral`, a difference within `tolerance` forgiven:
/// `z = max(|k / N - integral| - tolerance, 0) / sqrt(p (1 - p) / N)`,
/// `p` the integral clamped to `[0, 1]` (a density integrating past 1 by
/// more than `tolerance` fails).
fn integral_p(integral: f64, tolerance: f64, successes: u64, samples: usize) -> f64 {
    let n = samples as f64;
    let off = ((successes as f64 / n - integral).abs() - tolerance).max(0.0);
    if integral > 1.0 + tolerance {
        return 0.0;
    }
    if off == 0.0 {
        return 1.0;
    }
    let p = integral.clamp(0.0, 1.0);
    let se = (p * (1.0 - p) / n).sqrt();
    if se == 0.0 {
        return 0.0;
    }
    (2.0 * Normal::standard().sf(off / se)).min(1.0)
}

/// `x` with `digits` decimals where that is readable, else in scientific
/// notation.
fn number(x: f64, digits: usize) -> String {
    if x == 0.0 || (1e-3..1e7).contains(&x.abs()) {
        format!("{x:.digits$}")
    } else {
        format!("{x:.digits$e}")
    }
}

/// A cell of a failed test, as Mitsuba's harness lists them.
#[derive(Debug, Clone, PartialEq)]
pub struct Cell {
    /// `[i, j]` along `u_0`, `u_1`; `None` for the refused samples' bin.
    pub index: Option<[usize; 2]>,
    /// Its `[u_0 range, u_1 range]`.
    pub u: [[f64; 2]; 2],
    /// The domain's point at its centre, formatted.
    pub centre: String,
    /// Samples observed.
    pub observed: f64,
    /// Samples expected.
    pub expected: f64,
}

/// What a [`ChiSquare`] test found.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    /// Both tests above the level.
    pub passed: bool,
    /// Pearson's statistic.
    pub statistic: f64,
    /// Its degrees of freedom.
    pub dof: usize,
    /// Its p-value.
    pub p_value: f64,
    /// The per-test level.
    pub level: f64,
    /// `int pdf` over the domain.
    pub pdf_integral: f64,
    /// The fraction of draws that gave a sample.
    pub success_fraction: f64,
    /// The p-value of the successes against `pdf_integral`.
    pub p_integral: f64,
    /// The difference of the two forgiven.
    pub integral_tolerance: f64,
    /// The expected counts' cubature error, in samples, summed over cells.
    pub cubature_error: f64,
    /// Samples drawn.
    pub samples: usize,
    /// The cells farthest from their expectation (largest terms first).
    pub worst: Vec<Cell>,
    /// Samples where the density is 0 (any fails the test).
    pub zero_density: usize,
    /// The first of them, in words.
    pub first_zero: Option<String>,
}

impl Outcome {
    /// Panics with the outcome in words unless it passed.
    pub fn assert_passed(&self) {
        assert!(self.passed, "{self}");
    }
}

impl fmt::Display for Outcome {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let verdict = if self.passed { "passed" } else { "FAILED" };
        writeln!(
            f,
            "chi-square goodness of fit {verdict}: statistic {} on {} degrees of freedom, p = {:.3e} (level {:.2e})",
            number(self.statistic, 1),
            self.dof,
            self.p_value,
            self.level
        )?;
        writeln!(
            f,
            "  the pdf integrates to {}; {:.6} of {} draws gave a sample (p = {:.3e}, {:.0e} forgiven)",
            number(self.pdf_integral, 6),
            self.success_fraction,
            self.samples,
            self.p_integral,
            self.integral_tolerance
        )?;
        write!(
            f,
            "  expected counts within {:.2e} samples in all (cubature's own estimate)",
            self.cubature_error
        )?;
        if let Some(first) = &self.first_zero {
            write!(
                f,
                "\n  {} samples where the pdf is 0, the first {first}",
                self.zero_density
            )?;
        }
        if !self.passed && !self.worst.is_empty() {
            write!(f, "\n  worst cells (observed / expected):")?;
            for c in &self.worst {
                match c.index {
                    Some([i, j]) => write!(
                        f,
                        "\n    [{i}, {j}] u0 in [{:.4}, {:.4}], u1 in [{:.4}, {:.4}], centre {}: {} / {}",
                        c.u[0][0],
                        c.u[0][1],
                        c.u[1][0],
                        c.u[1][1],
                        c.centre,
                        c.observed,
                        number(c.expected, 1)
                    )?,
                    None => write!(
                        f,
                        "\n    {}: {} / {}",
                        c.centre,
                        c.observed,
                        number(c.expected, 1)
                    )?,
                }
            }
        }
        Ok(())
    }
}
