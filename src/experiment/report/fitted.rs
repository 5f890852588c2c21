//! What a rule's rows say about it, as numbers a program reads: its fitted
//! slopes with their confidence intervals, and per target the row that
//! reached it (with its time's interval) or, where none did, the budget and
//! time the fitted order extrapolates to.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::order::{Against, ERRATIC, Order, fitted, time_to};
use super::rows::Row;
use crate::experiment::timing::TimeInterval;
use crate::experiment::validate::MAX_BUDGET;

/// A fitted slope of log error against log cost, with its 95% interval.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Slope {
    /// The least-squares slope: order p shows as -p.
    pub slope: f64,
    /// The 95% confidence interval's lower end (Student's t with points - 2
    /// degrees of freedom, from the residuals about the line).
    pub low: f64,
    /// Its upper end.
    pub high: f64,
    /// Rows fitted (3 or 4: the largest budgets above the error floor).
    pub points: usize,
    /// The largest factor by which a fitted error lies off the line (at
    /// most the largest f64).
    pub off: f64,
    /// The error grew by more than 1.5x from one fitted row to the next.
    pub growing: bool,
    /// True where the slope is no order: errors more than 2x off the line
    /// (4x for a random rule), or a deterministic rule's error growing by
    /// more than 1.5x between fitted rows (`growing`).
    pub erratic: bool,
}

impl Slope {
    /// The slope of `rows` against `against`, judged erratic or not.
    pub fn of(rows: &[&Row], against: Against, accuracy: f64, random: bool) -> Option<Slope> {
        fitted(rows, against, accuracy).map(|o| Slope::from_order(o, random))
    }

    /// The slope of a fitted order, judged erratic or not.
    pub fn from_order(o: Order, random: bool) -> Slope {
        let limit = if random { 2.0 * ERRATIC } else { ERRATIC };
        let l = o.line;
        Slope {
            slope: l.slope,
            low: l.slope - l.half_width,
            high: l.slope + l.half_width,
            points: l.points,
            off: l.off.min(f64::MAX),
            growing: o.grew,
            erratic: l.off > limit || (!random && o.grew),
        }
    }

    /// Whether the slope is an order known well enough to extrapolate
    /// with: not erratic, negative, its 95% interval within a quarter of it
    /// (Monte Carlo's -0.40 ± 0.26 over three repeats put 1e-9 at 1.5e12 s).
    pub fn extrapolates(&self) -> bool {
        !self.erratic && self.slope < 0.0 && (self.high - self.low) / 2.0 <= 0.25 * -self.slope
    }

    /// The slope as a table shows it: `-2.00 ± 0.01`, and why it is no
    /// order where it is erratic.
    pub fn shown(&self, random: bool) -> String {
        let half = (self.high - self.low) / 2.0;
        let base = format!("{:.2} ± {}", self.slope, short(half));
        if !self.erratic {
            return base;
        }
        let off = if self.off < 1e4 {
            format!("{:.1}", self.off)
        } else {
            format!("{:.1e}", self.off)
        };
        let growing = if !random && self.growing {
            ", growing with n"
        } else {
            ""
        };
        format!("{base} (erratic: errors up to {off}x off the line{growing}, not an order)")
    }
}

/// A half-width in two significant figures, plainly where it is moderate.
fn short(x: f64) -> String {
    if (0.01..100.0).contains(&x) {
        format!("{x:.2}")
    } else {
        format!("{x:.1e}")
    }
}

/// Where a rule stands against one target error.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "status", rename_all = "kebab-case")]
pub enum Reach {
    /// The target is below the reference's own accuracy: not judged.
    BelowReferenceAccuracy,
    /// Reached, and held at every larger budget.
    Reached {
        /// The budget of the row that gives the time.
        budget: usize,
        /// Its mean evaluations.
        evaluations: f64,
        /// Its median time per call with the median's interval.
        seconds: TimeInterval,
    },
    /// No budget reached it and held it.
    NotReached {
        /// Where the fitted order says it would be reached; None where the
        /// slope against evaluations is missing, erratic, not negative, or
        /// uncertain by more than a quarter of itself (its 95% interval).
        extrapolated: Option<Extrapolated>,
    },
}

/// A budget and time extrapolated from the fitted order: an estimate, not
/// a measurement.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Extrapolated {
    /// The evaluations at which the line of log error against log
    /// evaluations reaches the target.
    pub evaluations: f64,
    /// The budget in the ratio of the largest row's budget to its
    /// evaluations.
    pub budget: f64,
    /// Seconds, scaled from the largest row's median time in proportion to
    /// the evaluations (cost taken as linear in them).
    pub seconds: f64,
}

impl Reach {
    /// Where the rule with rows `mine` stands against `target`, given the
    /// reference's accuracy and its slope against evaluations.
    pub fn of(mine: &[&Row], target: f64, accuracy: f64, cost: Option<&Order>) -> Reach {
        if target < accuracy {
            return Reach::BelowReferenceAccuracy;
        }
        match time_to(mine, target) {
            Some(r) => Reach::Reached {
                budget: r.budget,
                evaluations: r.evaluations,
                seconds: r.time.unwrap_or(TimeInterval {
                    median: r.seconds,
                    low: r.seconds,
                    high: r.seconds,
                    confidence: 0.0,
                    samples: 1,
                }),
            },
            None => Reach::NotReached {
                extrapolated: cost.and_then(|o| extrapolate(mine, target, o)),
            },
        }
    }

    /// The median seconds where reached.
    pub fn seconds(&self) -> Option<f64> {
        match self {
            Reach::Reached { seconds, .. } => Some(seconds.median),
            _ => None,
        }
    }

    /// The time's interval where reached.
    pub fn interval(&self) -> Option<TimeInterval> {
        match self {
            Reach::Reached { seconds, .. } => Some(*seconds),
            _ => None,
        }
    }

    /// As a table cell shows it.
    pub fn shown(&self) -> String {
        match self {
            Reach::BelowReferenceAccuracy => "below reference accuracy".into(),
            Reach::Reached { seconds, .. } => format!("{:.2e}", seconds.median),
            Reach::NotReached { extrapolated: None } => "not reached".into(),
            Reach::NotReached {
                extrapolated: Some(x),
            } if x.budget > MAX_BUDGET as f64 => format!(
                "not reached (extrapolated: beyond n = {:.0e}, the largest budget a file may ask)",
                MAX_BUDGET as f64
            ),
            Reach::NotReached {
                extrapolated: Some(x),
            } => format!(
                "not reached (extrapolated: ~{:.1e} s at n ~ {:.1e})",
                x.seconds, x.budget
            ),
        }
    }
}

/// The evaluations, budget and time at which a rule's fitted line against
/// evaluations reaches `target`, scaled from its largest timed row; None
/// where that line is erratic or not falling, or says the target lies
/// within the budgets already run (the rows contradict it).
fn extrapolate(mine: &[&Row], target: f64, cost: &Order) -> Option<Extrapolated> {
    let last = mine
        .iter()
        .filter(|r| r.rel_error.is_finite() && r.seconds.is_finite() && r.evaluations > 0.0)
        .max_by_key(|r| r.budget)?;
    let evaluations = cost.line.cost_at(target)?;
    if !(evaluations.is_finite() && evaluations > last.evaluations) {
        return None;
    }
    let scale = evaluations / last.evaluations;
    let x = Extrapolated {
        evaluations,
        budget: last.budget as f64 * scale,
        seconds: last.seconds * scale,
    };
    (x.budget.is_finite() && x.seconds.is_finite()).then_some(x)
}
