//! Reports, the sinks of a run: per experiment a Markdown page (a table per
//! quantity, fitted orders, time to reach target errors, stability flags) with
//! SVG plots of error against time and against n, a CSV of every job, and an
//! index page that links every experiment and ranks the rules by time to error.
//!
//! Nothing here knows a family: a page is described by a [`Page`], and values
//! are channel vectors (a scalar, RGB, an image), compared by their root mean
//! square.
//!
//! A module a step: [`rows`](fn@rows) aggregates the jobs into a table's rows
//! and flags them; [`order`](fn@order) fits orders and [`time_to`] finds times to
//! targets through them; a [`Section`] gathers what one quantity shows (both pages print it);
//! the Markdown page, `results.csv` and the index are written from those, and
//! [`ranked`] orders the rules for the index.
//!
//! ```
//! use std::collections::BTreeMap;
//! use lightquad::experiment::report::{Against, RuleInfo, order, rows};
//! use lightquad::quadrature::{Rule, Trapezoid};
//!
//! let text = r#"{"name": "doc-report", "family": "calibration", "scene": {}, "quantities": ["exp"],
//!   "rules": [{"rule": "trapezoid"}], "budgets": [8, 16, 32, 64, 128], "repeats": 1,
//!   "reference": {"type": "closed-form"}}"#;
//! let exp = lightquad::families::builtin().load(serde_json::from_str(text)?, "hash")?;
//! let results: Vec<_> = exp.jobs(None).into_iter().map(|job| exp.run_job(job)).collect();
//! // One row per (rule, budget) against the reference e - 1, and the order fitted
//! // against the resolution a budget buys (n - 1 intervals): -2 for the trapezoid rule.
//! let intervals: BTreeMap<usize, f64> = [8, 16, 32, 64, 128].map(|n| (n, Trapezoid.resolution(n, 1))).into();
//! let rule = RuleInfo { label: "trapezoid".into(), is_random: false,
//!     min_budget: BTreeMap::from([("exp".to_string(), 2)]),
//!     resolution: BTreeMap::from([(1, intervals.clone())]), not_run: None };
//! let table = rows(&[rule], &results, "exp", &[std::f64::consts::E - 1.0], None);
//! assert_eq!(table.len(), 5);
//! let against = Against::Resolution { dimension: 1, by_budget: Some(&intervals) };
//! let slope = order(&table.iter().collect::<Vec<_>>(), against, 0.0).ok_or("no fit")?;
//! assert!((slope + 2.0).abs() < 0.01, "{slope}");
//! // The page itself: report.md, SVG plots, results.csv and index.html.
//! let dir = std::env::temp_dir().join(format!("lightquad-doc-report-{}", std::process::id()));
//! std::fs::create_dir_all(&dir)?;
//! exp.write_report(&dir, &results)?;
//! assert!(std::fs::read_to_string(dir.join("report.md"))?.contains("trapezoid"));
//! assert!(dir.join("results.csv").exists() && dir.join("index.html").exists());
//! std::fs::remove_dir_all(&dir)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod csv;
mod findings;
mod fitted;
mod index;
mod order;
mod page;
mod pictures;
mod ranking;
mod rows;
mod section;
mod summary;
pub mod verdict;

use std::collections::BTreeMap;

pub use findings::findings;
pub use fitted::{Extrapolated, Reach, Slope};
pub use index::write_index;
pub use order::{Against, ERRATIC, FIT_ROWS, Order, fit_floor, fitted, order, time_to};
pub use page::{
    FIT_NOTE, SHARED, external_times, interval_cell, provenance, short_rows, write_experiment,
    write_summary,
};
pub use pictures::Picture;
pub use ranking::{EXACT_FROM_START, Ranked, Summary, TIED, ranked, ranks, shares_rank, tied};
pub use rows::{FLAG_LEGEND, Row, RowFlag, rows};
pub use section::not_run;
pub use section::{
    Fit, Section, cell, count_cell, display_line, extra_columns, label, off_cell, over_budget,
    sections, show_value, skipped,
};
pub use summary::{
    ExperimentSummary, FlagSummary, QuantitySummary, ReferenceSummary, ReportSummary, RowSummary,
    RuleSummary, SUMMARY_VERSION, TargetSummary, experiment_summary, schema as summary_schema,
};

