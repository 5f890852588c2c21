//! # lightquad
//!
//! How accurate is each numerical approximation of a light-transport integral,
//! and what does it cost? lightquad answers with pluggable quadrature rules,
//! domains that map the unit cube onto the geometry of rendering, and the
//! equations of volume rendering with a directional light ([`volume`],
//! docs/EQUATIONS.md `V-*`) with closed forms ([`exact`]) where they exist, the
//! rendering equation ([`rendering`], `R-*`, and its closed scene, the
//! furnace, in [`rendering::closed`]) and Whitted ray tracing ([`whitted`],
//! `W-*`: W-6.1 with Phong, recursive rays, the pixel as an integral over its
//! square).
//!
//! Runnable programs in `examples/` (`cargo run --release --example NAME`):
//! `quadrature_over_a_domain` (a rule over a disk and a hemisphere),
//! `volume_term` (transmittance and emission along a ray through a constant
//! sphere) and `experiment_from_code` (an experiment file run from code into
//! a report) each check their result against a closed form they compute;
//! `verify_a_sampler` tests a hemisphere sampler and two planted bugs with
//! [`testing`] (lightquad's tests for a renderer's own `cargo test`);
//! `gl_race` times Gauss–Legendre integration against the crates `bilby` and
//! `gauss-quad`, and `tracking_race` times the tracking estimators for
//! `scripts/tracking_race.py`, which races them against Mitsuba 3.
//!
//! Three independent axes meet only where an integral is evaluated:
//!
//! - a **rule** ([`quadrature`]) places weighted nodes in `[0, 1]^D` for a budget
//!   of `n` evaluations and returns an [`Estimate`] (value, error estimate,
//!   evaluations); its facts (minimum budget, randomness, dimensions) are its
//!   own methods. Adding one: its file and one line in the `registry!` of
//!   [`quadrature`].
//! - a **domain** ([`domain`]) maps `[0, 1]^D` onto a ray segment, a surface
//!   patch, the hemisphere or a pixel, with the Jacobian of the map. Adding
//!   one: its file.
//! - a **family** of equations ([`family::Family`]: [`volume`], [`rendering`],
//!   [`whitted`], [`calibration`])
//!   owns its scene format, quantities, estimators beside the rules, closed
//!   forms and audit. Adding one: its module and one line in [`families`],
//!   the only place that names them.
//!
//! [`experiment`] (files, runs, references, reports) is generic over the
//! family and never names one.
//!
//! ```
//! use lightquad::domain::{Domain, Hemisphere, integrate_over};
//! use lightquad::quadrature::GaussLegendre;
//! use lightquad::rand::SeedableRng;
//!
//! // int_{H^2} cos(theta) d omega = pi
//! let mut rng = lightquad::rand_pcg::Pcg64::seed_from_u64(1);
//! let hemisphere = Hemisphere::uniform();
//! let est = integrate_over(&GaussLegendre::default(), &hemisphere, 64, &mut rng, |w| w.z)?;
//! assert!((est.value - std::f64::consts::PI).abs() < 1e-12);
//! # Ok::<(), lightquad::QuadError>(())
//! ```

// One `unsafe` call in the crate: the compensated sum's AVX pass, after
// checking that the CPU has AVX (`sum::avx::add_channel`). `.ci/run`
// fails on a second `unsafe` or `unsafe_code` anywhere in src, and clippy
// on a block without its SAFETY comment.
#![deny(unsafe_code)]
#![deny(clippy::undocumented_unsafe_blocks)]
#![deny(clippy::unwrap_used, clippy::expect_used)]
#![warn(missing_docs)]

/// `eprintln!` that never panics: a message to a closed stderr (`run 2>&1 |
/// head -2`) is dropped, and the run goes on to finish its results and
/// report (`eprintln!` panicked there and left folders without reports).
#[macro_export]
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

pub mod calibration;
pub mod domain;
pub mod error;
pub mod estimate;
pub mod exact;
pub mod experiment;
pub mod families;
pub mod family;
pub mod geometry;
pub mod integral;
pub mod parallel;
pub mod quadrature;
pub mod rendering;
pub mod sum;
pub mod testing;
pub mod value;
pub mod volume;
pub mod whitted;

pub use error::QuadError;
pub use estimate::{ErrorKind, Estimate};
pub use value::{Rgb, Value};

/// The random-number crate of the public API (every rule takes a
/// [`rand::Rng`]), at the version lightquad uses: code using lightquad needs
/// no dependency on it of its own.
pub use rand;
/// The generator the examples and tests seed ([`rand_pcg::Pcg64`]), at the
/// version lightquad uses.
pub use rand_pcg;

/// The README's Rust example, compiled and run with the doctests so that it
/// cannot go stale.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeExample;
