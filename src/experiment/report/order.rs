//! What a rule's rows say about it: the fitted order of convergence and the
//! time it needs to reach a target error.

use std::collections::BTreeMap;

use super::rows::{FLOOR, Row, RowFlag};
use crate::experiment::fit::{Line, line};
use crate::family::Flag;

/// What a fitted slope is measured against.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Against<'a> {
    /// The resolution per axis each budget buys the rule (intervals of a
    /// composite rule, nodes or samples per axis: `n^(1/D)` where the map has
    /// no entry): a rule of order p shows as -p whatever an evaluation costs
    /// and whatever the dimension.
    Resolution {
        /// The quantity's dimension D.
        dimension: usize,
        /// Budget to resolution, for this rule and dimension.
        by_budget: Option<&'a BTreeMap<usize, f64>>,
    },
    /// The evaluations spent: the cost (nested depth makes it ~n^2, so an
    /// order-2 rule shows as -1 there).
    Evaluations,
}

/// Rows an order is fitted through: the largest budgets above the floor (an
/// order is an asymptotic property; the smallest budgets are often not yet
/// in the asymptotic range).
pub const FIT_ROWS: usize = 4;

/// The fitted slope of log error against log `against` of one rule's rows,
/// through the last [`FIT_ROWS`] rows whose error is above both the rounding
/// floor and ten times the reference's own accuracy (`floor`); None below
/// three such rows.
pub fn order(rows: &[&Row], against: Against, floor: f64) -> Option<f64> {
    fitted(rows, against, floor).map(|o| o.line.slope)
}

/// The error an order is fitted above: ten times the reference's accuracy
/// `accuracy`, and `100 FLOOR` (f64 rounding), the larger.
pub fn fit_floor(accuracy: f64) -> f64 {
    (100.0 * FLOOR).max(10.0 * accuracy)
}

/// Errors further than this factor from the fitted line: the slope is shown
/// as erratic, not as an order (a deterministic rule's; a random rule's root
/// mean square over a few repeats scatters more and gets twice the room).
pub const ERRATIC: f64 = 2.0;

/// A fitted order: the line through a rule's last rows and whether the
/// error grew by more than 1.5x from one fitted point to the next.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Order {
    /// The line, with its slope's confidence interval and scatter.
    pub line: Line,
    /// The error grew by more than 1.5x between consecutive fitted points.
    pub grew: bool,
}

/// [`order`] with its line ([`Line`]: the slope's interval, how far a point
/// lies off it) and whether the error grew inside the fitted rows.
pub fn fitted(rows: &[&Row], against: Against, floor: f64) -> Option<Order> {
    let mut pts: Vec<(f64, f64)> = rows
        .iter()
        .filter(|r| r.rel_error > fit_floor(floor))
        .map(|r| {
            let x = match against {
                Against::Resolution {
                    dimension,
                    by_budget,
                } => by_budget
                    .and_then(|m| m.get(&r.budget).copied())
                    .unwrap_or_else(|| (r.budget as f64).powf(1.0 / dimension.max(1) as f64)),
                Against::Evaluations => r.evaluations,
            };
            (x, r.rel_error)
        })
        .collect();
    if pts.len() < 3 {
        return None;
    }
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    let tail = &pts[pts.len().saturating_sub(FIT_ROWS)..];
    let grew = tail.windows(2).any(|w| w[1].1 > 1.5 * w[0].1);
    line(tail).map(|line| Order { line, grew })
}

