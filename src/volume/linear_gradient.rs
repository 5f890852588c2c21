//! A sphere whose density varies linearly, clipped at zero:
//! `v_r(x) = max(0, b + g . (x - c))` for `|x - c| <= R`, 0 outside.
//!
//! Along `p + t d` (unit d) write `t_c = (c - p) . d` for the parameter of the
//! point closest to the centre and `q = p + t_c d - c` for its offset from the
//! centre (`|q| <= R` on a chord). Then
//!
//! `b + g . (p + t d - c) = gamma + beta (t - t_c)`, `gamma = b + g . q`,
//! `beta = g . d`,
//!
//! a linear function of `t` whose constant term is bounded by `|b| + |g| R`
//! however far the origin is. It vanishes at `t_z = t_c - gamma / beta`, where
//! the density has a kink; the support is the sphere chord cut there, keeping
//! the side where the linear function is positive, so every piece the
//! quadrature sees is linear and Gauss–Legendre with 2 nodes is exact. The
//! line integral over a piece `[a, b]` is the length times the midpoint value,
//!
//! `int_a^b v_r dt = (b - a) (gamma + beta ((a + b)/2 - t_c))`.
//!
//! ```
//! use lightquad::domain::Vec3;
//! use lightquad::geometry::Ray;
//! use lightquad::quadrature::GaussLegendre;
//! use lightquad::volume::{LinearGradient, Medium};
//! use rand::SeedableRng;
//!
//! // v = max(0, 1 + 2x) in the unit sphere. Along the x axis it is zero up to
//! // x = -1/2 and linear after it: int v dx = [x + x^2] from -1/2 to 1 = 9/4.
//! let medium = LinearGradient::new(Vec3::zeros(), 1.0, 1.0, Vec3::new(2.0, 0.0, 0.0))?;
//! let ray = Ray::new(Vec3::new(-3.0, 0.0, 0.0), Vec3::x())?; // x = t - 3
//! let support = medium.support(&ray, 0.0, 10.0);
//! assert_eq!(support.len(), 1); // cut at the kink t = 2.5, ends at the sphere
//! assert!((support[0].start() - 2.5).abs() < 1e-15 && (support[0].end() - 4.0).abs() < 1e-15);
//! let closed = medium.density_integral(&ray, 0.0, 10.0).ok_or("no closed form")?;
//! assert!((closed - 2.25).abs() < 1e-14);
//! // Linear on its piece, so 2 Gauss–Legendre nodes are exact.
//! let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
//! let gl = support[0].integrate(&GaussLegendre::default(), 2, &mut rng, |t| medium.density(ray.at(t)))?;
//! assert!((gl.value - 2.25).abs() < 1e-14);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use super::medium::Medium;
use crate::domain::{Segment, Vec3};
use crate::error::QuadError;
use crate::geometry::{Ray, Sphere, require_finite_vec};

/// `v_r = max(0, base + gradient . (x - centre))` inside the sphere, 0 outside.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearGradient {
    /// The sphere (its centre is the reference point of the linear function).
    pub sphere: Sphere,
    /// The linear function's value `b` at the centre (any sign: a negative
    /// base leaves only the part of the sphere where the gradient lifts it).
    pub base: f64,
    /// The gradient `g`.
    pub gradient: Vec3,
}

/// The linear function along a ray: `gamma + beta (t - t_c)`.
#[derive(Debug, Clone, Copy)]
struct Along {
    /// Parameter of the point closest to the centre.
    t_c: f64,
    /// Value at `t_c`.
    gamma: f64,
    /// Slope `g . d`.
    beta: f64,
}

impl Along {
    /// `gamma + beta (t - t_c)`.
    fn at(&self, t: f64) -> f64 {
        self.gamma + self.beta * (t - self.t_c)
    }
}

impl LinearGradient {
    /// A linear-gradient sphere; `base` finite, `gradient` finite (the sphere
    /// checks `centre` and `radius`).
    pub fn new(centre: Vec3, radius: f64, base: f64, gradient: Vec3) -> Result<Self, QuadError> {
        let sphere = Sphere::new(centre, radius)?;
        if !base.is_finite() {
            return Err(QuadError::invalid("base", base, "a finite number"));
        }
        require_finite_vec("gradient", gradient)?;
        Ok(LinearGradient {
            sphere,
            base,
            gradient,
        })
    }

    /// The linear function `b + g . (x - c)` without the clip at zero.
    pub fn linear(&self, p: Vec3) -> f64 {
        self.base + self.gradient.dot(&(p - self.sphere.centre))
    }

    /// The rounding allowance of the density bounds, `16 eps (|b| + |g| (|c|
    /// + 2 R))`: evaluating `b + g . (x - c)` in the sphere rounds by a few
    /// ulps of that scale. `|g|` and `|c|` are taken scaled by their largest
    /// component, so a gradient of 1e300 gives 1e300, not the infinity of
    /// `sqrt(1e600)` (which made the depth bound at lambda = 0 NaN), and
    /// `16 eps` multiplies before the products.
    fn rounding_margin(&self) -> f64 {
        let norm = |v: Vec3| {
            let m = v.amax();
            if m > 0.0 && m.is_finite() {
                m * (v / m).norm()
            } else {
                m
            }
        };
        // Each product taken after the factor 16 eps, so a margin of a finite
        // density stays finite (|g| = 1e308 times 2 R overflowed).
        let e = 16.0 * f64::EPSILON;
        e * self.base.abs()
            + (e * norm(self.gradient)) * (norm(self.sphere.centre) + 2.0 * self.sphere.radius)
    }

