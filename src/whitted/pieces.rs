//! A pixel cut into pieces along the scene's outlines on the film, so that
//! a rule integrating each piece samples every part of the pixel, however
//! thin: the converged reference's way past coverage slivers that an
//! adaptive rule over the whole square never sees.
//!
//! The cuts ([`outlines`]) are the film lines of every straight outline
//! (each triangle edge: the plane through the eye and the edge; each plane's
//! horizon: the plane through the eye parallel to it) and the four lines
//! bounding each sphere's outline ([`super::scene::Camera::sphere_bounds`]). Between the
//! straight cuts the set of film points whose ray meets a triangle or a
//! plane is constant, so coverage is constant on a piece; a sphere's curved
//! outline lies in the pieces inside its bounding lines, where it covers a
//! share of at least `pi / 4` of the box and a rule converges algebraically.
//!
//! Each piece is convex (the square clipped by half-planes) and is
//! integrated as a fan of triangles `(v_0, v_k, v_(k+1))`, each by the
//! collapsed-square map of [`crate::domain::Triangle`],
//! `p(u) = a + u_1 (b - a) + u_1 u_2 (c - b)`, `|J| = u_1 |(b - a) x (c - b)|`.
//!
//! ```
//! use lightquad::domain::Pixel;
//! use lightquad::whitted::coverage::HalfPlane;
//! use lightquad::whitted::pieces::{by_pieces, pieces};
//! use lightquad::quadrature::GaussLegendre;
//! use rand::SeedableRng;
//!
//! // A plane's edge parallel to the pixel's left side, a millionth inside:
//! // the covered sliver is a piece of its own, and the integral finds it.
//! let pixel = Pixel::new(3.0, 2.0, 1.0, 1.0)?;
//! let edge = HalfPlane { a: 1.0, b: 0.0, c: 3.0 + 1e-6 };
//! assert_eq!(pieces(&pixel, &[edge], 64).0.len(), 2);
//! let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
//! let covered = |p: [f64; 2]| if edge.side(p) <= 0.0 { 1.0 } else { 0.0 };
//! let est = by_pieces(&GaussLegendre::default(), &pixel, &[edge], 64, &mut rng, covered)?;
//! assert!((est.value / 1e-6 - 1.0).abs() < 1e-9, "{}", est.value);
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use crate::domain::Pixel;
use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::quadrature::Rule;
use crate::value::Value;

use super::coverage::{HalfPlane, area, clip};
use super::intersect::Shape;
use super::scene::Scene;

/// The most pieces a pixel is cut into: cuts beyond it are left out and
/// the estimate doubted ([`Estimate::reliable`] false). 2048 keeps 25
/// small triangles in one pixel exact (75 cut lines); 49 of them (147
/// lines) pass it, and their coverage reference is then 1.7% off, marked
/// not converged.
pub const MAX_PIECES: usize = 2048;

/// The film lines along which the scene's outlines may cross a pixel
/// (module documentation).
pub fn outlines(scene: &Scene) -> Vec<HalfPlane> {
    let cam = &scene.camera;
    let eye = cam.eye();
    let mut lines = Vec::new();
    for object in &scene.objects {
        match object.shape {
            Shape::Triangle { vertices, .. } => {
                for k in 0..3 {
                    let (p, q) = (vertices[k] - eye, vertices[(k + 1) % 3] - eye);
                    lines.push(cam.film_half_plane(p.cross(&q)));
                }
            }
            Shape::Plane { normal, .. } => lines.push(cam.film_half_plane(normal)),
            Shape::Sphere { centre, radius } => lines.extend(cam.sphere_bounds(centre, radius)),
        }
    }
    lines.retain(|l| [l.a, l.b, l.c].iter().all(|v| v.is_finite()) && (l.a, l.b) != (0.0, 0.0));
    lines
}

