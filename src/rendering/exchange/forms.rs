//! The three forms of the exchange integral between the receiving surface
//! and one emitter `k`,
//!
//! `G_k = int_(A_r) int_(A_k) cos theta_r cos theta_k / r^2 V(x, y) dA_k dA_r`
//!
//! (R-3P's geometry term over both surfaces), from which every quantity of
//! the family is a weighted sum (`F = sum_k G_k / (pi A_r)`,
//! `Phi = sum_k L_k G_k`):
//!
//! | form | domain | integrand in `u` |
//! |---|---|---|
//! | area | `[0,1]^4`: the receiver's map, then the emitter's | `cos theta_r cos theta_k / r^2 V J_r J_k` |
//! | cone | `[0,1]^4`: the receiver's map, then the emitter's cone of directions from that point | `[the ray meets k, unblocked] cos theta_r J_cone J_r` |
//! | contour | `[0,1]^2`: the receiver's map | `pi F_(dA(x) -> k) J_r`, the point's form factor in closed form |
//!
//! The point form factor is Lambert's contour formula over the lit part of a
//! polygon light ([`crate::rendering::experiment::lit_triangles`], clipped
//! at the receiver's horizon), or Howell's element-to-parallel-disk formula
//! for a disk light parallel to the receiver ([`parallel_disk_point`]).

use crate::domain::{Domain, Vec3};
use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::exact::rendering::{polygon_form_factor, polygon_form_factor_toward};
use crate::quadrature::Rule;
use crate::rendering::emitter::{AnyEmitter, Emitter};
use crate::rendering::experiment::lit_triangles;
use crate::rendering::receiver::Receiver;
use crate::rendering::scene::Scene;

use super::surface::Surface;

/// The form of the exchange integral (module table).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExchangeForm {
    /// 4-D over both surfaces.
    Area,
    /// 4-D over the receiver and each point's cone of directions.
    Cone,
    /// 2-D over the receiver, the point form factor in closed form.
    Contour,
}

impl ExchangeForm {
    /// The dimension of its unit cube.
    pub fn dimension(&self) -> usize {
        match self {
            ExchangeForm::Area | ExchangeForm::Cone => 4,
            ExchangeForm::Contour => 2,
        }
    }
}

/// A scene's emitters and occluders with the receiving surface.
#[derive(Debug, Clone, Copy)]
pub struct Transport<'a> {
    /// Emitters and occluders.
    pub scene: &'a Scene<f64>,
    /// The receiving surface.
    pub receiver: &'a Surface,
}

impl Transport<'_> {
    /// `G_k` by `form` with `rule` at `n` points.
    pub fn integrate<R: Rule>(
        &self,
        form: ExchangeForm,
        k: usize,
        rule: &R,
        n: usize,
        rng: &mut rand_pcg::Pcg64,
    ) -> Result<Estimate<f64>, QuadError> {
        let e = self.emitter(k)?;
        match form {
            ExchangeForm::Area => {
                let light = e.surface(&self.point_receiver(self.receiver.map([0.5, 0.5]).0)?)?;
                // Visibility is a term only where something can block k.
                let tested = self.scene.has_blockers(Some(k));
                rule.integrate(n, rng, |u: [f64; 4]| {
                    self.area_kernel(e, k, &light, tested, u)
                })
            }
            ExchangeForm::Cone => {
                rule.try_integrate(n, rng, |u: [f64; 4]| self.cone_kernel(e, k, u))
            }
            ExchangeForm::Contour => rule.try_integrate(n, rng, |u: [f64; 2]| {
                let (x, jr) = self.receiver.map(u);
                Ok(std::f64::consts::PI * self.point_factor(k, x)? * jr)
            }),
        }
    }

    fn emitter(&self, k: usize) -> Result<&AnyEmitter<f64>, QuadError> {
        self.scene
            .emitters()
            .get(k)
            .ok_or_else(|| QuadError::invalid("emitter", k, "an emitter of the scene"))
    }

    fn point_receiver(&self, x: Vec3) -> Result<Receiver, QuadError> {
        Receiver::new(x, self.receiver.normal())
    }

    /// The area form's integrand: `cos theta_r cos theta_k / r^2 V J_r J_k`,
    /// 0 where either cosine is not positive or the points meet.
    fn area_kernel<D: Domain<2, Point = Vec3>>(
        &self,
        e: &AnyEmitter<f64>,
        k: usize,
        light: &D,
        tested: bool,
        u: [f64; 4],
    ) -> f64 {
        let (x, jr) = self.receiver.map([u[0], u[1]]);
        let (y, jk) = light.map([u[2], u[3]]);
        let d = y - x;
        let r2 = d.norm_squared();
        let (cos_r, cos_k) = (self.receiver.normal().dot(&d), -e.normal_at(y).dot(&d));
        if cos_r <= 0.0 || cos_k <= 0.0 || r2 == 0.0 {
            return 0.0;
        }
        if tested && !self.scene.visible(x, y, Some(k)) {
            return 0.0;
        }
        cos_r / r2 * (cos_k / r2) * jr * jk
    }

    /// The cone form's integrand: `cos theta_r J_cone J_r` where the
    /// direction meets emitter `k`'s emitting side with nothing before it.
    fn cone_kernel(&self, e: &AnyEmitter<f64>, k: usize, u: [f64; 4]) -> Result<f64, QuadError> {
        let (x, jr) = self.receiver.map([u[0], u[1]]);
        let point = self.point_receiver(x)?;
        let cone = e.cone(&point)?;
        let (w, jc) = cone.map([u[2], u[3]]);
        let cos_r = point.cos_theta(w);
        if cos_r <= 0.0 {
            return Ok(0.0);
        }
        let Some(hit) = e.hit(x, w, 0.0) else {
            return Ok(0.0);
        };
        let front = -e.normal_at(x + w * hit.distance).dot(&w) > 0.0;
        if !front || self.scene.blocked(x, w, 0.0, hit.distance, Some(k)) {
            return Ok(0.0);
        }
        Ok(cos_r * jc * jr)
    }

    /// `F_(dA(x) -> k)`, the form factor from the receiver's point `x` to
    /// emitter `k` with visibility, in closed form (module documentation).
    pub fn point_factor(&self, k: usize, x: Vec3) -> Result<f64, QuadError> {
        let n = self.receiver.normal();
        match self.emitter(k)? {
            AnyEmitter::Disk(d) => {
                if self.scene.has_blockers(Some(k)) {
                    return Err(no_contour("a disk light with something in the way"));
                }
                let disk = d.shape();
                parallel_disk_point(x, n, disk.centre(), disk.frame().n, disk.radius())
            }
            e @ (AnyEmitter::Rectangle(_) | AnyEmitter::Triangle(_)) => {
                self.polygon_point_factor(e, k, x)
            }
            _ => Err(no_contour(
                "a light other than a rectangle, triangle or disk",
            )),
        }
    }
}

