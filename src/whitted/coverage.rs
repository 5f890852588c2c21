//! The exact fraction of a pixel covered by a half-plane or a convex
//! polygon, by polygon clipping: the reference of every supersampling
//! scheme (W-SS, W-Corner) on a pixel crossed by a straight edge.
//!
//! The pixel square is clipped against the half-plane `a x + b y <= c`
//! (Sutherland–Hodgman: each edge of the square kept where inside, cut at
//! `p = p_i + (p_j - p_i) s_i / (s_i - s_j)` where its end values `s = a x +
//! b y - c` change sign, `p_i` the end nearer the line), and the area of what is left is the shoelace sum
//! taken about its first vertex,
//!
//! `A = 1/2 |sum_k (x_k - x_0)(y_(k+1) - y_0) - (x_(k+1) - x_0)(y_k - y_0)|`,
//!
//! so a polygon of area 1e-12 in a corner keeps its relative accuracy (the
//! sum of absolute coordinates would lose it to cancellation). The fraction
//! is `A_in / (A_in + A_out)`, `A_out` the area of the complementary clip:
//! accurate relative to itself near 0 and near 1 alike. Everything is done
//! in the pixel's own coordinates (corner at the origin).
//!
//! ```
//! use lightquad::domain::Pixel;
//! use lightquad::whitted::coverage::{HalfPlane, half_plane_fraction};
//!
//! let pixel = Pixel::new(0.0, 0.0, 1.0, 1.0)?;
//! // The diagonal through two corners: half the pixel.
//! let diagonal = HalfPlane { a: 1.0, b: 1.0, c: 1.0 };
//! assert_eq!(half_plane_fraction(&pixel, diagonal), 0.5);
//! // A corner triangle with legs 1e-6 and 2e-6: area 1e-12.
//! let corner = HalfPlane { a: 1.0 / 1e-6, b: 1.0 / 2e-6, c: 1.0 };
//! assert!((half_plane_fraction(&pixel, corner) / 1e-12 - 1.0).abs() < 1e-12);
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use crate::domain::{Domain as _, Pixel};

/// The half-plane `a x + b y <= c` of the film.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HalfPlane {
    /// `a`.
    pub a: f64,
    /// `b`.
    pub b: f64,
    /// `c`.
    pub c: f64,
}

impl HalfPlane {
    /// `a x + b y - c`: `<= 0` inside.
    pub fn side(&self, p: [f64; 2]) -> f64 {
        self.a * p[0] + self.b * p[1] - self.c
    }

    /// The complement `a x + b y >= c` (as `-a x - b y <= -c`).
    pub fn complement(&self) -> HalfPlane {
        HalfPlane {
            a: -self.a,
            b: -self.b,
            c: -self.c,
        }
    }

    /// The half-plane to the left of the directed line from `p` to `q`
    /// (counter-clockwise in `x` right, `y` up coordinates).
    pub fn left_of(p: [f64; 2], q: [f64; 2]) -> HalfPlane {
        // Left: (q - p) x (r - p) >= 0, i.e. -dy x + dx y <= -dy p_x + dx p_y
        // negated.
        let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
        HalfPlane {
            a: dy,
            b: -dx,
            c: dy * p[0] - dx * p[1],
        }
    }

    /// The same half-plane in coordinates shifted by `-o` (`x' = x - o`).
    fn shifted(&self, o: [f64; 2]) -> HalfPlane {
        HalfPlane {
            c: self.c - self.a * o[0] - self.b * o[1],
            ..*self
        }
    }
}

