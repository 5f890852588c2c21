//! The index's ranking of the rules by time to the middle target error, with
//! ties where the times' confidence intervals overlap.

use crate::experiment::timing::TimeInterval;

/// Per-experiment summary for the index: per quantity, in the file's order,
/// each rule's time to the middle target (None: not reached).
pub type Summary = Vec<(&'static str, Vec<Ranked>)>;

/// One rule in the index's ranking of a quantity.
#[derive(Debug, Clone, PartialEq)]
pub struct Ranked {
    /// The rule's label.
    pub label: String,
    /// The target relative error it is ranked at: its experiment's middle
    /// target (the targets sorted from the largest; of two, the smaller).
    pub target: f64,
    /// Its time to `target` (None: not reached).
    pub seconds: Option<f64>,
    /// That time's confidence interval (None: not reached, or no time read).
    pub time: Option<TimeInterval>,
    /// A deterministic rule whose error is unresolved (exact, at rounding, or
    /// at the reference's accuracy) already at its smallest budget: its rank
    /// then says nothing about its speed on integrands in general.
    pub exact_from_start: bool,
}

/// A ranking, fastest first; rules that never reached the target last, by
/// name (unranked: [`ranks`]).
pub fn ranked(ranking: &[Ranked]) -> Vec<Ranked> {
    let mut ranked = ranking.to_vec();
    ranked.sort_by(|a, b| match (a.seconds, b.seconds) {
        (Some(x), Some(y)) => x.total_cmp(&y),
        (Some(_), None) => std::cmp::Ordering::Less,
        (None, Some(_)) => std::cmp::Ordering::Greater,
        (None, None) => a.label.cmp(&b.label),
    });
    ranked
}

/// The rank of each rule in `ranked` (sorted by [`ranked`]): 1, 2, ...,
/// with a rule whose time's interval overlaps that of the rule before it
/// sharing that one's rank (their times are not told apart). A rule that
/// did not reach the target has no rank: no time orders it against the
/// others, whether it ran out of budget or every job of it failed.
pub fn ranks(ranked: &[Ranked]) -> Vec<Option<usize>> {
    let mut out: Vec<Option<usize>> = Vec::with_capacity(ranked.len());
    for (i, r) in ranked.iter().enumerate() {
        let rank = match (r.seconds, i.checked_sub(1)) {
            (None, _) => None,
            (Some(_), Some(before)) if tied(&ranked[before], r) => out[before],
            (Some(_), _) => Some(i + 1),
        };
        out.push(rank);
    }
    out
}

/// Whether the rule at `i` shares its rank with the rule before it
/// (`ranks` of a ranking); never where it has no rank.
pub fn shares_rank(ranks: &[Option<usize>], i: usize) -> bool {
    i > 0 && ranks[i].is_some() && ranks[i] == ranks[i - 1]
}

/// Whether two reached times are not told apart: their intervals overlap,
/// or, where either is a single reading, they are within the noise of a
/// run ([`TimeInterval::apart`]); equal times where either has no time.
pub fn tied(a: &Ranked, b: &Ranked) -> bool {
    match (a.time, b.time, a.seconds, b.seconds) {
        (Some(x), Some(y), _, _) => !x.apart(&y),
        (_, _, Some(x), Some(y)) => x == y,
        _ => false,
    }
}

/// Said of a rule whose rank it shares with the one before.
pub const TIED: &str = "tied: not told apart from the rule before (their times' intervals \
overlap, or, for a single reading, are within 1.5x)";

/// Said of a rule ranked while exact from its first budget.
pub const EXACT_FROM_START: &str = "at the error floor from its first budget: this integrand is \
easy for it, the rank says little in general";

#[cfg(test)]
mod tests {
    use super::*;

    fn rule(label: &str, seconds: Option<f64>) -> Ranked {
        Ranked {
            target: 1e-6,
            label: label.into(),
            seconds,
            time: seconds.map(|s| TimeInterval {
                median: s,
                low: 0.9 * s,
                high: 1.1 * s,
                confidence: 0.95,
                samples: 15,
            }),
            exact_from_start: false,
        }
    }

    /// Times whose intervals overlap the one before share its rank; a gap
    /// starts a new rank at the position; rules that did not reach the
    /// target have no rank, and share none.
    #[test]
    fn times_whose_intervals_overlap_share_a_rank() {
        let r = ranked(&[
            rule("d", None),
            rule("c", Some(2.0e-6)),
            rule("b", Some(5.7e-7)),
            rule("a", Some(5.6e-7)),
            rule("e", None),
        ]);
        let labels: Vec<&str> = r.iter().map(|x| x.label.as_str()).collect();
        assert_eq!(labels, ["a", "b", "c", "d", "e"]);
        assert_eq!(ranks(&r), [Some(1), Some(1), Some(3), None, None]);
        let shared: Vec<bool> = (0..r.len()).map(|i| shares_rank(&ranks(&r), i)).collect();
        assert_eq!(shared, [false, true, false, false, false]);
    }
}
