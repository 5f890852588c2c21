//! Rays and spheres, with ray–sphere roots that stay accurate for grazing
//! rays, origins on or near the surface, and coordinates scaled by 1e-6 or 1e6.
//!
//! ```
//! use lightquad::domain::Vec3;
//! use lightquad::geometry::{Ray, Sphere};
//!
//! // A ray at height 0.6 through a unit sphere: the chord is 2 sqrt(1 - 0.36) = 1.6.
//! let ray = Ray::new(Vec3::new(-3.0, 0.6, 0.0), Vec3::new(2.0, 0.0, 0.0))?;
//! let sphere = Sphere::new(Vec3::zeros(), 1.0)?;
//! let (t0, t1) = sphere.clip(&ray, 0.0, f64::INFINITY).expect("hits");
//! assert!((t1 - t0 - 1.6).abs() < 1e-12);
//! assert!((ray.at(t0) - Vec3::new(-0.8, 0.6, 0.0)).norm() < 1e-12);
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use crate::domain::Vec3;
use crate::error::QuadError;

/// A ray `r(t) = origin + t d` with a unit direction `d`, so `t` is arc length.
///
/// The documents write `r(t) = e + t v` with any `v`; [`Ray::new`] normalises
/// `v`, so every `t` here is a distance and optical depths need no `|v|` factor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    /// The origin `e`.
    pub origin: Vec3,
    /// The unit direction.
    pub dir: Vec3,
}

/// Checks that every component of `v` is finite, naming `name`.
pub fn require_finite_vec(name: &str, v: Vec3) -> Result<Vec3, QuadError> {
    if v.iter().all(|c| c.is_finite()) {
        Ok(v)
    } else {
        Err(QuadError::invalid(
            name,
            format!("{:?}", v.as_slice()),
            "a vector of finite numbers",
        ))
    }
}

/// `|v|` without overflow or underflow for components near 1e±308
/// (scaled by the largest component first).
pub fn norm(v: Vec3) -> f64 {
    let scale = v.amax();
    if scale == 0.0 || !scale.is_finite() {
        return scale;
    }
    scale * (v / scale).norm()
}

/// `v / |v|`, or an error naming `name` for a zero or non-finite vector.
/// The length is taken after scaling by the largest component, so vectors of
/// size 1e-300 or 1e300 normalise without under- or overflow.
pub fn normalize(name: &str, v: Vec3) -> Result<Vec3, QuadError> {
    require_finite_vec(name, v)?;
    let scale = v.amax();
    if scale == 0.0 {
        return Err(QuadError::invalid(
            name,
            format!("{:?}", v.as_slice()),
            "a non-zero direction",
        ));
    }
    let w = v / scale;
    Ok(w / w.norm())
}

impl Ray {
    /// A ray from `origin` along `direction` (normalised; must be non-zero).
    pub fn new(origin: Vec3, direction: Vec3) -> Result<Ray, QuadError> {
        Ok(Ray {
            origin: require_finite_vec("origin", origin)?,
            dir: normalize("direction", direction)?,
        })
    }

    /// The point at distance `t`.
    #[inline]
    pub fn at(&self, t: f64) -> Vec3 {
        self.origin + self.dir * t
    }
}

/// The smallest sphere radius, the smallest normal f64 (about 2.2e-308).
pub const MIN_RADIUS: f64 = f64::MIN_POSITIVE;

/// The largest power of two at most `x` (finite, > 0), exactly, for normal
/// and subnormal `x` alike (`2f64.powi(-1030)` is 0: the reciprocal of
/// `2^1030` overflows).
fn power_of_two_below(x: f64) -> f64 {
    let bits = x.to_bits();
    let exponent = bits >> 52;
    if exponent == 0 {
        // Subnormal: the highest mantissa bit.
        f64::from_bits(1u64 << (63 - bits.leading_zeros()))
    } else {
        f64::from_bits(exponent << 52)
    }
}

/// A sphere `|p - centre| = radius`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sphere {
    /// Centre.
    pub centre: Vec3,
    /// Radius, > 0.
    pub radius: f64,
}

