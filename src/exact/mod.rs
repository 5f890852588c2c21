//! Closed forms, each naming its equation ID and its derivation. They are
//! tested against high-order quadrature, and quadrature is tested against
//! them: neither is trusted alone.
//!
//! ```
//! use lightquad::exact::volume::{emission, log_transmittance};
//!
//! // Through a chord of length 2 at sigma = 0.5: tau = e^-1, and
//! // I_E = c (1 - e^{-sigma L}) / sigma.
//! assert!((log_transmittance(0.5, 2.0) + 1.0).abs() < 1e-15);
//! let want = 3.0 * (1.0 - (-1.0f64).exp()) / 0.5;
//! assert!((emission(0.5, 2.0, 3.0) - want).abs() < 1e-14);
//! ```

pub mod exchange;
pub mod rendering;
pub mod volume;