/// The row that gives the time a rule needs to reach `target` and stay
/// there: the least median time among the rows from the smallest budget on
/// whose every larger budget meets the target too; None where the largest
/// budget misses it.
///
/// An error that dips below the target at one budget by a lucky
/// cancellation and rises above it again does not count (Gauss–Legendre on
/// r-sphere-below-horizon: 3.2e-7 at n = 1024, 5.7e-6 at 4096, below 1e-6
/// only from 65536 on; the first row ranked it first). A row where some
/// repeats failed reaches nothing, nor does one whose value underflowed: 0
/// against a reference that also reads 0 in f64 is an error of 0 on paper
/// and of 100% against the true value (`e^-100000` on the stiff sphere). A
/// row where every repeat failed measured no error, so it is left out: a
/// larger budget whose node lands on a singularity does not undo the
/// target reached below it (the row still shows its failure).
pub fn time_to<'a>(rows: &[&'a Row], target: f64) -> Option<&'a Row> {
    let meets = |r: &Row| {
        r.rel_error <= target
            && !r
                .flags
                .iter()
                .any(|f| matches!(f, RowFlag::Failed { .. } | RowFlag::Job(Flag::Underflow)))
    };
    let all_failed = |r: &Row| {
        r.flags
            .iter()
            .any(|f| matches!(f, RowFlag::Failed { failed, of, .. } if failed == of))
    };
    let mut by_budget: Vec<&'a Row> = rows.iter().copied().filter(|r| !all_failed(r)).collect();
    by_budget.sort_by_key(|r| r.budget);
    // The rows past the last budget that misses the target.
    let from = by_budget
        .iter()
        .rposition(|r| !meets(r))
        .map_or(0, |i| i + 1);
    by_budget[from..]
        .iter()
        .copied()
        .min_by(|a, b| a.seconds.total_cmp(&b.seconds))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(budget: usize, rel_error: f64, seconds: f64) -> Row {
        Row {
            rule_index: 0,
            budget,
            value: vec![1.0],
            rel_error,
            rel_estimate: rel_error,
            max_error: rel_error,
            display_off: None,
            evaluations: budget as f64,
            seconds,
            time: None,
            flags: Vec::new(),
        }
    }

    /// Gauss–Legendre on r-sphere-below-horizon (the independent check of
    /// session 22): 3.2e-7 at n = 1024 by a lucky cancellation, then 5.7e-6
    /// and 1.65e-6, below 1e-6 only from 65536 on. Its time to 1e-6 is the
    /// time at 65536, not the dip's.
    #[test]
    fn a_lucky_dip_below_the_target_is_not_the_time_to_it() {
        let rows = [
            row(256, 3e-5, 1e-5),
            row(1024, 3.2e-7, 2.5e-4),
            row(4096, 5.7e-6, 1e-3),
            row(16384, 1.65e-6, 5e-3),
            row(65536, 2e-7, 2e-2),
            row(262144, 5e-8, 8e-2),
        ];
        let refs: Vec<&Row> = rows.iter().collect();
        let seconds = |t| time_to(&refs, t).map(|r| r.seconds);
        assert_eq!(seconds(1e-6), Some(2e-2));
        assert_eq!(seconds(1e-4), Some(1e-5));
        assert_eq!(seconds(1e-8), None);
        // The largest budget missing the target: not reached, whatever
        // came before.
        let dip = [row(16, 1e-9, 1e-6), row(64, 1e-3, 4e-6)];
        let refs: Vec<&Row> = dip.iter().collect();
        assert!(time_to(&refs, 1e-6).is_none());
    }

    /// A larger budget where every repeat failed (a node on a singularity)
    /// measured nothing: the target reached below it stands. A row where
    /// some repeats failed does not reach it. A rule whose every row failed
    /// reaches nothing.
    #[test]
    fn a_row_where_every_repeat_failed_does_not_undo_the_target() {
        let failed = |budget, failed, of| Row {
            flags: vec![RowFlag::Failed {
                why: "inf at x = 0".into(),
                failed,
                of,
            }],
            ..row(budget, f64::NAN, f64::NAN)
        };
        let rows = [
            row(16, 1e-15, 4e-7),
            row(64, 1e-15, 1e-6),
            failed(4096, 3, 3),
        ];
        let refs: Vec<&Row> = rows.iter().collect();
        assert_eq!(time_to(&refs, 1e-6).map(|r| r.budget), Some(16));
        let some = Row {
            rel_error: 1e-15,
            ..failed(4096, 1, 3)
        };
        let rows = [row(16, 1e-15, 4e-7), some];
        let refs: Vec<&Row> = rows.iter().collect();
        assert!(time_to(&refs, 1e-6).is_none());
        let rows = [failed(16, 3, 3), failed(64, 3, 3)];
        let refs: Vec<&Row> = rows.iter().collect();
        assert!(time_to(&refs, 1e-6).is_none());
    }
}
