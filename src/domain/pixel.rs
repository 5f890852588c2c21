//! A pixel: the axis-aligned box `[x_0, x_0 + w] x [y_0, y_0 + h]` on the image
//! plane, the domain of supersampling (anti-aliasing).
//!
//! `p(u) = [x_0 + w u_1, y_0 + h u_2]`, `|J| = w h` (constant: the map is
//! affine). Whitted's supersampling schemes are rules over this square: W-SS
//! (a regular grid of samples at cell centres) is the midpoint product rule,
//! W-Corner (samples at the pixel corners, shared with the neighbours) the
//! trapezoid rule.
//!
//! ```
//! use lightquad::domain::{Domain, Pixel, integrate_over};
//! use lightquad::quadrature::GaussLegendre;
//! use rand::SeedableRng;
//!
//! // Box-filtered supersampling of the image f(x, y) = x y over pixel (10, 20):
//! // the pixel value is the mean of f over the pixel, 10.5 * 20.5 for this
//! // bilinear f, which 2 x 2 Gauss–Legendre nodes reproduce exactly.
//! let pixel = Pixel::new(10.0, 20.0, 1.0, 1.0)?;
//! assert_eq!(pixel.centre(), [10.5, 20.5]);
//! let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
//! let est = integrate_over(&GaussLegendre::default(), &pixel, 4, &mut rng, |p: [f64; 2]| p[0] * p[1])?;
//! assert!((est.value / pixel.measure() - 10.5 * 20.5).abs() < 1e-12);
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use super::{Domain, invert_slack, snap_unit};
use crate::error::{QuadError, require_finite, require_positive};

/// The pixel `[x_0, x_0 + w] x [y_0, y_0 + h]` of the image plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pixel {
    x0: f64,
    y0: f64,
    width: f64,
    height: f64,
}

impl Pixel {
    /// The pixel with lower corner `(x0, y0)`, width `width` and height
    /// `height`: corners finite, sizes finite and `> 0`.
    pub fn new(x0: f64, y0: f64, width: f64, height: f64) -> Result<Self, QuadError> {
        require_finite("x0", x0)?;
        require_finite("y0", y0)?;
        require_positive("width", width)?;
        require_positive("height", height)?;
        for (name, lo, size) in [("width", x0, width), ("height", y0, height)] {
            if !(lo + size).is_finite() {
                return Err(QuadError::invalid(
                    name,
                    size,
                    "a size whose far edge is finite",
                ));
            }
        }
        if !(width * height).is_finite() {
            return Err(QuadError::invalid(
                "height",
                height,
                format!("a size whose area with width = {width} is finite"),
            ));
        }
        Ok(Pixel {
            x0,
            y0,
            width,
            height,
        })
    }

    /// The unit square `[0, 1]^2`.
    pub fn unit_square() -> Self {
        Pixel {
            x0: 0.0,
            y0: 0.0,
            width: 1.0,
            height: 1.0,
        }
    }

    /// The lower corner `[x_0, y_0]`.
    pub fn corner(&self) -> [f64; 2] {
        [self.x0, self.y0]
    }

    /// The width `w`.
    pub fn width(&self) -> f64 {
        self.width
    }

    /// The height `h`.
    pub fn height(&self) -> f64 {
        self.height
    }

    /// The centre `[x_0 + w / 2, y_0 + h / 2]`.
    pub fn centre(&self) -> [f64; 2] {
        [self.x0 + 0.5 * self.width, self.y0 + 0.5 * self.height]
    }
}

impl Domain<2> for Pixel {
    type Point = [f64; 2];

    /// `p = [x_0 + w u_1, y_0 + h u_2]`, `|J| = w h`.
    fn map(&self, u: [f64; 2]) -> ([f64; 2], f64) {
        (
            [self.x0 + self.width * u[0], self.y0 + self.height * u[1]],
            self.width * self.height,
        )
    }

    /// `u = [(x - x_0) / w, (y - y_0) / h]`; `None` outside the pixel by more
    /// than the tolerance.
    fn invert(&self, p: &[f64; 2]) -> Option<[f64; 2]> {
        let axis = |x: f64, lo: f64, size: f64| {
            let slack = invert_slack(size, lo.abs() + x.abs());
            snap_unit((x - lo) / size, slack)
        };
        Some([
            axis(p[0], self.x0, self.width)?,
            axis(p[1], self.y0, self.height)?,
        ])
    }

    fn measure(&self) -> f64 {
        self.width * self.height
    }
}
