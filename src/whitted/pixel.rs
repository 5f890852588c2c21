//! A pixel's value as an integral over its square (box filter), and the
//! schemes that estimate it: Whitted's supersampling read as quadrature.
//!
//! With `L(x, y)` the intensity seen through film point `(x, y)` (one ray),
//! pixel `(i, j)`, the square `P = [i, i + 1] x [j, j + 1]`, has the value
//!
//! `I_P = (1 / |P|) int_P L(x, y) dx dy`  (box filter).
//!
//! | scheme | points | as quadrature | rays |
//! |---|---|---|---|
//! | [`centre`] | the pixel's centre | 1-point midpoint rule | 1 per pixel |
//! | [`grid`] | W-SS: the centres of an `n x n` grid of cells, the mean | midpoint product rule | `n^2` per pixel |
//! | [`by_rule`] | any rule of the core over the [`Pixel`] domain: `stratified` is jittered sampling, `sobol` scrambled low-discrepancy points, `gauss-legendre`, ... | the rule | the rule's |
//! | [`corner_image`] | W-Corner: the pixel's corners, shared with its neighbours, the mean of four; with `m` subdivisions the corners of an `m x m` grid per pixel | composite trapezoid rule over the image | `(s m + 1)(z m + 1)` for `s x z` pixels |
//! | [`adaptive_image`] | Whitted's adaptive subdivision: corners; a square whose corner values differ by more than a threshold split in four, recursively to a depth, every point shared | adaptive trapezoid rule | what the image needs |
//!
//! Every scheme takes `L` as a closure on film coordinates, so the rays are
//! counted by wrapping it.
//!
//! ```
//! use lightquad::domain::Pixel;
//! use lightquad::whitted::pixel::{corner_image, grid};
//!
//! // W-Corner on a 4 x 3 image traces (4 + 1)(3 + 1) = 20 rays.
//! let mut rays = 0;
//! let image = corner_image([0.0, 0.0], 4, 3, 1, |p: [f64; 2]| { rays += 1; p[0] + p[1] });
//! assert_eq!((rays, image.len()), (20, 12));
//! // A linear L is integrated exactly by both: pixel (1, 2) has mean 1.5 + 2.5.
//! assert_eq!(image[2 * 4 + 1], 4.0);
//! let pixel = Pixel::new(1.0, 2.0, 1.0, 1.0)?;
//! assert_eq!(grid(&pixel, 3, |p: [f64; 2]| p[0] + p[1]), 4.0);
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use std::collections::HashMap;

use crate::domain::{Domain, Pixel, integrate_over};
use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::quadrature::{Rule, Sobol, Stratified};
use crate::sum::Compensated;
use crate::value::Value;

/// The deepest level of [`adaptive_image`]: `2^12` subdivisions per pixel
/// side.
pub const MAX_LEVEL: u32 = 12;

/// The mean of `values`.
fn mean<V: Value>(values: &[V]) -> V {
    let inv = 1.0 / values.len() as f64;
    let mut sum = Compensated::<V>::new();
    for v in values {
        sum.add(*v);
    }
    sum.total().map(|x| x * inv)
}

/// One ray through the pixel's centre: `I_P ~ L(c)`.
pub fn centre<V: Value>(pixel: &Pixel, mut f: impl FnMut([f64; 2]) -> V) -> V {
    f(pixel.centre())
}

/// W-SS: the mean of `L` at the centres of an `n x n` grid of equal cells,
/// `I_P ~ (1 / n^2) sum_(a, b) L(x_0 + (a + 1/2) w / n, y_0 + (b + 1/2) h /
/// n)` (the midpoint product rule; `n = 3` is the document's 3 x 3).
pub fn grid<V: Value>(pixel: &Pixel, n: usize, mut f: impl FnMut([f64; 2]) -> V) -> V {
    let n = n.max(1);
    let [x0, y0] = pixel.corner();
    let (w, h) = (pixel.width() / n as f64, pixel.height() / n as f64);
    // Compensated: a pixel of 4096 rays that hit and miss sums to its exact
    // mean (a plain sum of 1024 hits of 0.4 in 4096 gave 0.09999999999999849
    // for 0.1, which W-Grey shows one step lower).
    let mut sum = Compensated::<V>::new();
    for b in 0..n {
        for a in 0..n {
            let p = [x0 + (a as f64 + 0.5) * w, y0 + (b as f64 + 0.5) * h];
            sum.add(f(p));
        }
    }
    sum.total().map(|s| s / (n * n) as f64)
}

/// `I_P` by any rule of the core with a budget of `n` rays over the
/// [`Pixel`] domain: `(1 / |P|) int_[0,1]^2 L(p(u)) |J| du`.
pub fn by_rule<R: Rule, V: Value>(
    rule: &R,
    pixel: &Pixel,
    n: usize,
    rng: &mut rand_pcg::Pcg64,
    f: impl FnMut([f64; 2]) -> V,
) -> Result<Estimate<V>, QuadError> {
    Ok(integrate_over(rule, pixel, n, rng, f)?.scaled(1.0 / pixel.measure()))
}

