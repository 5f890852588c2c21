//! Delta tracking extended from `tau` to V-E, V-B, V-L and V-I.

use rand::RngExt;
use std::f64::consts::PI;

use crate::error::QuadError;
use crate::geometry::Ray;
use crate::quadrature::monte_carlo::power_of_two_above;
use crate::volume::scene::{DirectionalLight, EmissionMap, VolumeScene};
use crate::volume::terms::ShadowMethod;

use super::scores::Scores;
use super::span::{Crossing, SPANS, Span, spans, spans_of_shadow, too_deep};
use super::walks::{free_flight, walk};
use super::{Extinction, MAX_COLLISIONS, Tracked, Tracker, check};

/// What [`radiance`] scores besides `tau`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Wanted {
    /// V-E.
    pub emission: bool,
    /// V-L.
    pub light: bool,
}

/// The quantities of one set of delta-tracking walks along the eye ray, each
/// with the evaluations of all of them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Radiance {
    /// V-tau over the looked-at part.
    pub tau: Tracked,
    /// V-B: `I_b` times each walk's `tau` score.
    pub background: Tracked,
    /// V-E (0 with no error when not wanted or the scene does not emit).
    pub emission: Tracked,
    /// V-L (0 with no error when not wanted or the scene has no light).
    pub light: Tracked,
    /// V-I: each walk's V-E + V-B + V-L scores summed, so the error holds
    /// their covariance.
    pub total: Tracked,
}

