//! The closed forms of `coverage`, `pixel` and `image`: a triangle's or a
//! plane's footprint on the film, clipped to the pixel.

use super::{Built, WhittedQuantity};
use crate::domain::Pixel;
use crate::value::Rgb;
use crate::whitted::coverage::{HalfPlane, convex_fraction, half_plane_fraction};
use crate::whitted::intersect::Shape;
use crate::whitted::scene::{Camera, Object, Scene};

/// The film region whose primary rays meet a shape, when it is a convex
/// region of the film: a triangle's is the common part of three
/// half-planes ([`Camera::triangle_half_planes`]; no area when the eye is
/// in its plane), a plane's one half-plane.
enum Footprint {
    Cone([HalfPlane; 3]),
    HalfPlane(HalfPlane),
    Empty,
}

fn footprint(cam: &Camera, shape: &Shape) -> Option<Footprint> {
    match *shape {
        Shape::Triangle { vertices, .. } => Some(match cam.triangle_half_planes(&vertices) {
            Some(planes) => Footprint::Cone(planes),
            None => Footprint::Empty,
        }),
        Shape::Plane { point, normal } => {
            // The ray meets the plane where d . n has the sign opposite to
            // the eye's side.
            let side = (cam.eye() - point).dot(&normal);
            if side == 0.0 {
                return None;
            }
            let toward = cam.film_half_plane(normal);
            Some(Footprint::HalfPlane(if side > 0.0 {
                toward
            } else {
                toward.complement()
            }))
        }
        Shape::Sphere { .. } => None,
    }
}

/// The closed form of `q` (the family's [module documentation](super), **Closed forms**).
pub(super) fn closed_form(built: &Built, q: WhittedQuantity) -> Option<Vec<f64>> {
    let scene = &built.scene;
    let [object] = scene.objects.as_slice() else {
        return None;
    };
    let cam = &scene.camera;
    let print = footprint(cam, &object.shape)?;
    let fraction = |i: usize, j: usize| -> Option<f64> {
        let p = Pixel::new(i as f64, j as f64, 1.0, 1.0).ok()?;
        Some(match &print {
            Footprint::Cone(planes) => convex_fraction(&p, planes),
            Footprint::Empty => 0.0,
            Footprint::HalfPlane(h) => half_plane_fraction(&p, *h),
        })
    };
    if q == WhittedQuantity::Coverage {
        let [i, j] = built.pixel?;
        return Some(vec![fraction(i, j)?]);
    }
    let flat = flat_intensity(scene, object)?;
    let pixel = |i, j| -> Option<[f64; 3]> {
        let f = fraction(i, j)?;
        let v = scene.background + (flat - scene.background) * f;
        Some([v.x, v.y, v.z])
    };
    match q {
        WhittedQuantity::Pixel => {
            let [i, j] = built.pixel?;
            Some(pixel(i, j)?.to_vec())
        }
        _ => {
            let mut out = Vec::with_capacity(3 * cam.width() * cam.height());
            for j in 0..cam.height() {
                for i in 0..cam.width() {
                    out.extend(pixel(i, j)?);
                }
            }
            Some(out)
        }
    }
}

/// The intensity of `object` where it is seen, when it is the same at every
/// point: `I_a k_a C` with no light term (no lights, or `k_d = k_s = 0`) and
/// no mirror or transmitted ray (`k_s = k_t = 0`, or `max_depth = 0`).
fn flat_intensity(scene: &Scene, object: &Object) -> Option<Rgb> {
    let m = &object.material;
    let lit = !scene.lights.is_empty() && (m.k_d > 0.0 || m.k_s > 0.0);
    let recursive = scene.max_depth > 0 && (m.k_s > 0.0 || m.k_t > 0.0);
    (!lit && !recursive).then(|| scene.ambient.component_mul(&m.colour) * m.k_a)
}
