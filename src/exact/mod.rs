//! Closed forms, each naming its equation ID and its derivation. They are
//! tested against high-order quadrature, and quadrature is tested against
//! them: neither is trusted alone.

pub mod volume;