impl Transport<'_> {
    /// [`Transport::point_factor`] of a polygon light: Lambert's contour
    /// formula over its lit part, lengths in units of the light's size (so
    /// no cross product under- or overflows), 0 behind it; at a receiver
    /// point in the light's plane, the limit from the light's front side
    /// along the receiver (the value on an edge the two share).
    fn polygon_point_factor(
        &self,
        e: &AnyEmitter<f64>,
        k: usize,
        x: Vec3,
    ) -> Result<f64, QuadError> {
        let n = self.receiver.normal();
        let corners = super::reference::light_corners(e)
            .ok_or_else(|| no_contour("a light that is not a polygon"))?;
        let m = e.normal_at(corners[0]);
        let size = corners
            .iter()
            .map(|c| (c - corners[0]).norm())
            .fold(0.0, f64::max);
        let h = m.dot(&(x - corners[0]));
        let rounding = 64.0 * f64::EPSILON * (x.norm() + corners[0].norm());
        let toward = if h.abs() <= rounding {
            let d = m - n * n.dot(&m);
            if d.norm() <= 1e-12 {
                return Ok(0.0);
            }
            Some(d)
        } else if h < 0.0 {
            return Ok(0.0);
        } else {
            None
        };
        let lit = lit_triangles(self.scene, x, k).ok_or_else(|| {
            no_contour("a blocker whose plane does not separate the receiver from the light")
        })?;
        lit.iter()
            .map(|t| {
                let rel = t.vertices().map(|v| (v - x) / size);
                match toward {
                    Some(d) => polygon_form_factor_toward(Vec3::zeros(), n, &rel, d),
                    None => polygon_form_factor(Vec3::zeros(), n, &rel),
                }
            })
            .sum()
    }
}

fn no_contour(why: &str) -> QuadError {
    QuadError::invalid(
        "form",
        "contour",
        format!(
            "a scene whose point form factor is closed at every receiver point (polygon \
             lights behind polygon blockers whose planes separate them from the receiver, or \
             a disk light parallel to the receiver with nothing in the way); here: {why}"
        ),
    )
}

/// R-A, form factor from a differential area at `x` (unit normal `n`) to a
/// disk (centre `c`, unit normal `m` toward `x`, radius `r`) in a plane
/// parallel to the area's (Howell's element to a parallel disk, offset from
/// its axis by `a`, at height `h`):
///
/// `F = 1/2 [1 - (h^2 + a^2 - r^2) / sqrt((h^2 + a^2 + r^2)^2 - 4 a^2 r^2)]`,
///
/// evaluated without cancellation: with `A = h^2 + a^2 - r^2` and
/// `B = sqrt((h^2 + (a - r)^2)(h^2 + (a + r)^2))`, `B^2 - A^2 = 4 r^2 h^2`,
/// so `F = 2 r^2 h^2 / (B (B + A))` for `A >= 0` and `(B - A) / (2B)`
/// otherwise, lengths in units of the largest. `F = 0` where `x` is behind
/// the disk or in its plane; an error where the planes are not parallel.
pub fn parallel_disk_point(x: Vec3, n: Vec3, c: Vec3, m: Vec3, r: f64) -> Result<f64, QuadError> {
    if n.cross(&m).norm() > 1e-12 || n.dot(&m) > 0.0 {
        return Err(no_contour(
            "a disk light not parallel to the receiver, facing it",
        ));
    }
    let d = x - c;
    let h = m.dot(&d);
    if h <= 0.0 {
        return Ok(0.0);
    }
    let a = (d - m * h).norm();
    // In units of the largest length, so that no square overflows.
    let unit = h.max(a).max(r);
    let (h, a, r) = (h / unit, a / unit, r / unit);
    let big_a = h * h + a * a - r * r;
    let big_b = ((h * h + (a - r) * (a - r)) * (h * h + (a + r) * (a + r))).sqrt();
    Ok(if big_a >= 0.0 {
        2.0 * r * r * h * h / (big_b * (big_b + big_a))
    } else {
        (big_b - big_a) / (2.0 * big_b)
    })
}
