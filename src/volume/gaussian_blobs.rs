//! A sum of isotropic Gaussian blobs, `v_r(x) = sum_i a_i exp(-|x - c_i|^2 / (2 w_i^2))`,
//! whose line integral has an erf closed form.
//!
//! Along `p + t d` (unit d), `|p + t d - c|^2 = h^2 + (t - t_c)^2` with
//! `t_c = (c - p) . d` and `h` the distance of `c` from the line, so
//!
//! `int_{t0}^{t1} a e^{-|x-c|^2/(2w^2)} dt = a e^{-h^2/(2w^2)} w sqrt(pi/2)
//!     [erf((t1 - t_c)/(w sqrt 2)) - erf((t0 - t_c)/(w sqrt 2))]`,
//!
//! ([`crate::exact::volume::gaussian_line_integral`]). Blobs never vanish: the support is cut at
//! 12 widths, where the density is below `e^-72 = 5e-32` of the peak.
//!
//! ```
//! use std::f64::consts::PI;
//! use lightquad::domain::Vec3;
//! use lightquad::geometry::Ray;
//! use lightquad::volume::{GaussianBlob, GaussianBlobs, Medium};
//!
//! let blobs = GaussianBlobs::new(vec![
//!     GaussianBlob { centre: Vec3::zeros(), amplitude: 2.0, width: 0.5 },
//!     GaussianBlob { centre: Vec3::new(0.0, 1.0, 0.0), amplitude: 1.0, width: 0.25 },
//! ])?;
//! // At the first centre: 2 plus the second blob at distance 1, e^{-1/(2 w^2)} = e^-8.
//! assert!((blobs.density(Vec3::zeros()) - (2.0 + (-8.0f64).exp())).abs() < 1e-15);
//! // A ray through the first centre sees all of it, a w sqrt(2 pi), and the
//! // second at distance h = 1 scaled by e^{-h^2/(2 w^2)}.
//! let ray = Ray::new(Vec3::new(-10.0, 0.0, 0.0), Vec3::x())?;
//! let want = 2.0 * 0.5 * (2.0 * PI).sqrt() + 0.25 * (2.0 * PI).sqrt() * (-8.0f64).exp();
//! let depth = blobs.density_integral(&ray, 0.0, 20.0).ok_or("no closed form")?;
//! assert!((depth - want).abs() < 1e-14);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use super::medium::Medium;
use crate::domain::{Segment, Vec3};
use crate::error::QuadError;
use crate::exact::volume::gaussian_line_integral;
use crate::geometry::{Ray, require_finite_vec};

/// Support radius in widths.
const CUTOFF_WIDTHS: f64 = 12.0;

/// A blob whose width times this is below the length of its piece is cut
/// around its peak (see `support`).
const NARROW: f64 = 64.0;

/// One blob.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GaussianBlob {
    /// Centre `c`.
    pub centre: Vec3,
    /// Peak density `a >= 0`.
    pub amplitude: f64,
    /// Width (standard deviation) `w > 0`.
    pub width: f64,
}

/// The narrowest blob width accepted.
pub const MIN_WIDTH: f64 = 1e-150;

/// The widest blob width accepted.
pub const MAX_WIDTH: f64 = 1e150;

/// A sum of Gaussian blobs.
#[derive(Debug, Clone, PartialEq)]
pub struct GaussianBlobs {
    blobs: Vec<GaussianBlob>,
}

impl GaussianBlobs {
    /// Validates every blob (`blobs[i].amplitude` etc. name the faulty field).
    pub fn new(blobs: Vec<GaussianBlob>) -> Result<Self, QuadError> {
        for (i, b) in blobs.iter().enumerate() {
            require_finite_vec(&format!("blobs[{i}].centre"), b.centre)?;
            if !(b.amplitude.is_finite() && b.amplitude >= 0.0) {
                return Err(QuadError::invalid(
                    format!("blobs[{i}].amplitude"),
                    b.amplitude,
                    "a finite density >= 0",
                ));
            }
            // |x - c|^2 / (2 w^2) must not overflow or divide by an
            // underflowed w^2: a width of 1e200 gave NaN at every node (and
            // 1e-300 a density that is 0 but at the centre).
            if !(b.width.is_finite() && (MIN_WIDTH..=MAX_WIDTH).contains(&b.width)) {
                return Err(QuadError::invalid(
                    format!("blobs[{i}].width"),
                    b.width,
                    format!(
                        "a width in [{MIN_WIDTH:e}, {MAX_WIDTH:e}] (its square is then a normal number)"
                    ),
                ));
            }
        }
        Ok(GaussianBlobs { blobs })
    }

