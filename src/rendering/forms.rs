//! Irradiance `E(x, n)` and reflected radiance `L_r(x, wo)` at a receiver,
//! by the hemispherical form R-H and the area form R-A, as integrands over
//! the domains of [`crate::domain`] so that every [`Rule`] integrates them
//! ([`integrate_over`]).
//!
//! **R-H** (integral over solid angle, Kajiya 1986):
//!
//! `L_r(x, wo) = int_H f_r(wi, wo) L_i(x, wi) cos theta_i d wi`, `E(x, n) =
//! int_H L_i(x, wi) cos theta_i d wi`,
//!
//! with `L_i` from [`Scene::incident`] (a ray cast per evaluation). Domains:
//! the receiver's hemisphere with the uniform, cosine or projected map
//! ([`HemisphereMap`]; the projected map carries the cosine in its measure,
//! so its integrand drops it), the BRDF-sampled map [`BrdfSampled`]
//! (`|J| = 1 / pdf`, through [`Brdf::sample`] and [`Brdf::invert`]), and,
//! per emitter, the cone of directions that contains it ([`cone`]: the
//! integral of that emitter's part of `L_i`, [`Scene::incident_from`]).
//! Over the hemisphere a bounded light makes the integrand discontinuous
//! at its outline, and product rules converge only algebraically there;
//! over the exact cone of a sphere, a cap light or a disk seen from its
//! axis the integrand is smooth and Gauss–Legendre converges spectrally.
//!
//! **R-A** (integral over the emitters' surfaces, the change of variables
//! `d wi = cos theta' dA / r^2`):
//!
//! `L_r(x, wo) = sum_lights int_A L_e f_r(wi, wo) cos theta cos theta' / r^2
//! V(x, y) dA`, `wi = (y - x)/r`,
//!
//! over each emitter's [`Emitter::surface`] through its map and Jacobian;
//! for a light at infinity, over its cap of directions, `L_e f_r cos theta
//! V(x, w) d omega` (R-H restricted to the light). The factor `V / r^2` is
//! the geometry term `g` of R-3P.
//!
//! Each form returns an [`Estimate`]; sums over emitters combine the
//! per-emitter estimates ([`Estimate::combine`]), `n` evaluations each.
//! Where the kernel is zero (a direction below the horizon, outside a BRDF
//! lobe) no ray is cast.
//!
//! ```
//! use std::f64::consts::PI;
//! use lightquad::domain::Vec3;
//! use lightquad::exact::rendering::disk_coaxial;
//! use lightquad::quadrature::GaussLegendre;
//! use lightquad::rendering::emitter::{AnyEmitter, DiskLight};
//! use lightquad::rendering::forms::{self, Irradiance};
//! use lightquad::rendering::receiver::Receiver;
//! use lightquad::rendering::scene::Scene;
//! use rand::SeedableRng;
//!
//! // A disk light of radius 1 at height 2 facing the receiver: E = pi L F.
//! let light = DiskLight::new(Vec3::new(0.0, 0.0, 2.0), -Vec3::z(), 1.0, 1.5)?;
//! let scene = Scene::new(vec![AnyEmitter::from(light)], vec![]);
//! let x = Receiver::new(Vec3::zeros(), Vec3::z())?;
//! let exact = PI * 1.5 * disk_coaxial(2.0, 1.0)?;
//! let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
//! let gl = GaussLegendre::default();
//! let by_area = forms::area(&gl, &scene, &x, &Irradiance, 256, &mut rng)?;
//! let by_cone = forms::cone(&gl, &scene, &x, &Irradiance, 256, &mut rng)?;
//! assert!((by_area.value / exact - 1.0).abs() < 1e-13);
//! assert!((by_cone.value / exact - 1.0).abs() < 1e-13);
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use std::f64::consts::PI;

