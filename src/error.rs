//! Errors of the quadrature core: every variant names the parameter, the value
//! it was given and what is accepted, so a user can fix the input without
//! reading the code.
//!
//! ```
//! use lightquad::QuadError;
//! use lightquad::domain::Segment;
//!
//! // Bad input is an error that says what was expected, never a panic.
//! let e = Segment::new(1.0, f64::NAN).unwrap_err();
//! assert!(matches!(e, QuadError::InvalidParameter { .. }), "{e}");
//! assert!(!e.to_string().is_empty());
//! ```

use thiserror::Error;

/// An error raised by a rule, a domain or an integration.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum QuadError {
    /// A parameter is outside its accepted range.
    #[error("invalid {name} = {value}: expected {accepted}")]
    InvalidParameter {
        /// Name of the parameter, as the user wrote it (`n`, `a`, `radius`, ...).
        name: String,
        /// The value that was given, formatted.
        value: String,
        /// What is accepted, in words (`an integer in 1..=100000000`).
        accepted: String,
    },
    /// A rule name that the registry does not know.
    #[error("unknown rule `{name}`: expected one of {known}")]
    UnknownRule {
        /// The name that was given.
        name: String,
        /// The known names, comma separated.
        known: String,
    },
    /// The rule cannot integrate over the requested dimension.
    #[error("rule `{rule}` does not support dimension {dim}: it supports {supported}")]
    UnsupportedDimension {
        /// Rule name.
        rule: &'static str,
        /// Requested dimension.
        dim: usize,
        /// Dimensions the rule supports, in words.
        supported: &'static str,
    },
    /// The integral is beyond the f64 range (or the rule's arithmetic is,
    /// even with the integrand scaled to at most 1).
    #[error(
        "rule `{rule}`: the integral overflows f64: the integrand scaled by 2^-{exponent} integrates to {value}, which times 2^{exponent} is beyond 1.8e308"
    )]
    Overflow {
        /// Rule name.
        rule: &'static str,
        /// The scaled estimate, formatted.
        value: String,
        /// The scaling exponent.
        exponent: i32,
    },
    /// The integral overflowed f64, and the rescaled second pass would
    /// evaluate past the budget (an adaptive rule took another path than the
    /// first, or the first outgrew the tape the second replays).
    #[error(
        "rule `{rule}`: the integral overflows f64 at this scale, and taking it again scaled by 2^-{exponent} would evaluate past the budget of {budget} (an adaptive rule took another path, or the pass outgrew its replay tape); scale the integrand nearer 1"
    )]
    RescaleOverBudget {
        /// Rule name.
        rule: &'static str,
        /// The budget.
        budget: usize,
        /// The scaling exponent.
        exponent: i32,
    },
    /// The integrand returned a non-finite value.
    #[error("integrand returned {value} at unit-cube point {point:?}")]
    NonFiniteIntegrand {
        /// The point in the unit cube where it happened.
        point: Vec<f64>,
        /// The offending value, formatted.
        value: String,
    },
}

impl QuadError {
    /// Shorthand for [`QuadError::InvalidParameter`].
    pub fn invalid(
        name: impl Into<String>,
        value: impl std::fmt::Display,
        accepted: impl Into<String>,
    ) -> Self {
        QuadError::InvalidParameter {
            name: name.into(),
            value: shortened(value.to_string()),
            accepted: accepted.into(),
        }
    }
}

/// A value as a person reads it in a message: a long number in scientific
/// notation (1e200 was echoed as its 201 digits), and any other text cut
/// after 200 characters (a 10 MB name was echoed whole).
pub fn shortened(value: String) -> String {
    const LONGEST: usize = 200;
    if value.len() > 24
        && let Ok(x) = value.parse::<f64>()
    {
        return format!("{x:e}");
    }
    match value.char_indices().nth(LONGEST) {
        Some((cut, _)) => format!("{}... ({} bytes)", &value[..cut], value.len()),
        None => value,
    }
}

/// Checks that `x` is finite, naming the parameter otherwise.
pub fn require_finite(name: &str, x: f64) -> Result<f64, QuadError> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(QuadError::invalid(name, x, "a finite number"))
    }
}

/// Checks that `x` is finite and strictly positive.
pub fn require_positive(name: &str, x: f64) -> Result<f64, QuadError> {
    if x.is_finite() && x > 0.0 {
        Ok(x)
    } else {
        Err(QuadError::invalid(name, x, "a finite number > 0"))
    }
}

/// A fault in an experiment file, at a JSON path.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("at `{path}`: {message}")]
pub struct SpecError {
    /// JSON path of the fault (`scene.medium.kappa`, `budgets[2]`, ...).
    pub path: String,
    /// What is wrong and what is accepted.
    pub message: String,
}

impl SpecError {
    /// An error at `path`.
    pub fn at(path: impl Into<String>, message: impl Into<String>) -> Self {
        SpecError {
            path: path.into(),
            message: message.into(),
        }
    }

    /// A library error re-anchored under `path`: an invalid parameter lands at
    /// `path.<parameter>`, anything else at `path`.
    pub fn from_quad(path: &str, e: QuadError) -> Self {
        let field = match &e {
            QuadError::InvalidParameter { name, .. } => Some(name.clone()),
            _ => None,
        };
        let path = match field {
            Some(f) if !path.ends_with(&f) => format!("{path}.{f}"),
            _ => path.to_string(),
        };
        SpecError {
            path,
            message: e.to_string(),
        }
    }
}
