//! The result of every integration: a value, an error estimate and a cost.
//!
//! ```
//! use lightquad::{ErrorKind, Estimate};
//!
//! // Two halves of an integral, each with its error estimate: the sum adds the
//! // values and the costs.
//! let a = Estimate::deterministic(0.5, 1e-12, 16);
//! let b = Estimate::deterministic(0.25, 1e-12, 16);
//! let total = a.combine(b);
//! assert_eq!(total.value, 0.75);
//! assert_eq!(total.evaluations, 32);
//! assert_eq!(total.kind, ErrorKind::Deterministic);
//! ```

use crate::value::Value;

/// What an [`Estimate`]'s `error` is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ErrorKind {
    /// A deterministic rule's estimate of `|value - exact|` (Richardson,
    /// embedded rule, geometric tail). Estimates over disjoint regions add.
    Deterministic,
    /// One standard error of a random estimate, widened by
    /// [`t95_factor`] where it was estimated from few degrees of freedom, so
    /// that `value +- 1.96 error` is the two-sided 95% Student-t interval
    /// (`+- 1.96` plain sample standard errors cover 93% of normal data at
    /// 15 degrees of freedom and 89% at 5; the stratified rule's volume
    /// quantities at 16 cells covered 87-92% before the widening). Standard errors of
    /// independent estimates over disjoint regions add in quadrature
    /// (`sqrt(a^2 + b^2)`); adding them linearly would overstate the
    /// uncertainty by up to the square root of the number of regions.
    StandardError,
}

/// An integral estimate with the rule's own error estimate and its cost.
///
/// `error` is the rule's estimate of `|value - exact|` per channel: a standard
/// error for Monte Carlo rules, a Richardson or embedded-rule difference for
/// deterministic ones (`kind` says which); `f64::INFINITY` when the rule has no
/// information to estimate it (a one-node rule). `reliable` is false when the
/// rule saw that the assumption behind its estimate does not hold (differences
/// that do not shrink the way the estimate assumes; for a random rule,
/// samples that were all alike, so that a standard error of 0 says nothing
/// about values not seen, or a sample variance carried by a few samples, as
/// with infinite-variance integrands and rare events: see
/// [`crate::quadrature::monte_carlo`]): reports flag such an estimate instead
/// of presenting it as trustworthy. Reports put the error
/// beside the true error.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate<V: Value> {
    /// The integral estimate.
    pub value: V,
    /// The rule's estimate of the absolute error, per channel.
    pub error: V,
    /// Integrand evaluations spent, including those spent on the error estimate.
    pub evaluations: u64,
    /// What `error` is.
    pub kind: ErrorKind,
    /// False when the rule itself doubts its error estimate.
    pub reliable: bool,
    /// True when a deterministic rule's every evaluation gave the same
    /// value and its error estimate is 0 in some channel: the 0 says
    /// nothing of what lies between the nodes (a light no node saw; a
    /// constant integrand is flagged too, truly). Set by
    /// [`Rule::try_integrate`](crate::quadrature::Rule::try_integrate);
    /// a sum of pieces is alike when each piece is.
    pub alike: bool,
}

impl<V: Value> Estimate<V> {
    /// A deterministic rule's estimate, trusted.
    pub fn deterministic(value: V, error: V, evaluations: u64) -> Self {
        Estimate {
            value,
            error,
            evaluations,
            kind: ErrorKind::Deterministic,
            reliable: true,
            alike: false,
        }
    }

    /// A random estimate with its standard error.
    pub fn random(value: V, standard_error: V, evaluations: u64) -> Self {
        Estimate {
            value,
            error: standard_error,
            evaluations,
            kind: ErrorKind::StandardError,
            reliable: true,
            alike: false,
        }
    }

    /// Zero with no cost: the neutral element of [`Estimate::combine`] (a
    /// zero deterministic error leaves either kind of error unchanged and
    /// takes the other's kind).
    pub fn zero() -> Self {
        Estimate {
            value: V::zero(),
            error: V::zero(),
            evaluations: 0,
            kind: ErrorKind::Deterministic,
            reliable: true,
            alike: false,
        }
    }

    /// The same estimate, marked as one the rule doubts.
    pub fn doubted(self) -> Self {
        Estimate {
            reliable: false,
            ..self
        }
    }

    /// Largest per-channel error estimate.
    pub fn max_error(&self) -> f64 {
        self.error.max_abs()
    }