use crate::domain::{Domain, Frame, HemisphereMap, Vec3, integrate_over};
use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::quadrature::Rule;
use crate::rendering::brdf::{Brdf, Ggx, Lambert, NormalizedPhong, Phong};
use crate::rendering::emitter::{AnyEmitter, Emitter};
use crate::rendering::receiver::{Receiver, unit_direction};
use crate::rendering::scene::Scene;
use crate::value::Value;

/// What incident radiance is weighted with: `1` for irradiance, `f_r(wi,
/// wo)` for reflected radiance.
pub trait Kernel {
    /// The weight of the unit world direction `wi`.
    fn weight(&self, wi: Vec3) -> f64;

    /// The unit world normal of the plane through the receiver beyond which
    /// the weight is clamped to zero with a kink ([`Brdf::clamp`]); `None`
    /// where the weight has no such clamp.
    fn clamp(&self) -> Option<Vec3> {
        None
    }
}

/// The kernel of irradiance, `E = int L_i cos theta d w`: weight 1.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Irradiance;

impl Kernel for Irradiance {
    fn weight(&self, _: Vec3) -> f64 {
        1.0
    }
}

/// The kernel of reflected radiance toward `wo`: `f_r(wi, wo)` in the
/// receiver's shading frame.
#[derive(Debug)]
pub struct Reflected<'a, B: Brdf> {
    brdf: &'a B,
    frame: Frame,
    wo: Vec3,
}

// By hand: a derive would ask `B: Copy`, but only the reference is copied.
impl<B: Brdf> Clone for Reflected<'_, B> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<B: Brdf> Copy for Reflected<'_, B> {}

impl<'a, B: Brdf> Reflected<'a, B> {
    /// `f_r(., wo)` at `receiver` for the world direction `wo` toward the
    /// viewer (finite, non-zero; normalised). Below the horizon every BRDF
    /// is zero, and so is `L_r`.
    pub fn new(brdf: &'a B, receiver: &Receiver, wo: Vec3) -> Result<Self, QuadError> {
        let wo = unit_direction("wo", wo)?;
        let frame = receiver.frame();
        Ok(Reflected {
            brdf,
            frame,
            wo: frame.to_local(wo),
        })
    }

    /// The BRDF.
    pub fn brdf(&self) -> &B {
        self.brdf
    }

    /// `wo` in the shading frame.
    pub fn wo_local(&self) -> Vec3 {
        self.wo
    }

    /// The shading frame.
    pub fn frame(&self) -> Frame {
        self.frame
    }
}

impl<B: Brdf> Kernel for Reflected<'_, B> {
    /// `f_r(wi, wo)` (R-H).
    fn weight(&self, wi: Vec3) -> f64 {
        self.brdf.eval(self.frame.to_local(wi), self.wo)
    }

    fn clamp(&self) -> Option<Vec3> {
        self.brdf.clamp(self.wo).map(|r| self.frame.to_world(r))
    }
}

/// The solid angle of the directions above the horizon that a BRDF's
/// sampling map reaches for a given `wo` (where its pdf is positive): the
/// measure of [`BrdfSampled`].
pub trait Reach {
    /// The solid angle reached for `wo` (local frame, above the horizon).
    fn reach(&self, wo: Vec3) -> f64;
}

impl Reach for Lambert {
    /// The whole hemisphere, `2 pi`.
    fn reach(&self, _: Vec3) -> f64 {
        2.0 * PI
    }
}

/// The lune between the upper hemisphere and the hemisphere about the
/// mirror direction (at `theta_o` from the normal): `2 (pi - theta_o)`.
fn lobe_reach(wo: Vec3) -> f64 {
    2.0 * (PI - wo.x.hypot(wo.y).atan2(wo.z))
}

impl Reach for Phong {
    /// `2 (pi - theta_o)`: the lobe about the mirror direction covers its
    /// hemisphere.
    fn reach(&self, wo: Vec3) -> f64 {
        lobe_reach(wo)
    }
}

