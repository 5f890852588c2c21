//! The domains of the `integral` family: each maps the unit cube onto its
//! points, gives the expression its variables there, and the Jacobian of the
//! measure the integral is taken in.
//!
//! | `type` | D | variables | measure |
//! |---|---:|---|---|
//! | `interval` (`a`, `b`; either may be `"-inf"` / `"inf"`) | 1 | `x` | length |
//! | `segment` (`a < b` finite, optional `breaks`) | 1 | `t` | length, each piece between breaks integrated with the whole budget |
//! | `cube` (`dimension` 1..=6) | D | `x1`..`xD`; `x`, `y`, `z` for the first three | volume of `[0, 1]^D` |
//! | `box` (`min`, `max`, 1 to 6 numbers each) | D | as `cube` | volume |
//! | `rectangle` (`origin`, `edge_u`, `edge_v`) | 2 | `x`, `y`, `z` of the point | area |
//! | `disk` (`centre`, `normal`, `radius`) | 2 | `x`, `y`, `z` | area |
//! | `triangle` (`a`, `b`, `c`) | 2 | `x`, `y`, `z` | area |
//! | `cap` (`centre`, `axis`, `radius`, `cos_max`) | 2 | `x`, `y`, `z`; `theta`, `phi` about `axis` | area |
//! | `sphere` (`centre`, `radius`) | 2 | `x`, `y`, `z`; `theta`, `phi` about `+z` | area |
//! | `hemisphere` (`normal`, default `+z`; `map`) | 2 | `x`, `y`, `z` of the unit direction; `theta`, `phi` about `normal` | `map: "uniform"` (default) and `"cosine"`: solid angle; `"projected"`: projected solid angle `cos theta d omega` |
//! | `pixel` (`x0`, `y0`, `width`, `height`) | 2 | `x`, `y` on the image plane | area |
//!
//! `phi` is in `[0, 2 pi)`, measured from the frame's first axis.
//!
//! An infinite interval is cut into pieces, each integrated with the whole
//! budget: a finite piece of length 1 at each finite end, mapped from that
//! end, and a tail for each infinite end, `[c, inf)` by `x = c + (1 - u)/u`
//! and `(-inf, c]` by `x = c - (1 - u)/u`, `|J| = 1/u^2` (`(-inf, inf)`:
//! `(-inf, -1]`, `[-1, 1]`, `[1, inf)`). The infinite end sits at `u = 0`,
//! where f64 resolves `u` down to 1e-308 (`x` up to 1e308), and so does the
//! interval's finite end (where an integrand may be singular); a single map
//! of `[a, inf)` onto `[0, 1]` resolves one of its ends only to 1e-16 (an
//! integrand falling as `x^-1.5` lost 1e-8 of its mass past `x = 1e16`, a
//! `1/sqrt` at the finite end 1e-8 before it). At `u = 0` the integrand
//! times `|J|` is taken as 0, its limit for any integrand falling faster
//! than `1/x^2`; rules with a node there (trapezoid, Simpson) lose
//! accuracy on integrands that fall slower. A divergent integral is not
//! detected: its converged reference says it did not converge.

use std::f64::consts::PI;

use crate::domain::{
    Disk, Domain, Frame, Hemisphere, Pixel, Rectangle, Segment, SphericalCap, Triangle, Vec3,
};

use super::expr::MAX_VARIABLES;

/// The most dimensions of a `cube` or `box`.
pub const MAX_BOX_DIM: usize = 6;

/// The names of a box's coordinates.
const BOX_NAMES: [&str; MAX_BOX_DIM] = ["x1", "x2", "x3", "x4", "x5", "x6"];

/// One piece of an `interval`: finite, or a tail reaching to infinity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Interval {
    /// Between two finite ends, the first at `u = 0` (where f64 resolves
    /// `u` best): `x = a + (b - a) u`, `|J| = |b - a|`.
    Finite(f64, f64),
    /// `[c, inf)` by `x = c + (1 - u)/u`.
    Above(f64),
    /// `(-inf, c]` by `x = c - (1 - u)/u`.
    Below(f64),
}