    /// Scales value and error by `s` (a Jacobian or an interval length).
    pub fn scaled(self, s: f64) -> Self {
        Estimate {
            value: self.value.map(|v| v * s),
            error: self.error.map(|e| e * s.abs()),
            ..self
        }
    }

    /// Adds an independent estimate over a disjoint region: values add;
    /// deterministic errors add, standard errors add in quadrature. A sum with
    /// a random part is random, and its error is the linear sum of the parts
    /// (a deterministic bound plus a standard error: conservative).
    pub fn combine(self, other: Self) -> Self {
        use ErrorKind::{Deterministic, StandardError};
        let (kind, error) = match (self.kind, other.kind) {
            (StandardError, StandardError) => (
                StandardError,
                self.error.zip(other.error, |a, b| a.hypot(b)),
            ),
            (Deterministic, Deterministic) => {
                (Deterministic, self.error.zip(other.error, |a, b| a + b))
            }
            _ => (StandardError, self.error.zip(other.error, |a, b| a + b)),
        };
        Estimate {
            value: self.value.zip(other.value, |a, b| a + b),
            error,
            evaluations: self.evaluations + other.evaluations,
            kind,
            reliable: self.reliable && other.reliable,
            // Zero (no evaluations) is neutral.
            alike: (self.alike || self.evaluations == 0)
                && (other.alike || other.evaluations == 0)
                && (self.alike || other.alike),
        }
    }
}

/// The integral over a region cut into `k` pieces (a segment's between
/// its breaks, an infinite interval's middle and tails): the pieces'
/// estimates [combined](Estimate::combine) in order, their values also
/// added scaled by `2^-s`, `2^s >= k`, where no partial sum can overflow
/// (the scaling is exact). Where the plain sum passes the f64 range and
/// the scaled one, scaled back, does not, the latter is the value:
/// `1e308 + 1e308 - 1e308` is `1e308` in every order. Only a total itself
/// beyond the range is an error, which names it.
pub struct PieceSum<V: Value> {
    total: Estimate<V>,
    scaled: V,
    /// `2^-s` and `2^s`.
    down: f64,
    up: f64,
    pieces: usize,
}

impl<V: Value> PieceSum<V> {
    /// A sum of `k` pieces (at least one assumed).
    pub fn new(k: usize) -> Self {
        let s = k.max(1).next_power_of_two().trailing_zeros() as i32;
        PieceSum {
            total: Estimate::zero(),
            scaled: V::zero(),
            down: 2f64.powi(-s),
            up: 2f64.powi(s),
            pieces: 0,
        }
    }

    /// Adds the next piece's estimate.
    pub fn add(&mut self, piece: Estimate<V>) {
        let down = self.down;
        self.scaled = self.scaled.zip(piece.value, |a, b| a + b * down);
        self.total = self.total.combine(piece);
        self.pieces += 1;
    }

    /// The total; an error where its value is beyond the f64 range.
    pub fn finish(self) -> Result<Estimate<V>, crate::QuadError> {
        if self.total.value.all_finite() {
            return Ok(self.total);
        }
        let up = self.up;
        let value = self.scaled.map(|v| v * up);
        if value.all_finite() {
            return Ok(Estimate {
                value,
                ..self.total
            });
        }
        Err(crate::QuadError::invalid(
            "integrand",
            format!(
                "[{}], the sum of its integrals over {} pieces, is beyond the f64 range",
                crate::error::channels(value),
                self.pieces
            ),
            "an integral at most 1.8e308 in magnitude: scale the integrand down",
        ))
    }
}

