//! Warnings about occluders and lights that run but may not be what was
//! meant, each at the JSON path of the shape (`scene.occluders[j]`,
//! `scene.emitters[i]`):
//!
//! | case | what the forms give |
//! |---|---|
//! | a flat light more than `1/eps` times as large as its plane's distance from the receiver | R-A's integrand is a peak narrower than f64's spacing in the light's map: its rules are far off (the cone and hemisphere forms and the reference are not) |
//! | the receiver strictly inside a sphere occluder | 0 from every light outside the sphere |
//! | a planar occluder in the plane of a planar light, over it | that light unblocked: an occluder blocks only what lies strictly behind it |
//! | a planar occluder whose plane passes the receiver within f64's rounding at its coordinates | whether it is in front of the receiver is rounding's choice |

use crate::domain::Vec3;
use crate::error::SpecError;
use crate::rendering::emitter::{AnyEmitter, Emitter};
use crate::rendering::occluder::Occluder;
use crate::whitted::intersect::gamma;

/// The ratio of a light's size to its distance, beyond which R-A's peak
/// (about `distance / size` of the map wide) is narrower than f64 resolves
/// in map coordinates near 1: `1 / eps`.
pub const AREA_FORM_RATIO: f64 = 1.0 / f64::EPSILON;

/// The warning about emitter `i`, `e`, for a receiver at `x`: a flat light
/// whose size (its bounding sphere's diameter) is more than
/// [`AREA_FORM_RATIO`] times the distance of its plane from `x`.
pub(super) fn emitter_doubt(i: usize, e: &AnyEmitter<f64>, x: Vec3) -> Option<SpecError> {
    let body = e.occluder()?;
    let (p, n) = plane(&body)?;
    let (_, r) = body.bounding_sphere();
    let distance = n.dot(&(p - x)).abs();
    let ratio = 2.0 * r / distance;
    (distance > 0.0 && ratio > AREA_FORM_RATIO).then(|| {
        SpecError::at(
            format!("scene.emitters[{i}]"),
            format!(
                "is {ratio:.1e} times as large as its plane's distance from the receiver \
                 ({distance:e}), more than {AREA_FORM_RATIO:.1e}: the area form's integrand is a \
                 peak narrower than f64 resolves in the light's map, so the rules on E_area and \
                 L_area are far off whatever the budget (the cone and hemisphere forms and the \
                 reference are not; shrink the light to measure the area form)"
            ),
        )
    })
}

/// The warnings about occluder `j`, `o`, among `emitters`, for a receiver
/// at `x`.
pub(super) fn occluder_doubts(
    j: usize,
    o: &Occluder,
    emitters: &[AnyEmitter<f64>],
    x: Vec3,
) -> Vec<SpecError> {
    let at = format!("scene.occluders[{j}]");
    let mut out = Vec::new();
    if let Occluder::Sphere(s) = o {
        let d = (x - s.centre).norm();
        if s.radius - d > gamma(8) * (s.radius + d) {
            out.push(SpecError::at(
                &at,
                format!(
                    "the receiver at {:?} is inside this sphere (centre {:?}, radius {}): it \
                     sees no light from outside it, so every quantity gets 0 from such lights \
                     (move the receiver or the sphere to let light in)",
                    x.as_slice(),
                    s.centre.as_slice(),
                    s.radius
                ),
            ));
        }
        return out;
    }
    for (k, e) in emitters.iter().enumerate() {
        if let Some(body) = e.occluder()
            && coplanar_over(o, &body)
        {
            out.push(SpecError::at(
                &at,
                format!(
                    "lies in the plane of scene.emitters[{k}], over it: an occluder blocks only \
                     what lies strictly behind it, so it hides none of that light in any form \
                     (move it off the light's plane, toward the receiver, to block it)"
                ),
            ));
        }
    }
    if let Some((distance, rounding)) = unresolved_height(o, x) {
        out.push(SpecError::at(
            &at,
            format!(
                "its plane passes {distance:e} from the receiver at {:?}, within the rounding of \
                 f64 at these coordinates (about {rounding:.1e}): whether it is in front of the \
                 receiver is not resolved (expected 0, the receiver on it, or more than \
                 {rounding:.1e})",
                x.as_slice()
            ),
        ));
    }
    out
}

/// A point and the unit normal of a planar shape; `None` for a sphere.
fn plane(o: &Occluder) -> Option<(Vec3, Vec3)> {
    match o {
        Occluder::Sphere(_) => None,
        _ => {
            let (c, _) = o.bounding_sphere();
            Some((c, o.normal_at(c)))
        }
    }
}

/// True when planar `a` lies in the plane of planar `b` (normals parallel
/// and the distance between the planes within `1e-12` of their size) and
/// their bounding spheres overlap.
fn coplanar_over(a: &Occluder, b: &Occluder) -> bool {
    let (Some((pa, na)), Some((pb, nb))) = (plane(a), plane(b)) else {
        return false;
    };
    let ((ca, ra), (cb, rb)) = (a.bounding_sphere(), b.bounding_sphere());
    let size = a.extent().max(b.extent());
    na.cross(&nb).norm() <= 1e-12
        && nb.dot(&(pa - pb)).abs() <= 1e-12 * size
        && (ca - cb).norm() < ra + rb
}

/// `(|n . (p - x)|, gamma_8 |n| . |p - x|)` for a planar occluder whose
/// plane passes at a non-zero distance from `x` within that rounding bound
/// (the bound of [`crate::rendering::occluder::plane_t`] along the normal)
/// and whose bounding sphere holds `x`.
fn unresolved_height(o: &Occluder, x: Vec3) -> Option<(f64, f64)> {
    let (p, n) = plane(o)?;
    let (c, r) = o.bounding_sphere();
    let to = p - x;
    let distance = n.dot(&to).abs();
    let rounding = gamma(8) * n.abs().dot(&to.abs());
    (distance > 0.0 && distance <= rounding && (x - c).norm() <= r).then_some((distance, rounding))
}