/// Jittered sampling: one uniform sample in each cell of an `n x n` grid
/// (the core's `stratified` rule).
pub fn jittered<V: Value>(
    pixel: &Pixel,
    n: usize,
    rng: &mut rand_pcg::Pcg64,
    f: impl FnMut([f64; 2]) -> V,
) -> Result<Estimate<V>, QuadError> {
    by_rule(&Stratified, pixel, n * n, rng, f)
}

/// Scrambled low-discrepancy sampling: `n` Owen-scrambled Sobol' points
/// (the core's `sobol` rule, its default 8 scrambles).
pub fn low_discrepancy<V: Value>(
    pixel: &Pixel,
    n: usize,
    rng: &mut rand_pcg::Pcg64,
    f: impl FnMut([f64; 2]) -> V,
) -> Result<Estimate<V>, QuadError> {
    by_rule(&Sobol::default(), pixel, n, rng, f)
}

/// W-Corner over a `width x height` image whose top-left pixel has its
/// corner at `origin`: `L` at the corners of an `m x m` grid in every
/// pixel, each corner traced once and shared with the neighbours; the pixel
/// value is the composite trapezoid rule over its square (for `m = 1` the
/// mean of its four corners). Pixels in rows, `j * width + i`.
pub fn corner_image<V: Value>(
    origin: [f64; 2],
    width: usize,
    height: usize,
    m: usize,
    mut f: impl FnMut([f64; 2]) -> V,
) -> Vec<V> {
    let m = m.max(1);
    let (cols, rows) = (width * m + 1, height * m + 1);
    let step = 1.0 / m as f64;
    let mut lattice = Vec::with_capacity(cols * rows);
    for b in 0..rows {
        for a in 0..cols {
            lattice.push(f([
                origin[0] + a as f64 * step,
                origin[1] + b as f64 * step,
            ]));
        }
    }
    // Trapezoid weights 1/2 at a pixel's edges, 1 inside, over m^2 cells.
    let weight = |k: usize| if k == 0 || k == m { 0.5 } else { 1.0 };
    let norm = 1.0 / (m * m) as f64;
    let mut image = Vec::with_capacity(width * height);
    for j in 0..height {
        for i in 0..width {
            let mut sum = Compensated::<V>::new();
            for b in 0..=m {
                for a in 0..=m {
                    let v = lattice[(j * m + b) * cols + i * m + a];
                    let w = weight(a) * weight(b) * norm;
                    sum.add(v.map(|v| w * v));
                }
            }
            image.push(sum.total());
        }
    }
    image
}

/// Whitted's adaptive subdivision over a `width x height` image at
/// `origin`: each pixel starts as the mean of its four corners; a square
/// whose corner values differ by more than `threshold` in some channel
/// (`max - min`) is split into four, down to `max_level` splits (at most
/// [`MAX_LEVEL`]), and its value is the mean of its quarters'. Every point
/// is traced once and shared by the squares and pixels that meet there.
pub fn adaptive_image<V: Value>(
    origin: [f64; 2],
    width: usize,
    height: usize,
    threshold: f64,
    max_level: u32,
    f: impl FnMut([f64; 2]) -> V,
) -> Vec<V> {
    let level = max_level.min(MAX_LEVEL);
    let mut grid = Lattice {
        origin,
        scale: 1u64 << level,
        seen: HashMap::new(),
        f,
    };
    let size = grid.scale;
    let mut image = Vec::with_capacity(width * height);
    for j in 0..height as u64 {
        for i in 0..width as u64 {
            image.push(grid.square(i * size, j * size, size, threshold));
        }
    }
    image
}

/// The shared points of [`adaptive_image`], on a lattice of `scale` points
/// per pixel side.
struct Lattice<V, F> {
    origin: [f64; 2],
    scale: u64,
    seen: HashMap<(u64, u64), V>,
    f: F,
}

impl<V: Value, F: FnMut([f64; 2]) -> V> Lattice<V, F> {
    /// `L` at lattice point `(a, b)`, traced once.
    fn at(&mut self, a: u64, b: u64) -> V {
        if let Some(v) = self.seen.get(&(a, b)) {
            return *v;
        }
        let s = self.scale as f64;
        let v = (self.f)([self.origin[0] + a as f64 / s, self.origin[1] + b as f64 / s]);
        self.seen.insert((a, b), v);
        v
    }

    /// The value of the square of `size` lattice steps at `(a, b)`.
    fn square(&mut self, a: u64, b: u64, size: u64, threshold: f64) -> V {
        let corners = [
            self.at(a, b),
            self.at(a + size, b),
            self.at(a, b + size),
            self.at(a + size, b + size),
        ];
        let spread = (0..V::CHANNELS)
            .map(|c| {
                let (lo, hi) = corners
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
                        (l.min(v.channel(c)), h.max(v.channel(c)))
                    });
                hi - lo
            })
            .fold(0.0, f64::max);
        if spread <= threshold || size == 1 {
            return mean(&corners);
        }
        let half = size / 2;
        let quarters = [
            self.square(a, b, half, threshold),
            self.square(a + half, b, half, threshold),
            self.square(a, b + half, half, threshold),
            self.square(a + half, b + half, half, threshold),
        ];
        mean(&quarters)
    }
}