/// A built domain of the `integral` family ([module documentation](self)).
#[derive(Debug, Clone)]
pub enum Region {
    /// An interval, possibly infinite: its pieces ([module documentation](self)).
    Interval(Vec<Interval>),
    /// A finite segment cut at break points.
    Segment(Segment),
    /// A box (the unit cube included): its lower and upper corners.
    Box {
        /// Lower corner (first `dim` entries).
        lo: [f64; MAX_BOX_DIM],
        /// Upper corner.
        hi: [f64; MAX_BOX_DIM],
        /// Dimensions.
        dim: usize,
    },
    /// A parallelogram patch.
    Rectangle(Rectangle),
    /// A disk.
    Disk(Disk),
    /// A triangle.
    Triangle(Triangle),
    /// A spherical cap or a whole sphere.
    Cap(SphericalCap),
    /// The hemisphere of directions.
    Hemisphere(Hemisphere),
    /// A pixel on the image plane.
    Pixel(Pixel),
}

impl Region {
    /// The dimension of the unit cube it is mapped from.
    pub fn dim(&self) -> usize {
        match self {
            Region::Interval(_) | Region::Segment(_) => 1,
            Region::Box { dim, .. } => *dim,
            _ => 2,
        }
    }

    /// The variables an expression sees, in the order of the values
    /// [`Region::point`] fills.
    pub fn variables(&self) -> Vec<&'static str> {
        match self {
            Region::Interval(_) => vec!["x"],
            Region::Segment(_) => vec!["t"],
            Region::Box { dim, .. } => {
                let mut names = BOX_NAMES[..*dim].to_vec();
                names.extend(["x", "y", "z"].iter().take(*dim));
                names
            }
            Region::Pixel(_) => vec!["x", "y"],
            Region::Cap(_) | Region::Hemisphere(_) => vec!["x", "y", "z", "theta", "phi"],
            _ => vec!["x", "y", "z"],
        }
    }

    /// The variables that name a point (no aliases), for messages.
    pub fn coordinates(&self) -> usize {
        match self {
            Region::Box { dim, .. } => *dim,
            Region::Cap(_) | Region::Hemisphere(_) => 3,
            other => other.variables().len(),
        }
    }

    /// The domain's size in its measure (length, area, volume, solid
    /// angle); infinite for an infinite interval.
    pub fn size(&self) -> f64 {
        match self {
            Region::Interval(pieces) => pieces
                .iter()
                .map(|p| match p {
                    Interval::Finite(a, b) => (b - a).abs(),
                    _ => f64::INFINITY,
                })
                .sum(),
            Region::Segment(s) => s.measure(),
            Region::Box { lo, hi, dim } => (0..*dim).map(|k| hi[k] - lo[k]).product(),
            Region::Rectangle(r) => r.measure(),
            Region::Disk(d) => d.measure(),
            Region::Triangle(t) => t.measure(),
            Region::Cap(c) => c.measure(),
            Region::Hemisphere(h) => h.measure(),
            Region::Pixel(p) => p.measure(),
        }
    }

    /// The measure the integral is taken in, in words.
    pub fn measure(&self) -> &'static str {
        match self {
            Region::Interval(_) | Region::Segment(_) => "length",
            Region::Box { .. } => "volume",
            Region::Hemisphere(h) => match h.map {
                crate::domain::HemisphereMap::Projected => "projected solid angle",
                _ => "solid angle",
            },
            _ => "area",
        }
    }

    /// Fills `values` (see [`Region::variables`]) at the point `u` of the
    /// unit cube maps to and returns the Jacobian there; `None` at an
    /// infinite end of an interval (its contribution is taken as 0).
    /// `angles`: whether `theta` and `phi` are needed.
    #[inline]
    pub fn point(&self, u: &[f64], values: &mut [f64; MAX_VARIABLES], angles: bool) -> Option<f64> {
        match self {
            Region::Interval(pieces) => interval_point(pieces[0], u[0], values),
            Region::Segment(s) => {
                let (t, jacobian) = s.map([u[0]]);
                values[0] = t;
                Some(jacobian)
            }
            Region::Box { lo, hi, dim } => Some(box_point(lo, hi, *dim, u, values)),
            Region::Rectangle(r) => Some(spatial(r.map([u[0], u[1]]), values)),
            Region::Disk(d) => Some(spatial(d.map([u[0], u[1]]), values)),
            Region::Triangle(t) => Some(spatial(t.map([u[0], u[1]]), values)),
            Region::Pixel(p) => {
                let (q, jacobian) = p.map([u[0], u[1]]);
                values[..2].copy_from_slice(&q);
                Some(jacobian)
            }
            Region::Cap(c) => {
                let (p, jacobian) = c.map([u[0], u[1]]);
                spatial((p, jacobian), values);
                if angles {
                    polar(&c.frame(), (p - c.centre()) / c.radius(), values);
                }
                Some(jacobian)
            }
            Region::Hemisphere(h) => {
                let (w, jacobian) = h.map([u[0], u[1]]);
                spatial((w, jacobian), values);
                if angles {
                    polar(&h.frame, w, values);
                }
                Some(jacobian)
            }
        }
    }
}

