//! Pixels and images of a scene by a supersampling scheme ([`Scheme`]),
//! with the rays they traced by kind.
//!
//! ```
//! use lightquad::domain::Vec3;
//! use lightquad::value::Rgb;
//! use lightquad::whitted::intersect::Shape;
//! use lightquad::whitted::render::{Scheme, render};
//! use lightquad::whitted::scene::{Camera, Material, Object, Scene};
//! use rand::SeedableRng;
//!
//! // An 8 x 6 image of an ambient-lit sphere: W-Corner traces 9 x 7 rays.
//! let ball = Object { shape: Shape::sphere(Vec3::new(0.0, 0.0, -3.0), 1.0)?, material: Material::default() };
//! let cam = Camera::new(Vec3::zeros(), -Vec3::z(), Vec3::y(), 60.0, 8, 6)?;
//! let scene = Scene::new(vec![ball], vec![], Rgb::new(1.0, 1.0, 1.0), Rgb::zeros(), cam, 2)?;
//! let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
//! let out = render(&scene, &Scheme::Corner { m: 1 }, &mut rng)?;
//! assert_eq!(out.rays.primary, 9 * 7);
//! // No lights, no mirrors, nothing transparent: primary rays only.
//! assert_eq!(out.rays.total(), out.rays.primary);
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use crate::domain::Pixel;
use crate::error::QuadError;
use crate::quadrature::{AnyRule, Rule};
use crate::value::{Rgb, Value};

use super::coverage::HalfPlane;
use super::pieces::by_pieces;
use super::pixel;
use super::scene::Scene;
use super::shade::{RayCount, film};

/// How a pixel's integral is estimated ([`super::pixel`]).
#[derive(Debug, Clone, PartialEq)]
pub enum Scheme {
    /// One ray through the centre.
    Centre,
    /// W-SS: the `n x n` grid of cell centres.
    Grid {
        /// Cells per side.
        n: usize,
    },
    /// A rule of the core with `n` evaluations per pixel.
    Rule {
        /// The rule.
        rule: AnyRule,
        /// Its budget per pixel.
        n: usize,
    },
    /// A rule of the core on each piece of the pixel cut along `lines`
    /// ([`super::pieces`]), `n` evaluations per pixel shared between them.
    Pieces {
        /// The rule.
        rule: AnyRule,
        /// Its budget per pixel.
        n: usize,
        /// The film lines to cut along ([`super::pieces::outlines`]).
        lines: Vec<HalfPlane>,
    },
    /// W-Corner with `m x m` cells per pixel (`m = 1`: Whitted's corners).
    Corner {
        /// Subdivisions per pixel side.
        m: usize,
    },
    /// Whitted's adaptive subdivision.
    Adaptive {
        /// The largest corner spread left unsplit.
        threshold: f64,
        /// The deepest split.
        max_level: u32,
    },
}

/// Estimates of a block of pixels.
#[derive(Debug, Clone, PartialEq)]
pub struct Estimated<V: Value> {
    /// The values, rows from the top.
    pub values: Vec<V>,
    /// The rule's error estimate per pixel (infinite for the schemes
    /// without one).
    pub errors: Vec<V>,
    /// False when a rule doubted its estimate for some pixel.
    pub reliable: bool,
    /// True when, in every pixel, a deterministic rule's nodes all gave
    /// the same value with an error estimate of 0
    /// ([`crate::estimate::Estimate::alike`]).
    pub alike: bool,
}

/// The `width x height` pixels from pixel `(i0, j0)` of the film function
/// `f` by `scheme`.
pub fn estimate<V: Value>(
    corner: [usize; 2],
    width: usize,
    height: usize,
    scheme: &Scheme,
    rng: &mut rand_pcg::Pcg64,
    mut f: impl FnMut([f64; 2]) -> V,
) -> Result<Estimated<V>, QuadError> {
    let origin = [corner[0] as f64, corner[1] as f64];
    let unknown = V::from_fn(|_| f64::INFINITY);
    let image_wide = |values: Vec<V>| Estimated {
        errors: vec![unknown; values.len()],
        values,
        reliable: true,
        alike: false,
    };
    match scheme {
        Scheme::Corner { m } => Ok(image_wide(pixel::corner_image(
            origin, width, height, *m, f,
        ))),
        Scheme::Adaptive {
            threshold,
            max_level,
        } => Ok(image_wide(pixel::adaptive_image(
            origin, width, height, *threshold, *max_level, f,
        ))),
        _ => {
            let mut out = Estimated {
                values: Vec::with_capacity(width * height),
                errors: Vec::with_capacity(width * height),
                reliable: true,
                alike: matches!(scheme, Scheme::Rule { .. } | Scheme::Pieces { .. }),
            };
            for j in 0..height {
                for i in 0..width {
                    let p = Pixel::new(origin[0] + i as f64, origin[1] + j as f64, 1.0, 1.0)?;
                    let (v, e) = match scheme {
                        Scheme::Centre => (pixel::centre(&p, &mut f), unknown),
                        Scheme::Grid { n } => (pixel::grid(&p, *n, &mut f), unknown),
                        Scheme::Rule { rule, n } => {
                            let est = pixel::by_rule(rule, &p, *n, rng, &mut f);
                            let est = est.map_err(|e| undefined_ray(e, &p))?;
                            out.reliable &= est.reliable;
                            out.alike &= est.alike;
                            (est.value, est.error)
                        }
                        Scheme::Pieces { rule, n, lines } => {
                            let est = by_pieces(rule, &p, lines, *n, rng, &mut f);
                            let est = est.map_err(|e| undefined_ray(e, &p))?;
                            out.reliable &= est.reliable;
                            out.alike &= est.alike;
                            (est.value, est.error)
                        }
                        Scheme::Corner { .. } | Scheme::Adaptive { .. } => {
                            return Err(QuadError::invalid(
                                "scheme",
                                "an image-wide scheme",
                                "a per-pixel scheme (handled above)",
                            ));
                        }
                    };
                    out.values.push(v);
                    out.errors.push(e);
                }
            }
            Ok(out)
        }
    }
}

