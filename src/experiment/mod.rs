//! Experiments: budget sweeps of rules over integrals with known values, and
//! their reports (error against evaluations and time, fitted orders).
//!
//! Today this holds the built-in studies of the quadrature core
//! ([`core_study`]) and of the volume equations ([`volume_study`]);
//! JSON-described experiments over the equations grow here.

pub mod core_study;
pub mod fit;
pub mod volume_study;