/// The part of the convex polygon `poly` inside `h` (Sutherland–Hodgman).
pub fn clip(poly: &[[f64; 2]], h: HalfPlane) -> Vec<[f64; 2]> {
    let mut out = Vec::with_capacity(poly.len() + 1);
    for (i, &p) in poly.iter().enumerate() {
        let q = poly[(i + 1) % poly.len()];
        let (sp, sq) = (h.side(p), h.side(q));
        if sp <= 0.0 {
            out.push(p);
        }
        if (sp <= 0.0) != (sq <= 0.0) {
            // From the end nearer the line: its fraction of the edge is
            // the small one, so the cut keeps its relative accuracy (from
            // the far end, 1 - (1 - 1e-9) lost seven digits).
            let (from, to, s) = if sp.abs() <= sq.abs() {
                (p, q, sp / (sp - sq))
            } else {
                (q, p, sq / (sq - sp))
            };
            out.push([
                from[0] + (to[0] - from[0]) * s,
                from[1] + (to[1] - from[1]) * s,
            ]);
        }
    }
    out
}

/// The area of a simple polygon by the shoelace sum about its first vertex.
pub fn area(poly: &[[f64; 2]]) -> f64 {
    if poly.len() < 3 {
        return 0.0;
    }
    let o = poly[0];
    let mut twice = 0.0;
    for k in 1..poly.len() - 1 {
        let (p, q) = (poly[k], poly[k + 1]);
        twice += (p[0] - o[0]) * (q[1] - o[1]) - (q[0] - o[0]) * (p[1] - o[1]);
    }
    0.5 * twice.abs()
}

/// The pixel's square in its own coordinates.
fn square(pixel: &Pixel) -> Vec<[f64; 2]> {
    let (w, h) = (pixel.width(), pixel.height());
    vec![[0.0, 0.0], [w, 0.0], [w, h], [0.0, h]]
}

/// The fraction of `pixel` inside the half-plane `h`: `A_in / (A_in +
/// A_out)` (module documentation).
pub fn half_plane_fraction(pixel: &Pixel, h: HalfPlane) -> f64 {
    let local = h.shifted(pixel.corner());
    let sq = square(pixel);
    let inside = area(&clip(&sq, local));
    let outside = area(&clip(&sq, local.complement()));
    if inside + outside == 0.0 {
        return 0.0;
    }
    inside / (inside + outside)
}

/// The fraction of `pixel` inside every half-plane of `planes`: the square
/// clipped by each in turn, its area over the pixel's.
pub fn convex_fraction(pixel: &Pixel, planes: &[HalfPlane]) -> f64 {
    let mut piece = square(pixel);
    for h in planes {
        piece = clip(&piece, h.shifted(pixel.corner()));
        if piece.len() < 3 {
            return 0.0;
        }
    }
    area(&piece) / pixel.measure()
}

/// The fraction of `pixel` inside the convex polygon `poly` (vertices in
/// either order): the square clipped by each edge's half-plane.
pub fn polygon_fraction(pixel: &Pixel, poly: &[[f64; 2]]) -> f64 {
    if poly.len() < 3 {
        return 0.0;
    }
    let o = pixel.corner();
    let local: Vec<[f64; 2]> = poly.iter().map(|p| [p[0] - o[0], p[1] - o[1]]).collect();
    // Orientation: positive signed area is counter-clockwise.
    let signed: f64 = (1..local.len() - 1)
        .map(|k| {
            let (p, q) = (local[k], local[k + 1]);
            (p[0] - local[0][0]) * (q[1] - local[0][1])
                - (q[0] - local[0][0]) * (p[1] - local[0][1])
        })
        .sum();
    // A polygon of no area (its vertices rounded onto one point or line)
    // covers nothing; its edges bound no side.
    if signed == 0.0 {
        return 0.0;
    }
    let mut piece = square(pixel);
    for i in 0..local.len() {
        let (p, q) = (local[i], local[(i + 1) % local.len()]);
        let h = if signed >= 0.0 {
            HalfPlane::left_of(p, q)
        } else {
            HalfPlane::left_of(q, p)
        };
        piece = clip(&piece, h);
        if piece.len() < 3 {
            return 0.0;
        }
    }
    area(&piece) / pixel.measure()
}