/// Estimates V-tau, V-B, V-E, V-L and V-I along the eye ray of `scene` with
/// `n` delta-tracking walks, the way a renderer does (pbrt-v4's volumetric
/// path tracer, restricted to single scattering toward the light):
///
/// A walk draws tentative collisions `t_i` at the piecewise-constant rate
/// `mu` (the span's majorant `sigma_bar`; `1 / span length` on a span whose
/// majorant is 0) and stops at the first that is real (probability
/// `sigma(t_i) / mu`). At every tentative collision before it stops, the
/// stopping one included, it scores
///
/// `[c(v(t_i)) + I_p^(t_i) s(t_i)] / mu(t_i)`,
///
/// with `c` the emission map, `s = albedo sigma / (4 pi)` (V-L with single
/// scattering) or 1 (V-L as printed), and `I_p^(t)` the light reaching
/// `r(t)` (V-Lp): `I_p exp(-lambda int v)` along the shadow ray in closed
/// form where `shadow` allows and the medium has one, else `I_p` times one
/// ratio-tracking walk of the shadow ray (an unbiased estimate of its
/// transmittance, drawn independently of the eye walk).
///
/// Unbiased: the tentative collisions are a Poisson process of rate `mu`,
/// and the walk is still going at `t` exactly when no real collision fell
/// in `[t_n, t)`, which has probability `tau(t_n, t)` (real collisions are
/// the thinned process of rate `sigma`). So the expected sum is
/// `int mu(t) tau(t_n, t) [c + I_p(t) s] / mu dt = I_E + I_L` (V-E, V-L),
/// for every `mu > 0` with `mu >= sigma`, also where `sigma = 0` (where a
/// collision estimator `c / sigma` at the real collision would be undefined
/// and miss the emission). With `s = albedo sigma / (4 pi)` this is the
/// expectation, over the real/null choice, of the renderer's next-event
/// estimate at real collisions (`albedo I_p^ / (4 pi)` with probability
/// `sigma / mu`); the emission part is pbrt-v4's `sigma_a L_e / sigma_maj` at
/// every majorant event. A walk that leaves the looked-at part scores
/// `tau = 1` and `I_b` for V-B.
pub fn radiance<Rg: rand::Rng + ?Sized>(
    scene: &VolumeScene,
    shadow: ShadowMethod,
    wanted: Wanted,
    n: usize,
    rng: &mut Rg,
) -> Result<Radiance, QuadError> {
    scene.validate()?;
    let (t0, t1) = (scene.t_min, scene.t_max);
    check(scene.lambda, t0, t1, n)?;
    let lambda = scene.lambda;
    let ray = scene.ray;
    let background = scene.background.unwrap_or(0.0);
    let emission = scene.emission.as_ref().filter(|_| wanted.emission);
    // Collisions score c(v) of the density they happen at; an emission field
    // of its own (which may emit where the medium does not) is not a map of
    // the density, and walks confined to the medium would miss it.
    if let Some(EmissionMap::Field(_)) = emission {
        return Err(QuadError::invalid(
            "emission",
            "field",
            "a map of the density (constant, proportional, table) for delta tracking, which \
             scores c(v) at its collisions; integrate an emission field with a quadrature rule",
        ));
    }
    let light = scene.light.filter(|_| wanted.light);
    let Some(medium) = scene.medium.as_deref() else {
        // No medium: tau = 1, I_B = I_b, no emission and no scattering.
        let exact = |value: f64| Tracked {
            value,
            error: 0.0,
            evaluations: 0,
            walks: n as u64,
            all_alike: false,
            heavy: false,
            underflows: false,
        };
        return Ok(Radiance {
            tau: exact(1.0),
            background: exact(background),
            emission: exact(0.0),
            light: exact(0.0),
            total: exact(background),
        });
    };
    let sigma = Extinction { medium, lambda };
    let mut evaluations = 0u64;
    let spans = spans(
        Tracker::Delta,
        sigma,
        &ray,
        (t0, t1),
        SPANS,
        &mut evaluations,
    )?;
    let scoring = emission.is_some() || light.is_some();

    // The largest score one tentative collision can add on a span, for the
    // bound of Tracked::all_alike: |c| at the density bound (constant and
    // proportional maps are monotone in v; a table's largest value bounds it
    // anywhere) and I_p s at the density bound, over the rate.
    let rate = |span: &Span| {
        if span.bar > 0.0 {
            span.bar
        } else {
            1.0 / (span.b - span.a)
        }
    };
    let largest_c = |span: &Span, map: &EmissionMap| match map {
        EmissionMap::Table(table) => table.points().iter().map(|p| p.1.abs()).fold(0.0, f64::max),
        _ => map.at(span.v_bar).abs(),
    };
    let largest_s =
        |span: &Span, l: &DirectionalLight| l.albedo.map_or(1.0, |a| a * span.bar / (4.0 * PI));
    // Scores are summed in units: a power of two no smaller than the largest
    // |c| (V-E) or I_p s (V-L), so that one collision's `c / mu` stays finite
    // where `mu` is small (c = 8e306 and sigma = 2.6e-3 overflowed to inf
    // although I_E is 4e304) and scaling back is exact.
    let unit_of = |largest: f64| {
        if largest > 0.0 && largest.is_finite() {
            power_of_two_above(largest)
        } else {
            1.0
        }
    };
    let em_unit = unit_of(emission.map_or(0.0, |map| {
        spans.iter().map(|s| largest_c(s, map)).fold(0.0, f64::max)
    }));
    let li_unit = unit_of(light.map_or(0.0, |l| {
        spans
            .iter()
            .map(|s| l.intensity * largest_s(s, &l))
            .fold(0.0, f64::max)
    }));
    let total_unit = em_unit.max(li_unit).max(unit_of(background.abs()));
    let mut one_emission: f64 = 0.0;
    let mut one_light: f64 = 0.0;
    for span in &spans {
        if let Some(map) = emission {
            one_emission = one_emission.max(largest_c(span, map) / em_unit / rate(span));
        }
        if let Some(l) = light {
            one_light = one_light.max(l.intensity / li_unit * largest_s(span, &l) / rate(span));
        }
    }

    let (mut tau_s, mut bg_s, mut em_s, mut li_s, mut tot_s) = (
        Scores::default(),
        Scores::default(),
        Scores::default(),
        Scores::default(),
        Scores::default(),
    );
    for _ in 0..n {
        let (mut alive, mut em, mut li) = (true, 0.0, 0.0);
        'spans: for span in &spans {
            // Spans without extinction are crossed without tentative
            // collisions unless emission or light is scored on them.
            if span.bar <= 0.0 && !scoring {
                continue;
            }
            let mu = rate(span);
            let mut t = span.a;
            let mut collisions = 0u64;
            loop {
                t += free_flight(rng) / mu;
                if t >= span.b {
                    break;
                }
                evaluations += 1;
                collisions += 1;
                if collisions > MAX_COLLISIONS {
                    return Err(too_deep(span, MAX_COLLISIONS));
                }
                let p = ray.at(t);
                let v = medium.density(p);
                let sigma_t = lambda * v;
                if let Some(map) = emission {
                    em += map.at(v) / em_unit / mu;
                }
                if let Some(l) = light {
                    let shadow_ray = Ray {
                        origin: p,
                        dir: l.toward_light,
                    };
                    let closed = match shadow {
                        ShadowMethod::ClosedFormWhereAvailable => {
                            medium.density_integral(&shadow_ray, 0.0, f64::INFINITY)
                        }
                        ShadowMethod::Quadrature => None,
                    };
                    let shadow_tau = match closed {
                        Some(integral) => (-lambda * integral).exp(),
                        None => {
                            let mut evals = 0;
                            let s = spans_of_shadow(sigma, &shadow_ray, &mut evals)?;
                            let c = Crossing::of(&s);
                            let tau = walk(sigma, &shadow_ray, 1.0, &c, &mut evals, rng)?;
                            evaluations += evals;
                            tau
                        }
                    };
                    let s = l.albedo.map_or(1.0, |a| a * sigma_t / (4.0 * PI));
                    li += l.intensity / li_unit * shadow_tau * s / mu;
                }
                if rng.random::<f64>() < sigma_t / mu {
                    alive = false;
                    break 'spans;
                }
            }
        }
        let tau = if alive { 1.0 } else { 0.0 };
        tau_s.add(tau);
        bg_s.add(background * tau);
        em_s.add(em);
        li_s.add(li);
        tot_s.add(
            em * (em_unit / total_unit)
                + background / total_unit * tau
                + li * (li_unit / total_unit),
        );
    }
    let tau = tau_s.binary(evaluations);
    let scaled = |t: Tracked, s: f64| Tracked {
        value: t.value * s,
        error: t.error * s,
        ..t
    };
    // An unseen outcome moves a V-E, V-L or V-I score by at most the larger
    // of its own size and one tentative collision's largest score (plus I_b
    // for the escape or not of V-I).
    let unseen = |one: f64| move |x: f64| x.abs().max(one);
    // A term the scene lacks (or that was not asked for) is exactly 0; the
    // others are scaled back from their units.
    let term = |present: bool, scores: &Scores, one: f64, unit: f64| {
        if present {
            scaled(scores.tracked(evaluations, unseen(one)), unit)
        } else {
            Tracked {
                value: 0.0,
                error: 0.0,
                evaluations,
                walks: n as u64,
                all_alike: false,
                heavy: false,
                underflows: false,
            }
        }
    };
    let one_total = one_emission * (em_unit / total_unit)
        + one_light * (li_unit / total_unit)
        + background.abs() / total_unit;
    Ok(Radiance {
        tau,
        background: scaled(tau, background),
        emission: term(emission.is_some(), &em_s, one_emission, em_unit),
        light: term(light.is_some(), &li_s, one_light, li_unit),
        total: scaled(tot_s.tracked(evaluations, unseen(one_total)), total_unit),
    })
}
