//! Multiple importance sampling of reflected radiance (R-H): light sampling
//! and BRDF sampling combined by the balance or the power heuristic (E.
//! Veach, L. Guibas, "Optimally combining sampling techniques for Monte
//! Carlo rendering", SIGGRAPH 1995; Veach's thesis, 1997, ch. 9), a Monte
//! Carlo estimator with a standard error beside the rules.
//!
//! Each of the `n` samples draws one direction by each strategy:
//!
//! - light: an emitter `k` with probability `1/K`, a direction `wi` toward it
//!   by [`Emitter::sample`] with density `p_l(wi) = pdf_k(wi) / K`;
//! - BRDF: `wi` by [`Brdf::sample`] with density `p_b(wi)`; it reaches the
//!   emitter `j` it sees first (or the lights at infinity), whose light
//!   strategy would have drawn it with `p_l(wi) = pdf_j(wi) / K`;
//!
//! and scores, per emitter reached,
//!
//! `F = w_l f L_e cos / p_l V + w_b f L_e cos / p_b`, `w_l = h(p_l, p_b)`,
//! `w_b = h(p_b, p_l)`,
//!
//! `h(p, q) = p / (p + q)` (balance) or `p^2 / (p^2 + q^2)` (power, `beta =
//! 2`). Since `w_l + w_b = 1` wherever either density is positive, `E[F] =
//! L_r` (Veach's unbiasedness condition). The estimate is the mean of `F`
//! with its standard error (Welford, widened to the Student-t interval as
//! [`crate::quadrature::MonteCarlo`]); [`Heuristic::LightOnly`] and
//! [`Heuristic::BrdfOnly`] give the single strategies for comparison.
//!
//! Irradiance is `pi` times the reflected radiance of a white Lambertian
//! BRDF ([`crate::rendering::brdf::Lambert`] of albedo 1).
//!
//! ```
//! use std::f64::consts::PI;
//! use lightquad::domain::Vec3;
//! use lightquad::exact::rendering::spherical_cap_irradiance;
//! use lightquad::rendering::brdf::Lambert;
//! use lightquad::rendering::emitter::{AnyEmitter, LightSampling, SphereLight};
//! use lightquad::rendering::forms::Reflected;
//! use lightquad::rendering::mis::{Heuristic, mis};
//! use lightquad::rendering::receiver::Receiver;
//! use lightquad::rendering::scene::Scene;
//! use rand::SeedableRng;
//!
//! // A sphere light of radius 0.5 at distance 3 straight above: E = pi L (R/d)^2.
//! let light = SphereLight::new(Vec3::new(0.0, 0.0, 3.0), 0.5, 2.0)?;
//! let scene = Scene::new(vec![AnyEmitter::from(light)], vec![]);
//! let x = Receiver::new(Vec3::zeros(), Vec3::z())?;
//! let white = Lambert::new(1.0)?;
//! let kernel = Reflected::new(&white, &x, Vec3::z())?;
//! let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
//! let est = mis(&scene, &x, &kernel, LightSampling::Cone, Heuristic::Power, 4096, &mut rng)?;
//! let exact = 2.0 * spherical_cap_irradiance(1.0, 0.5 / 3.0)? / PI;
//! assert!((est.value - exact).abs() < 4.0 * est.error);
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use rand::RngExt;

use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::quadrature::monte_carlo::Welford;
use crate::rendering::brdf::Brdf;
use crate::rendering::emitter::{Emitter, LightSampling};
use crate::rendering::forms::{Kernel, Reflected};
use crate::rendering::receiver::Receiver;
use crate::rendering::scene::{FirstHit, Scene};
use crate::value::Value;

/// How the two strategies' samples are weighted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Heuristic {
    /// `h(p, q) = p / (p + q)` (Veach's balance heuristic).
    Balance,
    /// `h(p, q) = p^2 / (p^2 + q^2)` (Veach's power heuristic, `beta = 2`).
    Power,
    /// Light sampling alone (`h = 1` for light samples; no BRDF samples).
    LightOnly,
    /// BRDF sampling alone (`h = 1` for BRDF samples; no light samples).
    BrdfOnly,
}

impl Heuristic {
    /// The weight of a sample drawn by the strategy of density `p` against
    /// the other's `q`: `1 / (1 + (q/p)^beta)`, free of overflow for huge
    /// densities; 0 for `p = 0`, 1 for `q = 0`.
    pub fn weight(&self, p: f64, q: f64) -> f64 {
        if p <= 0.0 || p.is_nan() {
            return 0.0;
        }
        if q <= 0.0 || q.is_nan() {
            return 1.0;
        }
        let ratio = q / p;
        if ratio.is_nan() {
            // Both infinite: no strategy is better.
            return 0.5;
        }
        match self {
            Heuristic::Balance => 1.0 / (1.0 + ratio),
            Heuristic::Power => 1.0 / (1.0 + ratio * ratio),
            Heuristic::LightOnly | Heuristic::BrdfOnly => 1.0,
        }
    }

