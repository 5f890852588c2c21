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
    /// The integrand exceeded `2^500`, and its rescaled pass would evaluate
    /// past the budget (an adaptive rule took another path than the first,
    /// or the first outgrew the log the second replays).
    #[error(
        "rule `{rule}`: the integrand exceeded 2^500 (its sums or squares may overflow f64), and taking it again scaled by 2^-{exponent} would evaluate past the budget of {budget} (an adaptive rule took another path, or the pass outgrew its replay log); scale the integrand nearer 1"
    )]
    RescaleOverBudget {
        /// Rule name.
        rule: &'static str,
        /// The budget.
        budget: usize,
        /// The scaling exponent.
        exponent: i32,
    },
    /// A tracking walk would take more tentative collisions on one span of
    /// the ray than it may.
    #[error(
        "a tracking walk needs more than {limit} tentative collisions on one span of the ray: the majorant's optical depth over the span is {depth:.3e}; expected a depth below about {limit} per span: lower the medium's density or lambda (`scene.medium`, `scene.lambda` in an experiment), or integrate with a quadrature rule"
    )]
    TooDeepForTracking {
        /// The majorant's optical depth over the span.
        depth: f64,
        /// Most tentative collisions per walk and span.
        limit: u64,
    },
    /// The weighted sum of finite integrand values left the f64 range: a
    /// raw sum ([`crate::quadrature::nodes::product_sum`],
    /// [`crate::quadrature::nodes::line_sum_par`]) of values within rounding
    /// of `f64::MAX`, whose running sum can pass it where the integral does
    /// not (in two and more dimensions). Never a sum that is not finite.
    /// [`crate::quadrature::Rule::try_integrate`] takes such an integrand
    /// again scaled, and never returns this.
    #[error(
        "the weighted sum of the integrand's finite values (`{sum}`) overflows f64: it came to {value} (the rule's largest term |w f| is {largest}); expected values whose sums stay below f64::MAX: scale the integrand down, or integrate through a rule's `try_integrate`, which scales it"
    )]
    SumOutOfRange {
        /// Which sum left the range, named as the field of
        /// [`crate::quadrature::nodes::ProductSum`] it would have filled:
        /// `value`, or a companion's (`companion`, `companion4`,
        /// `companion8`).
        sum: &'static str,
        /// That sum as it came out (infinite or NaN in some channel),
        /// formatted.
        value: String,
        /// The largest `|w f|` of the rule's own sum, formatted.
        largest: String,
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
            accepted: short_numbers(&accepted.into()),
        }
    }

    /// The error for an integrand's finite `value` at the point `at` whose
    /// product with its domain's `jacobian` is not finite: past the f64
    /// range, or a Jacobian that is itself infinite (the map of an
    /// infinite end, within about 1e-154 of it).
    #[cold]
    pub fn times_jacobian<V: crate::value::Value>(value: V, jacobian: f64, at: String) -> Self {
        let value = channels(value);
        let jacobian_text = readable_number(jacobian);
        if jacobian.is_finite() {
            QuadError::invalid(
                "integrand",
                format!(
                    "{value} at {at}, times the domain's Jacobian {jacobian_text}, is beyond \
                     the f64 range"
                ),
                "values whose product with the domain's Jacobian (its measure per unit of the \
                 unit cube) is at most 1.8e308 in magnitude: scale the integrand down",
            )
        } else {
            QuadError::invalid(
                "integrand",
                format!("{value} at {at}, where the domain's Jacobian is {jacobian_text}"),
                "points where the domain's Jacobian is finite: the map of an infinite end \
                 overflows within about 1e-154 of it, where a rule that splits that deep \
                 evaluates; give the interval a finite end there",
            )
        }
    }
}

/// The channels of `value` as a person reads them, comma-separated.
pub fn channels<V: crate::value::Value>(value: V) -> String {
    let each: Vec<String> = (0..V::CHANNELS)
        .map(|c| readable_number(value.channel(c)))
        .collect();
    each.join(", ")
}