    /// The linear function along `ray`, centred at its closest approach.
    fn along(&self, ray: &Ray) -> Along {
        let t_c = (self.sphere.centre - ray.origin).dot(&ray.dir);
        let q = ray.at(t_c) - self.sphere.centre;
        Along {
            t_c,
            gamma: self.base + self.gradient.dot(&q),
            beta: self.gradient.dot(&ray.dir),
        }
    }

    /// The part of `[t_min, t_max]` inside the sphere where the linear function
    /// is positive, with the function along the ray; `None` when empty.
    fn positive_chord(&self, ray: &Ray, t_min: f64, t_max: f64) -> Option<(f64, f64, Along)> {
        let (a, b) = self.sphere.clip(ray, t_min, t_max)?;
        let f = self.along(ray);
        let (lo, hi) = if f.beta == 0.0 {
            if f.gamma > 0.0 {
                (a, b)
            } else {
                return None;
            }
        } else {
            // The zero crossing (a kink of the density); +-inf when gamma/beta
            // overflows, which min/max handle.
            let t_z = f.t_c - f.gamma / f.beta;
            if f.beta > 0.0 {
                (a.max(t_z), b)
            } else {
                (a, b.min(t_z))
            }
        };
        (lo < hi).then_some((lo, hi, f))
    }
}

impl Medium for LinearGradient {
    fn name(&self) -> &'static str {
        "linear-gradient"
    }

    fn density(&self, p: Vec3) -> f64 {
        if (p - self.sphere.centre).norm() <= self.sphere.radius {
            self.linear(p).max(0.0)
        } else {
            0.0
        }
    }

    /// On the piece inside the sphere where the linear function is positive,
    /// that function (clamped at 0 only against rounding at the zero
    /// crossing); 0 on any other piece.
    fn density_on(&self, p: Vec3, inside: Vec3) -> f64 {
        if self.density(inside) > 0.0 {
            self.linear(p).max(0.0)
        } else {
            0.0
        }
    }

    /// The sphere chord cut at the zero crossing of the linear function, on
    /// the side where it is positive: one linear piece, or none. The kink is an
    /// end of the support, so no piece contains it.
    fn support(&self, ray: &Ray, t_min: f64, t_max: f64) -> Vec<Segment> {
        self.positive_chord(ray, t_min, t_max)
            .and_then(|(a, b, _)| Segment::new(a, b).ok())
            .into_iter()
            .collect()
    }

    /// On the positive piece the density is `gamma + beta (t - t_c)`, so it
    /// crosses `level` once, at `t = t_c + (level - gamma) / beta`, when that
    /// lies inside `(lo, hi)`; never when `beta = 0`. A piece of zero density
    /// crosses no positive level.
    fn level_crossings(
        &self,
        ray: &Ray,
        lo: f64,
        hi: f64,
        inside: Vec3,
        level: f64,
    ) -> Option<Vec<f64>> {
        let f = self.along(ray);
        if self.density(inside) <= 0.0 || f.beta == 0.0 {
            return Some(Vec::new());
        }
        let t = f.t_c + (level - f.gamma) / f.beta;
        Some((lo < t && t < hi).then_some(t).into_iter().collect())
    }

    /// The larger value of the linear function at the two ends of the chord
    /// inside `[t0, t1]` (a linear function peaks at an end), clamped at 0,
    /// plus a rounding margin `16 eps (|b| + |g| (|c| + 2R))` so that the
    /// computed density never exceeds it; 0 where the ray misses the sphere.
    fn centre(&self) -> Option<Vec3> {
        Some(self.sphere.centre)
    }

    fn max_density(&self, ray: &Ray, t0: f64, t1: f64) -> f64 {
        let Some((a, b)) = self.sphere.clip(ray, t0, t1) else {
            return 0.0;
        };
        let peak = self.linear(ray.at(a)).max(self.linear(ray.at(b)));
        peak.max(0.0) + self.rounding_margin()
    }

    /// The smaller end value of the linear function (it is linear along the
    /// ray) where `[t0, t1]` lies inside the sphere, less the rounding
    /// margin `16 eps (|b| + |g| (|c| + 2 R))` that `max_density` adds,
    /// floored at 0; else 0.
    fn min_density(&self, ray: &Ray, t0: f64, t1: f64) -> f64 {
        if self.sphere.clip(ray, t0, t1) != Some((t0, t1)) {
            return 0.0;
        }
        let low = self.linear(ray.at(t0)).min(self.linear(ray.at(t1)));
        (low - self.rounding_margin()).max(0.0)
    }

    /// `(b - a)` times the value at the midpoint of the positive chord `[a, b]`
    /// (the integral of a linear function), 0 where there is none.
    fn density_integral(&self, ray: &Ray, t0: f64, t1: f64) -> Option<f64> {
        Some(
            self.positive_chord(ray, t0, t1)
                .map_or(0.0, |(a, b, f)| (b - a) * f.at(0.5 * (a + b)).max(0.0)),
        )
    }
}
