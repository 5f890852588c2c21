//! The rendering-equation family (R-* in docs/EQUATIONS.md): BRDFs,
//! emitters and occluders, and the hemispherical (R-H) and area (R-A)
//! forms of reflected radiance and irradiance at a point.
//!
//! Closed forms live in [`crate::exact::rendering`].

pub mod brdf;
