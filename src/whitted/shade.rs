//! Whitted's illumination model (W-6.1 with the Phong term of W-Phong),
//! traced recursively, per R, G, B.
//!
//! At the first hit `P` of a ray, with unit normal `N` turned toward the
//! ray's origin, `A` the unit direction toward the viewer (back along the
//! ray) and `L_q` the unit direction toward light `q`:
//!
//! `I = I_a k_a C + sum_q S_q I_q (k_d C max(0, N . L_q) + k_s max(0, R_q .
//! A)^n) + k_s I_r + k_t I_t`  (W-6.1, W-Phong)
//!
//! with `C` the material's colour, `R_q = 2 (N . L_q) N - L_q` the
//! reflection of `L_q`, `S_q` the shadow ray's verdict (1 when no object
//! lies between `P` and the light, 0 otherwise: a transparent object casts
//! as black a shadow as an opaque one, as in Whitted's model, which traces
//! no light through refracting surfaces; a light below the surface, `N .
//! L_q <= 0`, adds nothing and casts no shadow ray), `I_r` the intensity seen along
//! the mirror direction `R = D - 2 (D . N) N` of the incoming direction `D`,
//! and `I_t` the intensity along the refracted direction (Snell's law,
//! `eta_1 sin theta_1 = eta_2 sin theta_2`):
//!
//! `T = eta D + (eta cos theta_1 - cos theta_2) N`, `eta = eta_1 / eta_2`,
//! `cos theta_2 = sqrt(1 - eta^2 (1 - cos^2 theta_1))`.
//!
//! Where `eta^2 (1 - cos^2 theta_1) > 1` there is no transmitted ray: the
//! light is totally internally reflected, and `k_t I_t` is taken along the
//! mirror direction (a reflection ray). The inside of a sphere, the back of
//! a plane and the back of a triangle have index `ior`, the outside 1.
//!
//! Recursion stops at `max_depth` (the primary ray is depth 0): a ray of
//! depth `max_depth` gets no reflected or transmitted term. Rays a scene
//! does not need are not traced: no `k_s`, no reflection ray; no `k_t`, no
//! refraction ray; no lights, or a light below the surface, no shadow ray;
//! `k_d = k_s = 0`, no shadow ray either. [`RayCount`] counts the rays
//! traced by kind.
//!
//! ```
//! use lightquad::domain::Vec3;
//! use lightquad::value::Rgb;
//! use lightquad::whitted::intersect::{Ray, Shape};
//! use lightquad::whitted::scene::{Camera, Light, Material, Object, Scene};
//! use lightquad::whitted::shade::{RayCount, trace};
//!
//! // A diffuse floor z = 0 under a light straight above: I = I_a k_a + I_q k_d.
//! let floor = Object {
//!     shape: Shape::plane(Vec3::zeros(), Vec3::z())?,
//!     material: Material { k_a: 0.2, k_d: 0.5, ..Material::default() },
//! };
//! let light = Light::point(Vec3::new(0.0, 0.0, 10.0), Rgb::new(1.0, 1.0, 1.0))?;
//! let cam = Camera::new(Vec3::new(0.0, 0.0, 1.0), -Vec3::z(), Vec3::y(), 60.0, 1, 1)?;
//! let scene = Scene::new(vec![floor], vec![light], Rgb::new(1.0, 1.0, 1.0), Rgb::zeros(), cam, 4)?;
//! let mut rays = RayCount::default();
//! let i = trace(&scene, &Ray::new(Vec3::new(0.0, 0.0, 1.0), -Vec3::z()), 0, &mut rays);
//! assert!((i.x - (0.2 + 0.5)).abs() < 1e-15);
//! assert_eq!((rays.primary, rays.shadow, rays.reflection, rays.refraction), (1, 1, 0, 0));
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use crate::domain::Vec3;
use crate::value::Rgb;

use super::intersect::Ray;
use super::scene::Scene;

/// The rays traced, by kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RayCount {
    /// Rays from the eye.
    pub primary: u64,
    /// Rays toward the lights (W-6.1's `S_q`).
    pub shadow: u64,
    /// Rays along the mirror direction (`I_r`, and `I_t` under total
    /// internal reflection).
    pub reflection: u64,
    /// Rays along the refracted direction (`I_t`).
    pub refraction: u64,
}