impl Sphere {
    /// A sphere; the radius must be a finite positive normal number, from
    /// [`MIN_RADIUS`] to `f64::MAX`: a subnormal radius (1e-310) has fewer
    /// digits than a parameter along its chord needs, and its chord came out
    /// as `(-inf, inf)` (a closed-form `ln tau` of `-inf`).
    pub fn new(centre: Vec3, radius: f64) -> Result<Sphere, QuadError> {
        require_finite_vec("centre", centre)?;
        if !(radius.is_finite() && radius >= MIN_RADIUS) {
            return Err(QuadError::invalid(
                "radius",
                radius,
                format!(
                    "a finite number in [{MIN_RADIUS:e}, {:e}] (a normal f64: a subnormal radius \
                     has too few digits for the points of its chord)",
                    f64::MAX
                ),
            ));
        }
        Ok(Sphere { centre, radius })
    }

    /// The chord of a line through the sphere: the parameters `t0 <= t1` where
    /// `p + t d` (unit `d`) meets the sphere, or `None` when it misses.
    ///
    /// `|f + t d|^2 = R^2` with `f = p - c` has `t = -b +- sqrt(R^2 - h^2)`,
    /// `b = f . d`. The radicand is formed as `(R - h)(R + h)` from the distance
    /// `h = |f - b d|` of the centre to the line, not as `b^2 - (|f|^2 - R^2)`,
    /// which cancels catastrophically for grazing rays and far origins
    /// (Haines et al., "Precision improvements for ray/sphere intersection",
    /// Ray Tracing Gems, 2019). The smaller-magnitude root comes from
    /// `t_0 t_1 = |f|^2 - R^2`, not from a difference, with the product formed
    /// as `(|b| - root)(|b| + root)` where `|b| < R` and as `(|f| - R)(|f| + R)`
    /// beyond: each is accurate where the other loses digits.
    ///
    /// Lengths are scaled by the power of two nearest below `max(R, |f|)`
    /// first (exactly), so radii up to 1e308 neither overflow in the products
    /// nor underflow near 1e-308. The roots are parameters along the line,
    /// each with a rounding error of about `eps |t|`: a chord shorter than
    /// that (a sphere of radius 1e-150 seen from a distance of 3, where the
    /// doubles are 4.4e-16 apart) has `t0 == t1`, and [`Sphere::clip`] finds
    /// it empty. Measure such a chord from an origin near the sphere (as
    /// `VolumeScene::anchored` does).
    pub fn line_roots(&self, p: Vec3, d: Vec3) -> Option<(f64, f64)> {
        let f0 = p - self.centre;
        let size = self.radius.max(f0.amax());
        if !(size.is_finite() && size > 0.0) {
            return None;
        }
        // A power of two, so the scaling itself is exact.
        let scale = power_of_two_below(size);
        let f = f0 / scale;
        let r = self.radius / scale;
        let b = f.dot(&d);
        let h = (f - d * b).norm();
        if h > r {
            return None;
        }
        let root = ((r - h) * (r + h)).sqrt();
        // q has the sign of -b, so no cancellation in -b -+ root.
        let q = if b > 0.0 { -b - root } else { -b + root };
        // The product of the roots, |f|^2 - r^2 = b^2 - root^2, two ways: as
        // (|b| - root)(|b| + root) its error is ~eps max(|b|, root)^2, as
        // (|f| - r)(|f| + r) ~eps r^2. The first wins where |b| < r (a line
        // that grazes the sphere, an origin near its surface: the shadow rays
        // of a grazing eye ray), the second for far origins.
        let c = if b.abs() < r {
            (b.abs() - root) * (b.abs() + root)
        } else {
            let norm = f.norm();
            (norm - r) * (norm + r)
        };
        let (a, other) = if q != 0.0 { (q, c / q) } else { (root, -root) };
        Some((a.min(other) * scale, a.max(other) * scale))
    }

    /// The part `[t_near, t_far]` of `[t_min, t_max]` along `ray` inside the
    /// sphere, or `None` when the ray misses it there.
    pub fn clip(&self, ray: &Ray, t_min: f64, t_max: f64) -> Option<(f64, f64)> {
        let (t0, t1) = self.line_roots(ray.origin, ray.dir)?;
        let (a, b) = (t0.max(t_min), t1.min(t_max));
        (a < b).then_some((a, b))
    }

    /// Distance from `p` (inside or on the sphere) to the boundary along the
    /// unit direction `d`: the positive root `s(p)` of `|p + s d - c|^2 = R^2`
    /// (docs/EQUATIONS.md, V-Lp, as corrected in audit point 1). Zero for a
    /// point outside the sphere.
    pub fn exit_distance(&self, p: Vec3, d: Vec3) -> f64 {
        if norm(p - self.centre) > self.radius {
            return 0.0;
        }
        match self.line_roots(p, d) {
            Some((_, t1)) => t1.max(0.0),
            None => 0.0,
        }
    }
}
