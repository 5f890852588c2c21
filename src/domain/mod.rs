//! Domains: maps from the unit cube `[0, 1]^D` onto the geometry an integral
//! lives on, with the Jacobian of the map and its inverse.
//!
//! `int_Omega g(p) d mu(p) = int_{[0,1]^D} g(map(u)) |J(u)| du`, so any
//! [`Rule`] integrates over any domain
//! ([`integrate_over`]): R rules and D domains cost R + D code.
//!
//! | domain | D | point | measure |
//! |---|---|---|---|
//! | [`Segment`] (ray segment, with break points) | 1 | `t` | length |
//! | [`Rectangle`] (parallelogram patch) | 2 | 3-D point | area |
//! | [`Disk`] | 2 | 3-D point | area |
//! | [`Triangle`] | 2 | 3-D point | area |
//! | [`SphericalCap`] (sphere when the cap is whole) | 2 | 3-D point | area |
//! | [`Hemisphere`] (uniform or cosine-weighted map) | 2 | unit direction | solid angle |
//! | [`Pixel`] (image-plane square) | 2 | `[x, y]` | area |
//!
//! ```
//! use lightquad::domain::{Domain, Segment, integrate_over};
//! use lightquad::quadrature::GaussLegendre;
//! use rand::SeedableRng;
//!
//! // int_1^3 t^2 dt = 26 / 3 over a ray segment, and its measure (length).
//! let seg = Segment::new(1.0, 3.0)?;
//! assert_eq!(seg.measure(), 2.0);
//! let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
//! let est = integrate_over(&GaussLegendre::default(), &seg, 4, &mut rng, |t: f64| t * t)?;
//! assert!((est.value - 26.0 / 3.0).abs() < 1e-13);
//! # Ok::<(), lightquad::QuadError>(())
//! ```

pub mod disk;
pub mod frame;
pub mod hemisphere;
pub mod pixel;
pub mod rectangle;
pub mod segment;
pub mod sphere;
pub mod triangle;

pub use disk::Disk;
pub use frame::Frame;
pub use hemisphere::{Hemisphere, HemisphereMap};
pub use pixel::Pixel;
pub use rectangle::Rectangle;
pub use segment::Segment;
pub use sphere::SphericalCap;
pub use triangle::Triangle;

use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::quadrature::Rule;
use crate::value::Value;

/// A 3-vector (points and directions).
pub type Vec3 = nalgebra::Vector3<f64>;

/// Relative tolerance of [`Domain::invert`]: a point within `INVERT_TOL` times
/// the domain's size of the domain (and of its surface) is on it; its `u` is
/// clamped into `[0, 1]^D`.
pub const INVERT_TOL: f64 = 1e-9;

/// The dimensionless slack `invert` grants a point: [`INVERT_TOL`] plus the
/// rounding of coordinates of magnitude `magnitude` on a domain of size `size`.
pub(crate) fn invert_slack(size: f64, magnitude: f64) -> f64 {
    INVERT_TOL + 64.0 * f64::EPSILON * magnitude / size
}

/// `x` clamped into `[0, 1]` when it lies within `slack` of it, else `None`
/// (`NaN` included).
pub(crate) fn snap_unit(x: f64, slack: f64) -> Option<f64> {
    if -slack <= x && x <= 1.0 + slack {
        Some(x.clamp(0.0, 1.0))
    } else {
        None
    }
}

/// `|x| <= bound`, false for `NaN`.
pub(crate) fn within(x: f64, bound: f64) -> bool {
    x.abs() <= bound
}

/// The azimuth `atan2(y, x) / (2 pi)` in `[0, 1]`: the inverse of `phi = 2 pi u`.
pub(crate) fn azimuth_fraction(y: f64, x: f64) -> f64 {
    let mut phi = y.atan2(x);
    if phi < 0.0 {
        phi += 2.0 * std::f64::consts::PI;
    }
    (phi / (2.0 * std::f64::consts::PI)).clamp(0.0, 1.0)
}

/// Checks that every component of `v` is finite, naming the parameter otherwise.
pub(crate) fn require_finite_vec3(name: &str, v: Vec3) -> Result<Vec3, QuadError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(v)
    } else {
        Err(QuadError::invalid(
            name,
            format!("{:?}", v.as_slice()),
            "a vector with finite components",
        ))
    }
}

/// The [`Frame`] around `normal`, an error naming `name` when `normal` is
/// non-finite or zero.
pub(crate) fn frame_around(name: &str, normal: Vec3) -> Result<Frame, QuadError> {
    Frame::from_normal(normal).map_err(|_| {
        QuadError::invalid(
            name,
            format!("{:?}", normal.as_slice()),
            "a finite, non-zero vector",
        )
    })
}

/// A map from `[0, 1]^D` onto a domain, with its Jacobian and inverse.
pub trait Domain<const D: usize> {
    /// A point of the domain.
    type Point: Copy;

    /// The point `map(u)` and the Jacobian `|J(u)|` of the map there (length,
    /// area or solid-angle element per unit of `du`).
    fn map(&self, u: [f64; D]) -> (Self::Point, f64);

    /// The `u` with `map(u) = p`, or `None` when `p` is not on the domain.
    fn invert(&self, p: &Self::Point) -> Option<[f64; D]>;

    /// The measure of the domain: `int |J(u)| du` (length, area, solid angle).
    fn measure(&self) -> f64;
}

/// Integrates `g` over `domain` with `rule` and a budget of `n` evaluations:
/// `int_{[0,1]^D} g(map(u)) |J(u)| du`.
pub fn integrate_over<const D: usize, Dom, R, Rg, V, G>(
    rule: &R,
    domain: &Dom,
    n: usize,
    rng: &mut Rg,
    mut g: G,
) -> Result<Estimate<V>, QuadError>
where
    Dom: Domain<D>,
    R: Rule,
    Rg: rand::Rng + ?Sized,
    V: Value,
    G: FnMut(Dom::Point) -> V,
{
    try_integrate_over(rule, domain, n, rng, |p| Ok(g(p)))
}

/// [`integrate_over`] for an integrand that may fail: its first error is
/// returned as is.
pub fn try_integrate_over<const D: usize, Dom, R, Rg, V, G>(
    rule: &R,
    domain: &Dom,
    n: usize,
    rng: &mut Rg,
    mut g: G,
) -> Result<Estimate<V>, QuadError>
where
    Dom: Domain<D>,
    R: Rule,
    Rg: rand::Rng + ?Sized,
    V: Value,
    G: FnMut(Dom::Point) -> Result<V, QuadError>,
{
    rule.try_integrate(n, rng, |u: [f64; D]| {
        let (p, jacobian) = domain.map(u);
        times_jacobian(g(p)?, jacobian, || format!("unit-cube point {u:?}"))
    })
}

/// `value` times the domain's `jacobian`; where the product is not finite
/// while `value` is, an error naming both and the point `at()`
/// ([`QuadError::times_jacobian`]). A value that is not finite itself is
/// passed on, for the rule to name at its point.
#[inline]
pub(crate) fn times_jacobian<V: Value>(
    value: V,
    jacobian: f64,
    at: impl FnOnce() -> String,
) -> Result<V, QuadError> {
    let product = value.map(|v| v * jacobian);
    if product.all_finite() || !value.all_finite() {
        return Ok(product);
    }
    Err(QuadError::times_jacobian(value, jacobian, at()))
}