impl Reach for NormalizedPhong {
    /// `2 (pi - theta_o)`, as [`Phong`].
    fn reach(&self, wo: Vec3) -> f64 {
        lobe_reach(wo)
    }
}

impl Reach for Ggx {
    /// `2 pi`: every `wi` above the horizon has a half vector above it.
    fn reach(&self, _: Vec3) -> f64 {
        2.0 * PI
    }
}

/// The BRDF-sampled map of the hemisphere: `u -> wi` by [`Brdf::sample`]
/// for the viewer `wo`, `|J| = 1 / pdf(wo, wi)`, so that `int_H g(wi) d wi
/// = int g(wi(u)) / pdf du` over the directions the map reaches (all of
/// the BRDF's support). Where the map sends `u` below the horizon the point
/// is the zero vector and `|J| = 0` (an integrand of R-H is zero there
/// without casting a ray).
#[derive(Debug, Clone, Copy)]
pub struct BrdfSampled<'a, B: Brdf> {
    reflected: Reflected<'a, B>,
}

impl<'a, B: Brdf> BrdfSampled<'a, B> {
    /// The map of `reflected`'s BRDF for its `wo`.
    pub fn new(reflected: Reflected<'a, B>) -> Self {
        BrdfSampled { reflected }
    }
}

impl<B: Brdf + Reach> Domain<2> for BrdfSampled<'_, B> {
    type Point = Vec3;

    fn map(&self, u: [f64; 2]) -> (Vec3, f64) {
        let r = &self.reflected;
        match r.brdf.sample(r.wo, u) {
            Some(s) if s.pdf > 0.0 => (r.frame.to_world(s.wi), 1.0 / s.pdf),
            _ => (Vec3::zeros(), 0.0),
        }
    }

    fn invert(&self, w: &Vec3) -> Option<[f64; 2]> {
        let r = &self.reflected;
        let local = r.frame.to_local(*w);
        if local.z <= 0.0 || local.z.is_nan() {
            return None;
        }
        r.brdf.invert(r.wo, local)
    }

    /// [`Reach::reach`]: the solid angle the map covers.
    fn measure(&self) -> f64 {
        self.reflected.brdf.reach(self.reflected.wo)
    }
}

/// `(K(w), cos theta)` for a direction above the receiver's horizon whose
/// kernel weight is not 0; `None` where the integrand is 0 without a ray
/// cast.
fn above_horizon<K: Kernel>(receiver: &Receiver, kernel: &K, w: Vec3) -> Option<(f64, f64)> {
    let cos = receiver.cos_theta(w);
    let weight = if cos > 0.0 { kernel.weight(w) } else { 0.0 };
    (weight != 0.0).then_some((weight, cos))
}

/// R-H's integrand over the receiver's hemisphere with the map `map` (and
/// over [`BrdfSampled`], with [`HemisphereMap::Uniform`]'s integrand):
/// `w -> K(w) L_i(x, w) cos theta`, the cosine left out for
/// [`HemisphereMap::Projected`], whose measure carries it. Zero without a
/// ray cast where `K(w) cos theta = 0`.
pub fn hemispherical_integrand<'a, V: Value, K: Kernel>(
    scene: &'a Scene<V>,
    receiver: &'a Receiver,
    kernel: &'a K,
    map: HemisphereMap,
) -> impl Fn(Vec3) -> V + 'a {
    let x = receiver.point();
    move |w: Vec3| {
        let Some((weight, cos)) = above_horizon(receiver, kernel, w) else {
            return V::zero();
        };
        let factor = if map == HemisphereMap::Projected {
            weight
        } else {
            weight * cos
        };
        scene.incident(x, w).map(|l| l * factor)
    }
}

