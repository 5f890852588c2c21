//! Which of two shapes a ray from a point meets first, where that is the
//! same for every ray that meets both: what lets a blocker's hidden light be
//! cut by outlines alone ([`crate::rendering::arcs`]), with no depth test
//! per direction.
//!
//! Two sufficient conditions, each exact:
//!
//! - distance: every point of `A` is at most as far from `x` as every point
//!   of `B` (`far(A) <= near(B)`);
//! - separation by a plane: `B` is planar and `A` lies wholly on `x`'s side
//!   of `B`'s plane (then a ray from `x` meets `A` before it reaches the
//!   plane, where it meets `B`), or wholly beyond it (then `B` first); the
//!   same with the roles exchanged.
//!
//! Shapes that pass neither (they interpenetrate, or one straddles the
//! other's plane with their distances overlapping) have no order here, and
//! [`apart`] says whether their cones of directions can overlap at all.

use crate::domain::Vec3;
use crate::rendering::cap::one_minus_cos_between;
use crate::rendering::occluder::Occluder;

/// The plane of a planar shape: a point of it and its unit normal.
fn plane(o: &Occluder) -> Option<(Vec3, Vec3)> {
    match o {
        Occluder::Sphere(_) => None,
        Occluder::Disk(d) => Some((d.centre(), d.frame().n)),
        Occluder::Rectangle(r) => Some((r.origin(), r.normal())),
        Occluder::Triangle(t) => Some((t.vertices()[0], t.normal())),
    }
}

/// The corners of a polygon shape.
fn corners(o: &Occluder) -> Vec<Vec3> {
    match o {
        Occluder::Rectangle(r) => {
            let (p, a, b) = (r.origin(), r.edge_u(), r.edge_v());
            vec![p, p + a, p + a + b, p + b]
        }
        Occluder::Triangle(t) => t.vertices().to_vec(),
        Occluder::Sphere(_) | Occluder::Disk(_) => Vec::new(),
    }
}

/// The least and greatest `n . p` over the shape's points `p` (unit `n`).
fn span(o: &Occluder, n: Vec3) -> (f64, f64) {
    match o {
        Occluder::Sphere(s) => {
            let c = n.dot(&s.centre);
            (c - s.radius, c + s.radius)
        }
        Occluder::Disk(d) => {
            let (c, m) = (d.centre(), d.frame().n);
            let reach = d.radius() * (n - m * n.dot(&m)).norm();
            (n.dot(&c) - reach, n.dot(&c) + reach)
        }
        _ => corners(o)
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(n.dot(p)), hi.max(n.dot(p)))
            }),
    }
}

/// A lower and an upper bound of the distance from `x` to the shape's
/// points: a sphere's exact, a planar shape's distance to its plane and
/// its farthest corner (a disk's centre plus its radius).
fn distances(o: &Occluder, x: Vec3) -> (f64, f64) {
    match o {
        Occluder::Sphere(s) => {
            let d = (s.centre - x).norm();
            ((d - s.radius).max(0.0), d + s.radius)
        }
        Occluder::Disk(d) => {
            let near = d.frame().n.dot(&(d.centre() - x)).abs();
            (near, (d.centre() - x).norm() + d.radius())
        }
        _ => {
            let near = plane(o).map_or(0.0, |(p, n)| n.dot(&(p - x)).abs());
            let far = corners(o)
                .iter()
                .fold(0.0_f64, |m, p| m.max((p - x).norm()));
            (near, far)
        }
    }
}

/// Whether `a` lies wholly on `x`'s side of `b`'s plane (`Some(true)`),
/// wholly beyond it (`Some(false)`), or neither; `None` too for `b` not
/// planar or `x` in its plane. Contact within `tol` counts as a side; `a`
/// lying within `tol` of the plane (a blocker in a light's plane, the
/// light's own rectangle) is a tie and `None`.
fn side(a: &Occluder, b: &Occluder, x: Vec3, tol: f64) -> Option<bool> {
    let (p, n) = plane(b)?;
    let offset = n.dot(&p);
    let sign = (n.dot(&x) - offset).signum();
    if n.dot(&x) == offset {
        return None;
    }
    let (lo, hi) = span(a, n);
    let (lo, hi) = if sign > 0.0 {
        (lo - offset, hi - offset)
    } else {
        (offset - hi, offset - lo)
    };
    if lo.abs() <= tol && hi.abs() <= tol {
        // `a` lies in `b`'s plane: a tie of depth, neither in front.
        None
    } else if lo >= -tol {
        Some(true)
    } else if hi <= tol {
        Some(false)
    } else {
        None
    }
}

