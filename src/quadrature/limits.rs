//! The limits every rule enforces (the budget, its memory, an adaptive
//! rule's tolerances) and the nodes per axis a budget buys.

use crate::error::QuadError;

/// Checks an adaptive rule's stopping tolerances (Gauss–Kronrod,
/// Genz–Malik): each finite and `>= 0`; the error names the parameter.
pub(crate) fn check_tolerances(abs_tol: f64, rel_tol: f64) -> Result<(), QuadError> {
    for (name, tol) in [("abs_tol", abs_tol), ("rel_tol", rel_tol)] {
        if !(tol.is_finite() && tol >= 0.0) {
            return Err(QuadError::invalid(name, tol, "a finite number >= 0"));
        }
    }
    Ok(())
}

/// The largest budget any rule accepts, `2^40` (about 1.1e12) evaluations:
/// hours of work at a nanosecond per evaluation. A larger `n` (`usize::MAX`
/// from an unchecked computation) is refused at once instead of looping for
/// centuries.
pub const MAX_BUDGET: usize = 1 << 40;

/// Refuses a budget above [`MAX_BUDGET`]: every rule's entry points, the
/// unguarded ones included (a trapezoid in three dimensions at `usize::MAX`
/// ran on for 1.8e19 evaluations).
#[inline]
pub(crate) fn check_budget(n: usize) -> Result<(), QuadError> {
    if n > MAX_BUDGET {
        return Err(over_budget(n));
    }
    Ok(())
}

/// [`check_budget`]'s error, out of the line of every rule's call.
#[cold]
fn over_budget(n: usize) -> QuadError {
    QuadError::invalid(
        "n",
        n,
        format!("a budget of at most 2^40 = {MAX_BUDGET} evaluations"),
    )
}

/// The most working memory one integral may need by its rule's own
/// estimate ([`Rule::memory`]): 32 GiB, more than the machines this runs on
/// hold; a larger `n` is refused at once instead of growing until the
/// machine runs out.
///
/// [`Rule::memory`]: super::Rule::memory
pub const MAX_RULE_BYTES: f64 = 32.0 * (1u64 << 30) as f64;

/// The largest `m` with `m^dim <= n` (`n` itself for `dim <= 1`).
#[inline]
pub fn integer_root(n: usize, dim: usize) -> usize {
    if dim <= 1 {
        return n;
    }
    let mut m = (n as f64).powf(1.0 / dim as f64).round() as usize;
    while m > 0 && m.checked_pow(dim as u32).is_none_or(|p| p > n) {
        m -= 1;
    }
    while (m + 1).checked_pow(dim as u32).is_some_and(|p| p <= n) {
        m += 1;
    }
    m
}

/// Nodes per axis for a product rule with a budget of `n` evaluations in `D`
/// dimensions: the largest `m` with `m^D <= n`; at least `min` (else an error
/// naming `name`).
#[inline]
pub fn per_axis<const D: usize>(n: usize, min: usize, name: &str) -> Result<usize, QuadError> {
    let need = min.checked_pow(D as u32).unwrap_or(usize::MAX);
    if n < need {
        return Err(too_small(name, n, need, D));
    }
    Ok(integer_root(n, D).max(min))
}

/// [`per_axis`]'s error, out of the line of every rule's call.
#[cold]
fn too_small(name: &str, n: usize, need: usize, dim: usize) -> QuadError {
    QuadError::invalid(
        name,
        n,
        format!("a budget of at least {need} evaluations in {dim} dimension(s)"),
    )
}
