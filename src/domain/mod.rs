//! Domains: maps from the unit cube `[0, 1]^D` onto the geometry an integral
//! lives on, with the Jacobian of the map and its inverse.
//!
//! `int_Omega g(p) d mu(p) = int_{[0,1]^D} g(map(u)) |J(u)| du`, so any
//! [`Rule`](crate::quadrature::Rule) integrates over any domain
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

pub mod frame;
pub mod hemisphere;
pub mod segment;

pub use frame::Frame;
pub use hemisphere::{Hemisphere, HemisphereMap};
pub use segment::Segment;

use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::quadrature::Rule;
use crate::value::Value;

/// A 3-vector (points and directions).
pub type Vec3 = nalgebra::Vector3<f64>;

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
    rule.integrate(n, rng, |u: [f64; D]| {
        let (p, jacobian) = domain.map(u);
        g(p).map(|v| v * jacobian)
    })
}