/// True when the shape has points strictly on both sides of the plane
/// through `p` with unit normal `n`.
pub fn straddles(o: &Occluder, p: Vec3, n: Vec3) -> bool {
    let (lo, hi) = span(o, n);
    let at = n.dot(&p);
    lo < at && hi > at
}

/// `Some(true)` when every ray from `x` that meets both `a` and `b` meets
/// `a` first, `Some(false)` when `b` first, `None` when neither condition
/// of the module holds.
pub fn first(a: &Occluder, b: &Occluder, x: Vec3) -> Option<bool> {
    let (near_a, far_a) = distances(a, x);
    let (near_b, far_b) = distances(b, x);
    if far_a <= near_b {
        return Some(true);
    }
    if far_b <= near_a {
        return Some(false);
    }
    let tol = 1e-13 * far_a.max(far_b);
    side(a, b, x, tol).or_else(|| side(b, a, x, tol).map(|b_first| !b_first))
}

/// True when the cones of directions from `x` to the bounding spheres of
/// `a` and `b` are apart: no ray from `x` meets both.
pub fn apart(a: &Occluder, b: &Occluder, x: Vec3) -> bool {
    let half = |o: &Occluder| -> Option<(Vec3, f64)> {
        let (c, r) = o.bounding_sphere();
        let d = (c - x).norm();
        (d > r).then(|| ((c - x) / d, (r / d).asin()))
    };
    match (half(a), half(b)) {
        (Some((u, alpha)), Some((v, beta))) => {
            let between = 2.0 * (one_minus_cos_between(u, v) / 2.0).sqrt().min(1.0).asin();
            between > alpha + beta
        }
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::QuadError;

    /// Orders checked against ray casting: over a grid of directions, every
    /// ray that meets both shapes meets the one [`first`] names first.
    #[test]
    fn the_first_shape_is_first_along_every_ray_meeting_both() -> Result<(), QuadError> {
        let x = Vec3::zeros();
        let light = Occluder::rectangle(
            Vec3::new(-1.0, -1.0, 2.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.3),
        )?;
        let cases = [
            (Occluder::sphere(Vec3::new(0.2, 0.1, 1.2), 0.5)?, Some(true)),
            (
                Occluder::sphere(Vec3::new(0.2, 0.1, 3.5), 0.5)?,
                Some(false),
            ),
            (Occluder::sphere(Vec3::new(0.2, 0.1, 2.0), 0.5)?, None),
            (
                Occluder::disk(Vec3::new(0.0, 0.3, 1.0), Vec3::new(0.2, 0.0, 1.0), 0.8)?,
                Some(true),
            ),
            (
                Occluder::triangle(
                    Vec3::new(-3.0, -3.0, 4.0),
                    Vec3::new(3.0, -3.0, 4.0),
                    Vec3::new(0.0, 3.0, 5.0),
                )?,
                Some(false),
            ),
        ];
        for (o, expected) in cases {
            let got = first(&o, &light, x);
            assert_eq!(got, expected, "{o:?}");
            let Some(o_first) = got else { continue };
            let mut both = 0;
            for i in 0..200 {
                for j in 0..200 {
                    let (u, v) = ((i as f64 + 0.5) / 200.0, (j as f64 + 0.5) / 200.0);
                    let w = Vec3::new(2.0 * u - 1.0, 2.0 * v - 1.0, 1.0).normalize();
                    let (Some(ta), Some(tb)) = (
                        o.intersect(x, w, 0.0, f64::INFINITY),
                        light.intersect(x, w, 0.0, f64::INFINITY),
                    ) else {
                        continue;
                    };
                    both += 1;
                    assert_eq!(ta < tb, o_first, "{o:?} along {w:?}");
                }
            }
            assert!(both > 100, "{o:?}: {both} rays met both");
        }
        Ok(())
    }

    #[test]
    fn cones_far_apart_are_apart_and_overlapping_ones_not() -> Result<(), QuadError> {
        let x = Vec3::zeros();
        let a = Occluder::sphere(Vec3::new(0.0, 0.0, 2.0), 0.5)?;
        let b = Occluder::sphere(Vec3::new(2.0, 0.0, 2.0), 0.5)?;
        let c = Occluder::sphere(Vec3::new(0.6, 0.0, 2.0), 0.5)?;
        assert!(apart(&a, &b, x));
        assert!(!apart(&a, &c, x));
        assert!(!apart(&a, &Occluder::sphere(Vec3::zeros(), 1.0)?, x));
        Ok(())
    }
}