/// R-H restricted to emitter `k`: `w -> K(w) L_i^k(x, w) cos theta` with
/// `L_i^k` the part of `L_i` that emitter `k` contributes
/// ([`Scene::incident_from`]), over the cone of [`Emitter::cone`].
pub fn cone_integrand<'a, V: Value, K: Kernel>(
    scene: &'a Scene<V>,
    receiver: &'a Receiver,
    kernel: &'a K,
    k: usize,
) -> impl Fn(Vec3) -> V + 'a {
    let x = receiver.point();
    move |w: Vec3| {
        let Some((weight, cos)) = above_horizon(receiver, kernel, w) else {
            return V::zero();
        };
        scene.incident_from(k, x, w).map(|l| l * weight * cos)
    }
}

/// Emitter `k` of the scene; an index past its emitters is an error naming
/// `k`.
pub fn emitter_at<V: Value>(scene: &Scene<V>, k: usize) -> Result<&AnyEmitter<V>, QuadError> {
    let count = scene.emitters().len();
    scene.emitters().get(k).ok_or_else(|| {
        QuadError::invalid(
            "k",
            k,
            format!("an emitter index below {count}, the scene's number of emitters"),
        )
    })
}

/// R-A's integrand over the surface of emitter `k` ([`Emitter::surface`]):
///
/// `y -> L_e K(wi) cos theta cos theta' / r^2 V(x, y)`, `r = |y - x|`, `wi =
/// (y - x)/r`, `cos theta = n . wi`, `cos theta' = -n_y . wi`, each clamped
/// at 0 (R-A, the geometry term `g` of R-3P); for a light at infinity, whose
/// domain is its cap of directions, `w -> L_e K(w) cos theta V(x, w)`.
/// Zero without a shadow ray where the cosines or the kernel vanish, and
/// without one anywhere when nothing can block the emitter
/// ([`Scene::has_blockers`]). An index `k` past the scene's emitters is an
/// error naming `k`.
pub fn area_integrand<'a, V: Value, K: Kernel>(
    scene: &'a Scene<V>,
    receiver: &'a Receiver,
    kernel: &'a K,
    k: usize,
) -> Result<impl Fn(Vec3) -> V + 'a, QuadError> {
    let visible = area_visibility(scene, receiver.point(), k);
    area_integrand_with(scene, receiver, kernel, k, visible)
}

/// R-A's visibility term for emitter `k` seen from `x`, as
/// [`area_integrand`] evaluates it: `V(x, y)` for a point `y` on a finite
/// emitter ([`Scene::visible`], the emitter itself not tested), `V(x, w)`
/// toward the lights at infinity for a direction `w`
/// ([`Scene::visible_to_infinity`]); the constant 1, with no ray cast, when
/// nothing can block the emitter ([`Scene::has_blockers`]).
pub fn area_visibility<V: Value>(
    scene: &Scene<V>,
    x: Vec3,
    k: usize,
) -> impl Fn(Vec3) -> bool + '_ {
    let infinite = scene.emitters().get(k).is_some_and(|e| e.at_infinity());
    let skip = if infinite { None } else { Some(k) };
    let tested = scene.has_blockers(skip);
    move |y: Vec3| {
        !tested
            || if infinite {
                scene.visible_to_infinity(x, y)
            } else {
                scene.visible(x, y, Some(k))
            }
    }
}