impl RayCount {
    /// Every ray.
    pub fn total(&self) -> u64 {
        self.primary + self.shadow + self.reflection + self.refraction
    }

    /// The sum of two counts.
    pub fn add(&mut self, other: RayCount) {
        self.primary += other.primary;
        self.shadow += other.shadow;
        self.reflection += other.reflection;
        self.refraction += other.refraction;
    }
}

/// The mirror direction of `d` about the unit `n`: `R = d - 2 (d . n) n`.
pub fn reflect(d: Vec3, n: Vec3) -> Vec3 {
    d - n * (2.0 * d.dot(&n))
}

/// The refracted direction of the unit `d` through the unit `n` (turned
/// toward `d`'s origin, `d . n <= 0`) for `eta = eta_1 / eta_2`: `T = eta d +
/// (eta cos theta_1 - cos theta_2) n` by Snell's law, or `None` under total
/// internal reflection (`eta^2 (1 - cos^2 theta_1) > 1`).
pub fn refract(d: Vec3, n: Vec3, eta: f64) -> Option<Vec3> {
    let cos1 = -d.dot(&n);
    let sin2_sq = eta * eta * (1.0 - cos1 * cos1).max(0.0);
    if sin2_sq > 1.0 {
        return None;
    }
    let cos2 = (1.0 - sin2_sq).sqrt();
    Some(d * eta + n * (eta * cos1 - cos2))
}

/// The intensity seen back along `ray` (W-6.1 with W-Phong), the ray being
/// of recursion depth `depth`; every ray traced, this one included, is
/// counted in `rays` (`depth = 0` counts as primary; a caller tracing a
/// secondary ray counts it itself).
pub fn trace(scene: &Scene, ray: &Ray, depth: usize, rays: &mut RayCount) -> Rgb {
    if depth == 0 {
        rays.primary += 1;
    }
    let Some((k, hit)) = scene.nearest(ray) else {
        return scene.background;
    };
    let m = scene.objects[k].material;
    let d = ray.direction / ray.direction.norm();
    // The normal turned toward the ray's origin; entering the object when
    // the ray meets its outside.
    let entering = d.dot(&hit.normal) < 0.0;
    let n = if entering { hit.normal } else { -hit.normal };
    let a = -d;
    // W-6.1: ambient.
    let mut i = scene.ambient.component_mul(&m.colour) * m.k_a;
    // W-6.1 diffuse and W-Phong specular per light, each behind its shadow ray.
    if m.k_d > 0.0 || m.k_s > 0.0 {
        for light in &scene.lights {
            let Some((l, shadow)) = light.toward(&hit) else {
                continue;
            };
            let cos = n.dot(&l);
            if cos <= 0.0 {
                continue;
            }
            rays.shadow += 1;
            if scene.blocked(&shadow) {
                continue;
            }
            let r_q = n * (2.0 * cos) - l;
            let highlight = if m.k_s > 0.0 {
                m.k_s * r_q.dot(&a).max(0.0).powf(m.phong)
            } else {
                0.0
            };
            let diffuse = m.colour * (m.k_d * cos);
            i += light
                .intensity()
                .component_mul(&(diffuse + Rgb::repeat(highlight)));
        }
    }
    if depth >= scene.max_depth {
        return i;
    }
    // W-6.1: k_s I_r, the mirror ray.
    let mirror = reflect(d, n);
    if m.k_s > 0.0 {
        rays.reflection += 1;
        i += trace(scene, &hit.spawn(mirror), depth + 1, rays) * m.k_s;
    }
    // W-6.1: k_t I_t, the refracted ray (or the mirror ray under total
    // internal reflection).
    if m.k_t > 0.0 {
        let eta = if entering { 1.0 / m.ior } else { m.ior };
        let i_t = match refract(d, n, eta) {
            Some(t) => {
                rays.refraction += 1;
                trace(scene, &hit.spawn(t), depth + 1, rays)
            }
            None => {
                rays.reflection += 1;
                trace(scene, &hit.spawn(mirror), depth + 1, rays)
            }
        };
        i += i_t * m.k_t;
    }
    i
}

/// The intensity seen through film point `[x, y]` (one primary ray).
pub fn film(scene: &Scene, at: [f64; 2], rays: &mut RayCount) -> Rgb {
    trace(scene, &scene.camera.ray(at), 0, rays)
}
