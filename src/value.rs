//! Integrand values: a scalar `f64` or an RGB triple, behind one small trait so
//! every rule sums colours in one pass instead of three separate runs.
//!
//! ```
//! use lightquad::quadrature::{GaussLegendre, Rule};
//! use lightquad::Rgb;
//! use rand::SeedableRng;
//!
//! // One integral per colour channel: int_0^1 (1, 2u, 3u^2) du = (1, 1, 1).
//! let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
//! let est = GaussLegendre::default()
//!     .integrate(8, &mut rng, |u: [f64; 1]| Rgb::new(1.0, 2.0 * u[0], 3.0 * u[0] * u[0]))?;
//! assert!((est.value - Rgb::new(1.0, 1.0, 1.0)).norm() < 1e-14);
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use nalgebra::Vector3;

/// An RGB radiance or colour value, one `f64` per channel.
pub type Rgb = Vector3<f64>;

/// What a rule needs of an integrand value: a fixed number of `f64` channels.
pub trait Value: Copy + Send + Sync + std::fmt::Debug + 'static {
    /// Number of channels (1 for a scalar, 3 for RGB). At most 6 for the
    /// deterministic rules, whose sum keeps each channel's lanes in a SIMD
    /// vector of a fixed-size array ([`crate::sum::LaneValues`]); a value of
    /// more channels fails to compile there, with that message.
    const CHANNELS: usize;
    /// The value with every channel zero.
    fn zero() -> Self;
    /// Channel `i` (`i < CHANNELS`).
    fn channel(&self, i: usize) -> f64;
    /// Builds a value channel by channel.
    fn from_fn(f: impl FnMut(usize) -> f64) -> Self;
    /// Applies `f` to every channel.
    fn map(self, f: impl Fn(f64) -> f64) -> Self;
    /// Combines two values channel by channel.
    fn zip(self, other: Self, f: impl Fn(f64, f64) -> f64) -> Self;
    /// True when every channel is finite.
    fn all_finite(&self) -> bool;
    /// Largest absolute channel value.
    fn max_abs(&self) -> f64 {
        (0..Self::CHANNELS).fold(0.0, |m: f64, i| m.max(self.channel(i).abs()))
    }
}

impl Value for f64 {
    const CHANNELS: usize = 1;
    #[inline]
    fn zero() -> Self {
        0.0
    }
    #[inline]
    fn channel(&self, _: usize) -> f64 {
        *self
    }
    #[inline]
    fn from_fn(mut f: impl FnMut(usize) -> f64) -> Self {
        f(0)
    }
    #[inline]
    fn map(self, f: impl Fn(f64) -> f64) -> Self {
        f(self)
    }
    #[inline]
    fn zip(self, other: Self, f: impl Fn(f64, f64) -> f64) -> Self {
        f(self, other)
    }
    #[inline]
    fn all_finite(&self) -> bool {
        self.is_finite()
    }
}

impl Value for Rgb {
    const CHANNELS: usize = 3;
    #[inline]
    fn zero() -> Self {
        Vector3::zeros()
    }
    #[inline]
    fn channel(&self, i: usize) -> f64 {
        self[i]
    }
    #[inline]
    fn from_fn(mut f: impl FnMut(usize) -> f64) -> Self {
        Vector3::new(f(0), f(1), f(2))
    }
    #[inline]
    fn map(self, f: impl Fn(f64) -> f64) -> Self {
        Vector3::new(f(self.x), f(self.y), f(self.z))
    }
    #[inline]
    fn zip(self, o: Self, f: impl Fn(f64, f64) -> f64) -> Self {
        Vector3::new(f(self.x, o.x), f(self.y, o.y), f(self.z, o.z))
    }
    #[inline]
    fn all_finite(&self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.z.is_finite()
    }
}