/// A ray left undefined by the scene's numbers, said with its pixel.
fn undefined_ray(e: QuadError, pixel: &Pixel) -> QuadError {
    match e {
        QuadError::NonFiniteIntegrand { point, .. } => QuadError::invalid(
            "scene",
            format!(
                "a value that is not a number from the ray through pixel [{}, {}] at {point:?} \
                 of its square",
                pixel.corner()[0],
                pixel.corner()[1]
            ),
            super::experiment::RESOLVED_SCENE,
        ),
        other => other,
    }
}

/// A rendered block and the rays it traced.
#[derive(Debug, Clone, PartialEq)]
pub struct Rendered {
    /// The pixel estimates.
    pub image: Estimated<Rgb>,
    /// The rays traced, by kind.
    pub rays: RayCount,
}

/// The pixels of the block by `scheme`, each ray of W-6.1 counted.
pub fn render_block(
    scene: &Scene,
    corner: [usize; 2],
    width: usize,
    height: usize,
    scheme: &Scheme,
    rng: &mut rand_pcg::Pcg64,
) -> Result<Rendered, QuadError> {
    let mut rays = RayCount::default();
    let image = estimate(corner, width, height, scheme, rng, |p| {
        film(scene, p, &mut rays)
    })?;
    Ok(Rendered { image, rays })
}

/// The whole image by `scheme`.
pub fn render(
    scene: &Scene,
    scheme: &Scheme,
    rng: &mut rand_pcg::Pcg64,
) -> Result<Rendered, QuadError> {
    let cam = &scene.camera;
    render_block(scene, [0, 0], cam.width(), cam.height(), scheme, rng)
}

/// The whole image by `scheme` on rayon's threads, in bands of rows, each
/// band drawing from its own generator seeded by `(seed, band)`: the same
/// image for every thread count. The image-wide schemes (corner rays shared
/// between neighbouring pixels, adaptive subdivision) share rays across band
/// edges and are rendered whole, on one thread.
pub fn render_parallel(scene: &Scene, scheme: &Scheme, seed: u64) -> Result<Rendered, QuadError> {
    use rand::SeedableRng;
    use rayon::prelude::*;
    let cam = &scene.camera;
    let (width, height) = (cam.width(), cam.height());
    if matches!(scheme, Scheme::Corner { .. } | Scheme::Adaptive { .. }) {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
        return render(scene, scheme, &mut rng);
    }
    // Bands of a few rows: enough of them to balance the threads.
    const BAND: usize = 4;
    let parts = (0..height.div_ceil(BAND))
        .into_par_iter()
        .map(|b| {
            let mut rng = rand_pcg::Pcg64::new(u128::from(seed), 2 * b as u128 + 1);
            let rows = BAND.min(height - b * BAND);
            render_block(scene, [0, b * BAND], width, rows, scheme, &mut rng)
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Rendered::joined(parts))
}

impl Rendered {
    /// The blocks of an image, in order, as one: their pixels one after
    /// another, their rays added, reliable when every block is.
    pub fn joined(parts: Vec<Rendered>) -> Rendered {
        let pixels = parts.iter().map(|p| p.image.values.len()).sum();
        let mut rays = RayCount::default();
        let mut image = Estimated {
            values: Vec::with_capacity(pixels),
            errors: Vec::with_capacity(pixels),
            reliable: true,
            alike: !parts.is_empty(),
        };
        for part in parts {
            rays.add(part.rays);
            image.values.extend(part.image.values);
            image.errors.extend(part.image.errors);
            image.reliable &= part.image.reliable;
            image.alike &= part.image.alike;
        }
        Rendered { image, rays }
    }
}

/// The fraction of the block's pixels covered by some object (1 where the
/// primary ray hits, 0 where it escapes), by `scheme`; primary rays counted.
pub fn coverage_block(
    scene: &Scene,
    corner: [usize; 2],
    width: usize,
    height: usize,
    scheme: &Scheme,
    rng: &mut rand_pcg::Pcg64,
) -> Result<(Estimated<f64>, RayCount), QuadError> {
    let mut rays = RayCount::default();
    let est = estimate(corner, width, height, scheme, rng, |p| {
        rays.primary += 1;
        let ray = scene.camera.ray(p);
        if scene.nearest(&ray).is_some() {
            1.0
        } else {
            0.0
        }
    })?;
    Ok((est, rays))
}

/// The rays `scheme` traces per pixel for a scheme with a fixed count (the
/// budget a rule was given; `None` for the image-wide schemes).
pub fn rays_per_pixel(scheme: &Scheme) -> Option<f64> {
    match scheme {
        Scheme::Centre => Some(1.0),
        Scheme::Grid { n } => Some((n * n) as f64),
        Scheme::Rule { rule, n } | Scheme::Pieces { rule, n, .. } => Some(rule.evaluations(*n, 2)),
        Scheme::Corner { .. } | Scheme::Adaptive { .. } => None,
    }
}