/// `x` and `|J|` of an interval piece's map ([module documentation](self));
/// `None` at a tail's infinite end.
#[inline]
pub fn interval_point(i: Interval, u: f64, values: &mut [f64; MAX_VARIABLES]) -> Option<f64> {
    let (x, jacobian) = match i {
        Interval::Finite(a, b) => (along(a, b, u), (b - a).abs()),
        Interval::Above(c) => {
            (u > 0.0).then_some(())?;
            (c + (1.0 - u) / u, 1.0 / (u * u))
        }
        Interval::Below(c) => {
            (u > 0.0).then_some(())?;
            (c - (1.0 - u) / u, 1.0 / (u * u))
        }
    };
    values[0] = x;
    Some(jacobian)
}

/// `a + (b - a) u`, written from the nearer end so that `u = 0` and `u = 1`
/// give `a` and `b` exactly.
#[inline]
fn along(a: f64, b: f64, u: f64) -> f64 {
    if u <= 0.5 {
        a + (b - a) * u
    } else {
        b - (b - a) * (1.0 - u)
    }
}

/// A box's point, its first three coordinates copied to `x`, `y`, `z`; the
/// Jacobian is the volume.
#[inline]
fn box_point(
    lo: &[f64; MAX_BOX_DIM],
    hi: &[f64; MAX_BOX_DIM],
    dim: usize,
    u: &[f64],
    values: &mut [f64; MAX_VARIABLES],
) -> f64 {
    let mut volume = 1.0;
    for k in 0..dim {
        values[k] = along(lo[k], hi[k], u[k]);
        volume *= hi[k] - lo[k];
    }
    for k in 0..dim.min(3) {
        values[dim + k] = values[k];
    }
    volume
}

/// `x`, `y`, `z` of a 3-D point; passes the Jacobian through.
#[inline]
fn spatial((p, jacobian): (Vec3, f64), values: &mut [f64; MAX_VARIABLES]) -> f64 {
    values[..3].copy_from_slice(p.as_slice());
    jacobian
}

/// `theta` (from the frame's normal) and `phi` (in `[0, 2 pi)`) of the unit
/// vector `w`, into `values[3..5]`.
#[inline]
fn polar(frame: &Frame, w: Vec3, values: &mut [f64; MAX_VARIABLES]) {
    let l = frame.to_local(w);
    values[3] = l.x.hypot(l.y).atan2(l.z);
    let phi = l.y.atan2(l.x);
    values[4] = if phi < 0.0 { phi + 2.0 * PI } else { phi };
}