/// `t_dof(0.975) / 1.96`: the factor that turns `+- 1.96` standard errors
/// estimated with `dof` degrees of freedom into the two-sided 95% Student-t
/// interval (1.312 at 5, 1.087 at 15, 1.0001 at 10^4, 0.99998 in the
/// normal limit); infinite for `dof <= 0`, where there is no estimate of
/// the spread.
pub fn t95_factor(dof: f64) -> f64 {
    use statrs::distribution::{ContinuousCDF, StudentsT};
    /// The normal quantile `z_0.975`.
    const Z: f64 = 1.959_963_984_540_054;
    if dof.is_nan() || dof <= 0.0 {
        return f64::INFINITY;
    }
    if dof > 1e4 {
        // Cornish-Fisher: `t = z + (z^3 + z)/(4 nu) + (5z^5 + 16z^3 + 3z)/(96 nu^2)`,
        // within 1e-11 here; statrs' inversion loses digits past 1e5 degrees
        // of freedom (1.95985 at 10^6, below the normal quantile).
        let (z2, nu) = (Z * Z, dof);
        let t = Z
            + Z * (z2 + 1.0) / (4.0 * nu)
            + Z * (5.0 * z2 * z2 + 16.0 * z2 + 3.0) / (96.0 * nu * nu);
        return t / 1.96;
    }
    let exact = |nu: f64| match StudentsT::new(0.0, 1.0, nu) {
        Ok(t) => t.inverse_cdf(0.975) / 1.96,
        Err(_) => f64::INFINITY,
    };
    // Whole degrees of freedom up to TABLED from a table made once: the
    // inversion costs about 1.3 us, as much as a small rule's whole work,
    // and every random estimate asks for it. A fractional count (the
    // Welch-Satterthwaite estimate) below 10 is computed; from 10 on it is
    // interpolated linearly in 1/dof, in which the quantile is nearly linear
    // (within 3.4e-5 relative, measured on a 0.05 grid from 1 to 1000).
    const TABLED: usize = 1024;
    static TABLE: std::sync::OnceLock<Vec<f64>> = std::sync::OnceLock::new();
    if (1.0..=TABLED as f64).contains(&dof) {
        let table = TABLE.get_or_init(|| (0..=TABLED).map(|k| exact(k as f64)).collect());
        let k = dof.floor() as usize;
        if k == TABLED || dof == k as f64 {
            return table[k];
        }
        if k < 10 {
            return exact(dof);
        }
        let w = (1.0 / k as f64 - 1.0 / dof) / (1.0 / k as f64 - 1.0 / (k + 1) as f64);
        return table[k] + w * (table[k + 1] - table[k]);
    }
    exact(dof)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn t95_factor_matches_printed_student_t_quantiles() {
        // t_{0.975} from the standard tables (e.g. NIST/SEMATECH e-Handbook
        // 1.3.6.7.2): 12.706 (1), 2.571 (5), 2.131 (15), 2.042 (30), 1.984 (100).
        for (dof, t) in [
            (1.0, 12.706),
            (5.0, 2.571),
            (15.0, 2.131),
            (30.0, 2.042),
            (100.0, 1.984),
        ] {
            let got = t95_factor(dof) * 1.96;
            assert!((got - t).abs() < 6e-4, "dof {dof}: {got} vs {t}");
        }
        // Both sides of the switch to the expansion, and the normal limit.
        let (below, above) = (t95_factor(1e4), t95_factor(1e4 * (1.0 + 1e-9)));
        assert!((below - above).abs() < 1e-11, "{below} vs {above}");
        assert!((t95_factor(1e12) * 1.96 - 1.959_963_985).abs() < 1e-9);
        // Fractional counts between the tabled whole ones.
        for dof in [1.5, 7.25, 12.5, 333.3] {
            use statrs::distribution::{ContinuousCDF, StudentsT};
            let Ok(t) = StudentsT::new(0.0, 1.0, dof) else {
                panic!("dof {dof} > 0")
            };
            let direct = t.inverse_cdf(0.975) / 1.96;
            assert!((t95_factor(dof) / direct - 1.0).abs() < 5e-5, "dof {dof}");
        }
        assert_eq!(t95_factor(0.0), f64::INFINITY);
        assert_eq!(t95_factor(f64::NAN), f64::INFINITY);
    }

    #[test]
    fn standard_errors_of_disjoint_regions_add_in_quadrature_and_bounds_linearly() {
        let se = Estimate::random(1.0, 3.0, 10).combine(Estimate::random(2.0, 4.0, 10));
        assert_eq!((se.value, se.error, se.evaluations), (3.0, 5.0, 20));
        assert_eq!(se.kind, ErrorKind::StandardError);
        let det =
            Estimate::deterministic(1.0, 3.0, 10).combine(Estimate::deterministic(2.0, 4.0, 10));
        assert_eq!((det.error, det.kind), (7.0, ErrorKind::Deterministic));
        let mixed = Estimate::deterministic(1.0, 3.0, 1).combine(Estimate::random(2.0, 4.0, 1));
        assert_eq!((mixed.error, mixed.kind), (7.0, ErrorKind::StandardError));
        let zero = Estimate::zero().combine(Estimate::random(2.0, 4.0, 1));
        assert_eq!((zero.error, zero.kind), (4.0, ErrorKind::StandardError));
        let doubted = Estimate::deterministic(1.0, 1.0, 1)
            .doubted()
            .combine(Estimate::deterministic(1.0, 1.0, 1));
        assert!(!doubted.reliable);
    }
}