/// `v` as a person reads it: plain digits from 1e-4 to 1e15, else with an
/// exponent (`1.7e308`, not 309 digits).
pub fn readable_number(v: f64) -> String {
    if v == 0.0 || (1e-4..1e15).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// The most characters of a user's value (a name, a string, a key, a file's
/// JSON) a message quotes: past it the value is cut to an excerpt, so a
/// message never echoes a whole file back (a file holding one long string
/// was printed whole, 100 KB on stderr).
pub const EXCERPT_CHARS: usize = 60;

/// `value` cut to its first [`EXCERPT_CHARS`] characters, elided with `…`
/// and its length said, where it is longer.
///
/// ```
/// use lightquad::error::excerpt;
/// assert_eq!(excerpt("short"), "short");
/// let long = "x".repeat(1000);
/// assert_eq!(excerpt(&long), format!("{}… (1000 characters)", "x".repeat(60)));
/// ```
pub fn excerpt(value: &str) -> String {
    match value.char_indices().nth(EXCERPT_CHARS) {
        Some((cut, _)) => format!("{}… ({} characters)", &value[..cut], value.chars().count()),
        None => value.to_string(),
    }
}

/// A value as a person reads it in a message: a long number in scientific
/// notation (1e200 was echoed as its 201 digits), and any other text cut
/// after 200 characters (a 10 MB name was echoed whole). For a value of
/// ours (a formatted number, a described ray); a user's text is quoted as
/// an [`excerpt`].
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

/// A message as it is shown: its numbers short ([`short_numbers`]) and
/// every quoted value in it (`"..."`, or between backticks, as serde quotes
/// what it read: `invalid type: string "..."`, ``unknown field `...` ``)
/// cut to an [`excerpt`]. Every error and warning lightquad prints passes
/// here, so no message echoes more than an excerpt of a user's value.
///
/// ```
/// use lightquad::error::readable;
/// let secret = "s".repeat(500);
/// let shown = readable(&format!("invalid type: string \"{secret}\", expected a map"));
/// assert_eq!(
///     shown,
///     format!("invalid type: string \"{}…\" (500 characters), expected a map", "s".repeat(60))
/// );
/// assert_eq!(readable("unknown field `radius`"), "unknown field `radius`");
/// ```
pub fn readable(text: &str) -> String {
    bounded_quotes(&short_numbers(text))
}

/// `text` with the inside of every `"..."` (escapes skipped) and
/// `` `...` `` longer than [`EXCERPT_CHARS`] cut to an [`excerpt`], the
/// count after the closing quote; what follows a quote left open is kept.
fn bounded_quotes(text: &str) -> String {
    let mut out = String::with_capacity(text.len().min(4096));
    let mut rest = text;
    while let Some(open) = rest.find(['"', '`']) {
        let quote = rest.as_bytes()[open];
        out.push_str(&rest[..=open]);
        let inside = &rest[open + 1..];
        let close = closing(inside, quote);
        // A quote left open is text of ours (an excerpt of a JSON value cut
        // inside a string): the rest is left as it is.
        let Some(close) = close else {
            out.push_str(inside);
            return out;
        };
        let value = &inside[..close];
        // An excerpt already (the message was made readable before) is kept.
        let excerpted = value.ends_with('…') && value.chars().count() == EXCERPT_CHARS + 1;
        match value
            .char_indices()
            .nth(EXCERPT_CHARS)
            .filter(|_| !excerpted)
        {
            Some((cut, _)) => {
                out.push_str(&value[..cut]);
                out.push('…');
                out.push(char::from(quote));
                out.push_str(&format!(" ({} characters)", value.chars().count()));
            }
            None => {
                out.push_str(value);
                out.push(char::from(quote));
            }
        }
        rest = &inside[close + 1..];
    }
    out.push_str(rest);
    out
}

/// The byte index in `inside` of the quote that closes a quoted value opened
/// by `quote`; a backslash escapes the next character inside `"..."`.
fn closing(inside: &str, quote: u8) -> Option<usize> {
    let bytes = inside.as_bytes();
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b'\\' if quote == b'"' => i += 2,
            b if b == quote => return Some(i),
            _ => i += 1,
        }
    }
    None
}

/// The most characters of one key a JSON path in a message shows.
const PATH_KEY_CHARS: usize = 20;

/// A JSON path as a message shows it: each key of it longer than
/// [`PATH_KEY_CHARS`] cut and elided with `…` (a key is the user's text,
/// quoted whole in the message beside it as an excerpt).
fn readable_path(path: &str) -> String {
    if path.len() <= EXCERPT_CHARS {
        return path.to_string();
    }
    let key = |k: &str| match k.char_indices().nth(PATH_KEY_CHARS) {
        Some((cut, _)) => format!("{}…", &k[..cut]),
        None => k.to_string(),
    };
    path.split('.').map(key).collect::<Vec<_>>().join(".")
}

/// `text` with every number written in more than 24 characters put in
/// scientific notation, as a person reads it: Rust prints an f64 in full, so a
/// box corner of -1e308 came out as its 309 digits in the middle of a sentence
/// (and 1e-300 as 300 zeros). Shorter numbers, and digits inside a word (a
/// hash, a file name), are left as they are.
///
/// ```
/// use lightquad::error::short_numbers;
/// let long = format!("a number > min[0] = {} here", -1e308);
/// assert_eq!(short_numbers(&long), "a number > min[0] = -1e308 here");
/// assert_eq!(short_numbers(&format!("{} and 0.25", 1e-300)), "1e-300 and 0.25");
/// assert_eq!(short_numbers("hash 3c979872b2e1078a, n = 16"), "hash 3c979872b2e1078a, n = 16");
/// ```
pub fn short_numbers(text: &str) -> String {
    const LONGEST: usize = 24;
    let bytes = text.as_bytes();
    let word = |b: u8| b.is_ascii_alphanumeric() || b == b'_';
    let mut out = String::with_capacity(text.len());
    let mut copied = 0;
    let mut i = 0;
    while i < bytes.len() {
        let starts = bytes[i].is_ascii_digit()
            || (bytes[i] == b'-' && bytes.get(i + 1).is_some_and(u8::is_ascii_digit));
        if !starts || (i > 0 && (word(bytes[i - 1]) || bytes[i - 1] == b'.')) {
            i += 1;
            continue;
        }
        let start = i;
        i += 1;
        while i < bytes.len() && bytes[i].is_ascii_digit() {
            i += 1;
        }
        if i + 1 < bytes.len() && bytes[i] == b'.' && bytes[i + 1].is_ascii_digit() {
            i += 1;
            while i < bytes.len() && bytes[i].is_ascii_digit() {
                i += 1;
            }
        }
        if i < bytes.len() && word(bytes[i]) {
            // Part of a word (a hash, an identifier): not a number.
            while i < bytes.len() && word(bytes[i]) {
                i += 1;
            }
            continue;
        }
        let token = &text[start..i];
        if token.len() > LONGEST
            && let Ok(x) = token.parse::<f64>()
        {
            out.push_str(&text[copied..start]);
            out.push_str(&format!("{x:e}"));
            copied = i;
        }
    }
    out.push_str(&text[copied..]);
    out
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
            path: readable_path(&path.into()),
            message: readable(&message.into()),
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
            path: readable_path(&path),
            message: readable(&e.to_string()),
        }
    }
}