use super::reference::{Crosscheck, Reference};
use crate::family::Display;

/// What a report page shows of an experiment, whatever its family.
#[derive(Debug, Clone)]
pub struct Page<'a> {
    /// Experiment name.
    pub name: &'a str,
    /// FNV-1a hash of the experiment file.
    pub hash: &'a str,
    /// What it shows.
    pub description: &'a str,
    /// Its family.
    pub family: &'static str,
    /// Its equation IDs.
    pub equations: &'a [String],
    /// Budgets, ascending.
    pub budgets: &'a [usize],
    /// What a budget counts.
    pub budget_unit: &'static str,
    /// Why a row may count more evaluations than its budget
    /// ([`Family::OVER_BUDGET`](crate::family::Family::OVER_BUDGET)).
    pub over_budget: &'static str,
    /// Repeats per (rule, budget).
    pub repeats: usize,
    /// The file's seed.
    pub seed: u64,
    /// How the family evaluates the scene, in words (may be empty).
    pub settings: String,
    /// The quantities, in the file's order.
    pub quantities: Vec<&'static str>,
    /// Each quantity's dimension (a budget of n is n^(1/D) nodes per axis).
    pub dimensions: Vec<usize>,
    /// Each quantity's display ([`Family::display`](crate::family::Family::display)).
    pub displays: Vec<Option<Display>>,
    /// Each quantity's image shape ([`Family::image`](crate::family::Family::image)).
    pub images: Vec<Option<[usize; 2]>>,
    /// The rules and estimators, in the file's order.
    pub rules: Vec<RuleInfo>,
    /// Target relative errors.
    pub targets: &'a [f64],
    /// The reference.
    pub reference: &'a Reference,
    /// The Mitsuba comparison rows (may be empty).
    pub crosscheck: &'a [Crosscheck],
    /// The family's section on this scene (e.g. printed formulas), if any.
    pub scene_audit: Option<String>,
}

impl Page<'_> {
    /// The target the rules are ranked by: the middle one (1e-6 where the
    /// file gives none).
    pub fn middle_target(&self) -> f64 {
        self.targets
            .get(self.targets.len() / 2)
            .copied()
            .unwrap_or(1e-6)
    }

    /// The colours of this page's rules, no two alike.
    pub fn palette(&self) -> super::plot::Palette {
        super::plot::Palette::new(self.rules.iter().map(|r| r.label.as_str()))
    }
}

/// A rule or estimator as a report sees it.
#[derive(Debug, Clone, PartialEq)]
pub struct RuleInfo {
    /// Its label (its name, with `#index` where the file names it twice).
    pub label: String,
    /// True for randomised rules (their estimate is a standard error).
    pub is_random: bool,
    /// Per quantity, the smallest budget at which it computes it (smaller
    /// budgets are skipped for that quantity); a quantity not listed: 1.
    pub min_budget: BTreeMap<String, usize>,
    /// Per dimension, the resolution per axis each budget buys
    /// ([`crate::quadrature::Rule::resolution`]: intervals of a composite
    /// rule, nodes or samples per axis otherwise); a missing entry is read as
    /// `n^(1/D)`.
    pub resolution: BTreeMap<usize, BTreeMap<usize, f64>>,
    /// Why it has no jobs (an external program missing, its rule asking to
    /// be skipped), if so.
    pub not_run: Option<String>,
}

impl RuleInfo {
    /// The smallest budget at which it computes quantity `q`.
    pub fn min_budget_of(&self, q: &str) -> usize {
        self.min_budget.get(q).copied().unwrap_or(1)
    }
}