    fn uses_light(&self) -> bool {
        *self != Heuristic::BrdfOnly
    }

    fn uses_brdf(&self) -> bool {
        *self != Heuristic::LightOnly
    }
}

/// The MIS estimate of `L_r(x, wo)` with `n` samples per strategy
/// (module documentation): light sampling by `sampling`, BRDF sampling by
/// `reflected`'s BRDF, combined by `heuristic`; evaluations counted per
/// strategy sample. Lights of a scene without emitters give 0.
pub fn mis<V: Value, B: Brdf, G: rand::Rng + ?Sized>(
    scene: &Scene<V>,
    receiver: &Receiver,
    reflected: &Reflected<'_, B>,
    sampling: LightSampling,
    heuristic: Heuristic,
    n: usize,
    rng: &mut G,
) -> Result<Estimate<V>, QuadError> {
    if n < 2 {
        return Err(QuadError::invalid(
            "n",
            n,
            "at least 2 samples (a standard error needs two)",
        ));
    }
    if scene.emitters().is_empty() {
        return Ok(Estimate::random(V::zero(), V::zero(), 0));
    }
    let mut acc = Welford::<V>::default();
    let mut evaluations = 0u64;
    for _ in 0..n {
        let (score, spent) = mis_sample(scene, receiver, reflected, sampling, heuristic, rng)?;
        evaluations += spent;
        acc.add(score);
    }
    let estimate = Estimate::random(acc.mean(), acc.interval_error(), evaluations);
    Ok(if acc.doubtful() {
        estimate.doubted()
    } else {
        estimate
    })
}

/// One sample of each strategy of [`mis`] at `receiver` (one of them for
/// the single-strategy heuristics), combined by `heuristic`: the score
/// whose mean over samples is `L_r(x, wo)`, and the evaluations it took.
pub fn mis_sample<V: Value, B: Brdf, G: rand::Rng + ?Sized>(
    scene: &Scene<V>,
    receiver: &Receiver,
    reflected: &Reflected<'_, B>,
    sampling: LightSampling,
    heuristic: Heuristic,
    rng: &mut G,
) -> Result<(V, u64), QuadError> {
    let emitters = scene.emitters();
    if emitters.is_empty() {
        return Ok((V::zero(), 0));
    }
    let pmf = 1.0 / emitters.len() as f64;
    let x = receiver.point();
    let frame = reflected.frame();
    let wo = reflected.wo_local();
    let brdf = reflected.brdf();
    // p_l(w) of the light strategy for emitter j.
    let light_pdf = |j: usize, w| pmf * emitters[j].pdf(receiver, sampling, w);
    let mut evaluations = 0u64;
    let mut score = V::zero();
    if heuristic.uses_light() {
        evaluations += 1;
        let k = ((rng.random::<f64>() * emitters.len() as f64) as usize).min(emitters.len() - 1);
        let u = [rng.random::<f64>(), rng.random::<f64>()];
        if let Some(s) = emitters[k].sample(receiver, sampling, u) {
            let cos = receiver.cos_theta(s.wi);
            let f = if cos > 0.0 {
                reflected.weight(s.wi)
            } else {
                0.0
            };
            let p_l = pmf * s.pdf;
            let seen = f > 0.0
                && if s.distance.is_finite() {
                    scene.visible(x, s.point, Some(k))
                } else {
                    scene.visible_to_infinity(x, s.wi)
                };
            if seen && p_l > 0.0 {
                let p_b = brdf.pdf(wo, frame.to_local(s.wi));
                let w = heuristic.weight(p_l, p_b);
                let c = f * cos / p_l * w;
                score = score.zip(s.radiance, |a, l| a + l * c);
            }
        }
    }
    if heuristic.uses_brdf() {
        evaluations += 1;
        let u = [rng.random::<f64>(), rng.random::<f64>()];
        if let Some(b) = brdf.sample(wo, u) {
            let wi = frame.to_world(b.wi);
            match scene.first_hit(x, wi) {
                FirstHit::Emitter {
                    index, radiance, ..
                } => {
                    let w = heuristic.weight(b.pdf, light_pdf(index, wi));
                    score = score.zip(radiance, |a, l| a + l * b.weight * w);
                }
                FirstHit::Escaped => {
                    for (j, e) in emitters.iter().enumerate() {
                        if !e.at_infinity() {
                            continue;
                        }
                        if let Some(h) = e.hit(x, wi, 0.0) {
                            let w = heuristic.weight(b.pdf, light_pdf(j, wi));
                            score = score.zip(h.radiance, |a, l| a + l * b.weight * w);
                        }
                    }
                }
                FirstHit::Occluder { .. } => {}
            }
        }
    }
    if !score.all_finite() {
        return Err(QuadError::NonFiniteIntegrand {
            point: vec![],
            value: crate::error::channels(score),
        });
    }
    Ok((score, evaluations))
}