    /// The blobs.
    pub fn blobs(&self) -> &[GaussianBlob] {
        &self.blobs
    }
}

impl Medium for GaussianBlobs {
    fn name(&self) -> &'static str {
        "gaussian-blobs"
    }

    /// One term per blob.
    fn lookup_work(&self) -> f64 {
        self.blobs.len().max(1) as f64
    }

    fn density(&self, p: Vec3) -> f64 {
        self.blobs
            .iter()
            .map(|b| {
                b.amplitude * (-(p - b.centre).norm_squared() / (2.0 * b.width * b.width)).exp()
            })
            .sum()
    }

    /// The union of the blobs' 12-width balls along the ray: overlapping
    /// intervals are merged (the density is smooth across them).
    fn support(&self, ray: &Ray, t_min: f64, t_max: f64) -> Vec<Segment> {
        let mut spans: Vec<(f64, f64)> = self
            .blobs
            .iter()
            .filter_map(|b| {
                let ball = crate::geometry::Sphere {
                    centre: b.centre,
                    radius: CUTOFF_WIDTHS * b.width,
                };
                ball.clip(ray, t_min, t_max)
            })
            .collect();
        spans.sort_by(|x, y| x.0.total_cmp(&y.0));
        let mut merged: Vec<(f64, f64)> = Vec::new();
        for (a, b) in spans {
            match merged.last_mut() {
                Some(last) if a <= last.1 => last.1 = last.1.max(b),
                _ => merged.push((a, b)),
            }
        }
        // A blob much narrower than the piece it lies in is a spike that a
        // rule's nodes (an adaptive rule's first panel included) can step
        // over entirely: cut the piece at the blob's peak along the ray and
        // at 2 and 8 widths either side, so each spike gets pieces of its
        // own scale. (Along a line the blob is a Gaussian in t of the same
        // width: |r(t) - c|^2 = (t - t_c)^2 + b^2.)
        merged
            .into_iter()
            .filter_map(|(a, b)| {
                let cuts = self
                    .blobs
                    .iter()
                    .filter(|blob| blob.width * NARROW < b - a)
                    .flat_map(|blob| {
                        let t_c = (blob.centre - ray.origin).dot(&ray.dir);
                        [-8.0, -2.0, 0.0, 2.0, 8.0].map(|k| t_c + k * blob.width)
                    })
                    .filter(|&t| a < t && t < b)
                    .collect();
                Segment::with_breaks(a, b, cuts).ok()
            })
            .collect()
    }

    /// The sum of each blob's largest value on the chord.
    /// The mean of the blobs' centres.
    fn centre(&self) -> Option<Vec3> {
        let n = self.blobs.len();
        (n > 0).then(|| self.blobs.iter().map(|b| b.centre).sum::<Vec3>() / n as f64)
    }

    fn max_density(&self, ray: &Ray, t0: f64, t1: f64) -> f64 {
        self.blobs
            .iter()
            .map(|b| {
                let tc = (b.centre - ray.origin).dot(&ray.dir).clamp(t0, t1);
                b.amplitude
                    * (-(ray.at(tc) - b.centre).norm_squared() / (2.0 * b.width * b.width)).exp()
            })
            .sum()
    }

    /// Each blob's smaller value at the two ends (along a line a Gaussian
    /// blob is a Gaussian in `t`, whose least value over an interval is at
    /// an end), summed, less 1e-9 of it: a margin for rounding, not a proof
    /// (a bound for the cost estimate of tracking, not for a look-up).
    fn min_density(&self, ray: &Ray, t0: f64, t1: f64) -> f64 {
        if !(t0.is_finite() && t1.is_finite()) {
            return 0.0;
        }
        let (p0, p1) = (ray.at(t0), ray.at(t1));
        let least: f64 = self
            .blobs
            .iter()
            .map(|b| {
                let far = (p0 - b.centre)
                    .norm_squared()
                    .max((p1 - b.centre).norm_squared());
                b.amplitude * (-far / (2.0 * b.width * b.width)).exp()
            })
            .sum();
        least * (1.0 - 1e-9)
    }

    /// The erf closed form, [`crate::exact::volume::gaussian_line_integral`].
    fn density_integral(&self, ray: &Ray, t0: f64, t1: f64) -> Option<f64> {
        Some(
            self.blobs
                .iter()
                .map(|b| {
                    b.amplitude
                        * gaussian_line_integral(b.centre, b.width, ray.origin, ray.dir, t0, t1)
                })
                .sum(),
        )
    }
}