/// [`area_integrand`] with the visibility term `visible` (called only where
/// the rest of the integrand is non-zero): a caller that counts shadow rays
/// wraps [`area_visibility`] (counting by wrapping, as the rules' evaluations
/// are counted).
pub fn area_integrand_with<'a, V: Value, K: Kernel, W: Fn(Vec3) -> bool + 'a>(
    scene: &'a Scene<V>,
    receiver: &'a Receiver,
    kernel: &'a K,
    k: usize,
    visible: W,
) -> Result<impl Fn(Vec3) -> V + 'a, QuadError> {
    let x = receiver.point();
    let emitter = emitter_at(scene, k)?;
    let infinite = emitter.at_infinity();
    let radiance = emitter.radiance();
    Ok(move |y: Vec3| {
        if infinite {
            let cos = receiver.cos_theta(y);
            let weight = if cos > 0.0 { kernel.weight(y) } else { 0.0 };
            if weight == 0.0 || !visible(y) {
                return V::zero();
            }
            return radiance.map(|l| l * weight * cos);
        }
        let d = y - x;
        let r2 = d.norm_squared();
        let r = r2.sqrt();
        if r <= 0.0 || r.is_nan() {
            return V::zero();
        }
        let wi = d / r;
        let cos = receiver.cos_theta(wi);
        let cos_light = -emitter.normal_at(y).dot(&wi);
        if !(cos > 0.0 && cos_light > 0.0) {
            return V::zero();
        }
        let weight = kernel.weight(wi);
        if weight == 0.0 || !visible(y) {
            return V::zero();
        }
        let g = weight * cos * cos_light / r2;
        radiance.map(|l| l * g)
    })
}

/// R-H over the receiver's hemisphere with the map `map` and a budget of
/// `n` evaluations.
pub fn hemispherical<V: Value, K: Kernel, R: Rule, G: rand::Rng + ?Sized>(
    rule: &R,
    scene: &Scene<V>,
    receiver: &Receiver,
    kernel: &K,
    map: HemisphereMap,
    n: usize,
    rng: &mut G,
) -> Result<Estimate<V>, QuadError> {
    integrate_over(
        rule,
        &receiver.hemisphere(map),
        n,
        rng,
        hemispherical_integrand(scene, receiver, kernel, map),
    )
}

/// R-H over the BRDF-sampled map of `reflected` ([`BrdfSampled`]), `n`
/// evaluations: `L_r = int f L_i cos / pdf du`.
pub fn brdf_sampled<V: Value, B: Brdf + Reach, R: Rule, G: rand::Rng + ?Sized>(
    rule: &R,
    scene: &Scene<V>,
    receiver: &Receiver,
    reflected: &Reflected<'_, B>,
    n: usize,
    rng: &mut G,
) -> Result<Estimate<V>, QuadError> {
    integrate_over(
        rule,
        &BrdfSampled::new(*reflected),
        n,
        rng,
        hemispherical_integrand(scene, receiver, reflected, HemisphereMap::Uniform),
    )
}

/// R-H as a sum over emitters, each over its cone of directions
/// ([`cone_integrand`]), `n` evaluations per emitter.
pub fn cone<V: Value, K: Kernel, R: Rule, G: rand::Rng + ?Sized>(
    rule: &R,
    scene: &Scene<V>,
    receiver: &Receiver,
    kernel: &K,
    n: usize,
    rng: &mut G,
) -> Result<Estimate<V>, QuadError> {
    let mut total = Estimate::zero();
    for (k, e) in scene.emitters().iter().enumerate() {
        let domain = e.cone(receiver)?;
        let part = integrate_over(
            rule,
            &domain,
            n,
            rng,
            cone_integrand(scene, receiver, kernel, k),
        )?;
        total = total.combine(part);
    }
    Ok(total)
}

/// R-A as a sum over emitters, each over its surface ([`area_integrand`]),
/// `n` evaluations per emitter. An emitter whose domain cannot be built
/// from the receiver (a receiver inside a sphere light) is an error.
pub fn area<V: Value, K: Kernel, R: Rule, G: rand::Rng + ?Sized>(
    rule: &R,
    scene: &Scene<V>,
    receiver: &Receiver,
    kernel: &K,
    n: usize,
    rng: &mut G,
) -> Result<Estimate<V>, QuadError> {
    let mut total = Estimate::zero();
    for (k, e) in scene.emitters().iter().enumerate() {
        let domain = e.surface(receiver)?;
        let g = area_integrand(scene, receiver, kernel, k)?;
        let part = integrate_over(rule, &domain, n, rng, g)?;
        total = total.combine(part);
    }
    Ok(total)
}