/// The pixel's square (in film coordinates) cut along every line of
/// `lines` that crosses its inside, into at most `max` convex pieces of
/// positive area; true when a cut was left out to stay within `max`.
pub fn pieces(pixel: &Pixel, lines: &[HalfPlane], max: usize) -> (Vec<Vec<[f64; 2]>>, bool) {
    let [x, y] = pixel.corner();
    let (w, h) = (pixel.width(), pixel.height());
    let mut out = vec![vec![[x, y], [x + w, y], [x + w, y + h], [x, y + h]]];
    let mut left_out = false;
    let corners = [[x, y], [x + w, y], [x + w, y + h], [x, y + h]];
    // A line with every corner of the pixel on one side cuts nothing: it is
    // skipped before any piece is clipped (an image's lines are mostly so).
    let crossing = lines.iter().filter(|l| {
        let sides = corners.map(|p| l.side(p));
        sides.iter().any(|&s| s < 0.0) && sides.iter().any(|&s| s > 0.0)
    });
    for &line in crossing {
        let mut next = Vec::with_capacity(out.len() + 1);
        for piece in &out {
            let (inside, outside) = (clip(piece, line), clip(piece, line.complement()));
            if area(&inside) > 0.0 && area(&outside) > 0.0 {
                next.push(inside);
                next.push(outside);
            } else {
                next.push(piece.clone());
            }
        }
        if next.len() > max {
            left_out = true;
            continue;
        }
        out = next;
    }
    (out, left_out)
}

/// The mean of `f` over `pixel` by `rule` on each piece of the pixel cut
/// along `lines` ([`pieces`]), `n` evaluations in all: each fan triangle
/// first at [`PILOT_SHARE`] of an even share (at least 4 times the rule's least),
/// then the rest of `n` shared in proportion to those estimates' errors,
/// so a piece the integrand is smooth on costs little and one an outline
/// crosses gets the budget. Values and error estimates add, scaled by the
/// pixel's area.
pub fn by_pieces<R: Rule, V: Value>(
    rule: &R,
    pixel: &Pixel,
    lines: &[HalfPlane],
    n: usize,
    rng: &mut rand_pcg::Pcg64,
    mut f: impl FnMut([f64; 2]) -> V,
) -> Result<Estimate<V>, QuadError> {
    let (cut, left_out) = pieces(pixel, lines, MAX_PIECES);
    let fans: Vec<[[f64; 2]; 3]> = cut
        .iter()
        .flat_map(|p| (1..p.len() - 1).map(move |k| [p[0], p[k], p[k + 1]]))
        .collect();
    let least = rule.min_budget(2);
    // At least a few boxes of an adaptive rule, so that even a piece it
    // finds constant has a history to check its estimate against.
    let pilot = (n / fans.len().max(1) / PILOT_SHARE).max(4 * least);
    let mut parts = Vec::with_capacity(fans.len());
    for fan in &fans {
        parts.push(on_triangle(rule, *fan, pilot, rng, &mut f)?);
    }
    let spent: u64 = parts.iter().map(|p| p.evaluations).sum();
    let rest = (n as f64 - spent as f64).max(0.0);
    let errors: Vec<f64> = parts.iter().map(Estimate::max_error).collect();
    let total_error: f64 = errors.iter().sum();
    if total_error > 0.0 && total_error.is_finite() {
        for (k, fan) in fans.iter().enumerate() {
            let share = (rest * errors[k] / total_error) as usize;
            if share > pilot {
                parts[k] = on_triangle(rule, *fan, share, rng, &mut f)?;
            }
        }
    }
    let mut total = parts.into_iter().fold(Estimate::zero(), Estimate::combine);
    if left_out {
        total = total.doubted();
    }
    Ok(total.scaled(1.0 / (pixel.width() * pixel.height())))
}

/// A piece's first estimate gets 1/`PILOT_SHARE` of an even share of the
/// budget ([`by_pieces`]).
pub const PILOT_SHARE: usize = 16;

/// The integral of `f` over the film triangle `[a, b, c]` by `rule` with
/// `n` evaluations, through the collapsed-square map (module documentation).
fn on_triangle<R: Rule, V: Value>(
    rule: &R,
    [a, b, c]: [[f64; 2]; 3],
    n: usize,
    rng: &mut rand_pcg::Pcg64,
    f: &mut impl FnMut([f64; 2]) -> V,
) -> Result<Estimate<V>, QuadError> {
    let (ab, bc) = ([b[0] - a[0], b[1] - a[1]], [c[0] - b[0], c[1] - b[1]]);
    let double_area = (ab[0] * bc[1] - ab[1] * bc[0]).abs();
    rule.integrate(n, rng, |u: [f64; 2]| {
        let p = [
            a[0] + u[0] * ab[0] + u[0] * u[1] * bc[0],
            a[1] + u[0] * ab[1] + u[0] * u[1] * bc[1],
        ];
        f(p).map(|v| v * (u[0] * double_area))
    })
}
