//! One job's quantity by its method: a rule over one of the forms (R-H by
//! its uniform, projected or BRDF-sampled map, the cone form, R-A) or
//! multiple importance sampling, with the work it took beside the
//! integrand's evaluations.

use std::cell::Cell;
use std::f64::consts::PI;

use crate::domain::{HemisphereMap, Vec3, integrate_over};
use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::family::{self, Measured, Method};
use crate::quadrature::Rule;
use crate::rendering::brdf::Lambert;
use crate::rendering::emitter::{Emitter, LightSampling};
use crate::rendering::forms::{self, Irradiance, Kernel, Reflected};
use crate::rendering::mis::mis;

use super::{AnyBrdf, Built, Form, Mis, NEEDS_BRDF, RenderingQuantity, Work};

/// One quantity by `method` at `budget`, with the work it took beside the
/// integrand evaluations ([`Work`]).
pub fn evaluate_counted(
    built: &Built,
    method: &Method<Mis>,
    budget: usize,
    rng: &mut rand_pcg::Pcg64,
    q: RenderingQuantity,
) -> Result<(Measured, Work), QuadError> {
    let shadow_rays = Cell::new(0);
    let estimate = match method {
        Method::Rule(rule) => by_rule(built, rule, q, budget, rng, &shadow_rays)?,
        Method::Estimator(mis) => by_mis(built, *mis, q, budget, rng)?,
    };
    Ok((
        Measured::from(estimate),
        Work {
            shadow_rays: shadow_rays.get(),
        },
    ))
}

/// The reflected-radiance kernel of the scene's BRDF for its viewer, or
/// the error naming what is missing.
pub(super) fn reflected_kernel(built: &Built) -> Result<Reflected<'_, AnyBrdf>, QuadError> {
    let (Some(brdf), Some(wo)) = (built.brdf.as_ref(), built.toward_viewer) else {
        return Err(QuadError::invalid("brdf", "none", NEEDS_BRDF));
    };
    Reflected::new(brdf, &built.receiver, wo)
}

/// `q` by a quadrature rule.
fn by_rule<R: Rule>(
    built: &Built,
    rule: &R,
    q: RenderingQuantity,
    n: usize,
    rng: &mut rand_pcg::Pcg64,
    shadow_rays: &Cell<u64>,
) -> Result<Estimate<f64>, QuadError> {
    if !q.reflected() {
        return by_form(built, &Irradiance, q.form(), rule, n, rng, shadow_rays);
    }
    let kernel = reflected_kernel(built)?;
    if q.form() == Form::Brdf {
        return forms::brdf_sampled(rule, &built.scene, &built.receiver, &kernel, n, rng);
    }
    by_form(built, &kernel, q.form(), rule, n, rng, shadow_rays)
}

/// The form `form` of the integral of kernel `K` ([`forms`]).
fn by_form<K: Kernel, R: Rule>(
    built: &Built,
    kernel: &K,
    form: Form,
    rule: &R,
    n: usize,
    rng: &mut rand_pcg::Pcg64,
    shadow_rays: &Cell<u64>,
) -> Result<Estimate<f64>, QuadError> {
    let (scene, receiver) = (&built.scene, &built.receiver);
    match form {
        Form::Hemisphere => forms::hemispherical(
            rule,
            scene,
            receiver,
            kernel,
            HemisphereMap::Uniform,
            n,
            rng,
        ),
        Form::Cosine => forms::hemispherical(
            rule,
            scene,
            receiver,
            kernel,
            HemisphereMap::Projected,
            n,
            rng,
        ),
        Form::Cone => forms::cone(rule, scene, receiver, kernel, n, rng),
        Form::Area => area_counted(built, kernel, rule, n, rng, shadow_rays),
        Form::Brdf => Err(QuadError::invalid(
            "quantity",
            "a BRDF-sampled irradiance",
            "L_brdf (irradiance has no BRDF to sample)",
        )),
    }
}

/// R-A as [`forms::area`] evaluates it, each shadow ray counted (by
/// wrapping [`forms::area_visibility`]).
fn area_counted<K: Kernel, R: Rule>(
    built: &Built,
    kernel: &K,
    rule: &R,
    n: usize,
    rng: &mut rand_pcg::Pcg64,
    shadow_rays: &Cell<u64>,
) -> Result<Estimate<f64>, QuadError> {
    let (scene, receiver) = (&built.scene, &built.receiver);
    let mut total = Estimate::zero();
    for (k, e) in scene.emitters().iter().enumerate() {
        let domain = e.surface(receiver)?;
        let skip = if e.at_infinity() { None } else { Some(k) };
        let tested = scene.has_blockers(skip);
        let base = forms::area_visibility(scene, receiver.point(), k);
        let visible = |y: Vec3| {
            if tested {
                shadow_rays.set(shadow_rays.get() + 1);
            }
            base(y)
        };
        let g = forms::area_integrand_with(scene, receiver, kernel, k, visible)?;
        total = total.combine(integrate_over(rule, &domain, n, rng, g)?);
    }
    Ok(total)
}

/// `q` by MIS: light samples by the quantity's form, BRDF samples of the
/// scene's BRDF (of a white Lambertian one, times `pi`, for irradiance).
fn by_mis(
    built: &Built,
    mis_kind: Mis,
    q: RenderingQuantity,
    n: usize,
    rng: &mut rand_pcg::Pcg64,
) -> Result<Estimate<f64>, QuadError> {
    let sampling = match q.form() {
        Form::Area => LightSampling::Area,
        Form::Cone => LightSampling::Cone,
        _ => {
            return Err(QuadError::invalid(
                "quantity",
                family::Quantity::name(&q),
                "one of E_area, E_cone, L_area, L_cone for MIS (its light strategy is the form)",
            ));
        }
    };
    let (scene, receiver) = (&built.scene, &built.receiver);
    let heuristic = mis_kind.heuristic();
    if q.reflected() {
        let kernel = reflected_kernel(built)?;
        return mis(scene, receiver, &kernel, sampling, heuristic, n, rng);
    }
    let white = Lambert::new(1.0)?;
    let kernel = Reflected::new(&white, receiver, receiver.normal())?;
    Ok(mis(scene, receiver, &kernel, sampling, heuristic, n, rng)?.scaled(PI))
}
