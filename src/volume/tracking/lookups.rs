//! The density look-ups a set of walks is expected to spend, which the
//! runner's cost guard checks before it runs them.

use crate::error::QuadError;
use crate::geometry::Ray;
use crate::volume::scene::VolumeScene;
use crate::volume::terms::ShadowMethod;

use super::radiance::Wanted;
use super::span::{DELTA_SPANS, SPANS, Span, spans, spans_of_shadow};
use super::{Extinction, MAX_COLLISIONS, Tracker};

/// Which walks a cost estimate ([`expected_lookups`]) is for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Walks {
    /// [`transmittance`](super::transmittance)'s, with this tracker.
    Transmittance(Tracker),
    /// [`radiance`](fn@super::radiance)'s, scoring these terms, shadow rays by this method.
    Radiance(ShadowMethod, Wanted),
}

/// The expected density look-ups of one walk along the eye ray of `scene`
/// (its tentative collisions, and a shadow ray's for each where they are
/// tracked), from the spans the walks use, before any walk: what a run
/// costs. Over a span of length `L`, rate `mu` and extinction at least `m`
/// ([`Medium::min_density`](crate::volume::medium::Medium::min_density)):
///
/// - ratio tracking crosses every span: `sum mu L`, `mu = k sigma_bar`
///   (`ratio_rate_factor`); residual ratio tracking's `mu` is its
///   residual bound;
/// - a delta-tracking walk reaches the span with probability at most
///   `S = exp(-sum of m L over the spans before it)`, and then has at most
///   `mu (1 - exp(-m L)) / m` tentative collisions there (`mu L` where
///   `m = 0`): the sum is an upper bound, equal to the expectation where
///   the density is constant;
/// - each tentative collision of a radiance walk that scores V-L casts a
///   shadow ray, ratio tracking over one span where the medium has no
///   closed form for it: on each span of the eye ray, the larger `mu L` of
///   the shadow rays from the span's two ends (an estimate, not a bound:
///   a shadow ray from inside the span may cross more).
pub fn expected_lookups(scene: &VolumeScene, walks: Walks) -> Result<f64, QuadError> {
    let Some(medium) = scene.medium.as_deref() else {
        return Ok(0.0);
    };
    let sigma = Extinction {
        medium,
        lambda: scene.lambda,
    };
    let (ray, t0, t1) = (scene.ray, scene.t_min, scene.t_max);
    let mut unused = 0;
    let crossing = |s: &Span| s.majorant * (s.b - s.a);
    match walks {
        Walks::Transmittance(Tracker::Delta) => {
            let spans = spans(
                Tracker::Delta,
                sigma,
                &ray,
                (t0, t1),
                DELTA_SPANS,
                &mut unused,
            )?;
            Ok(delta_lookups(sigma, &ray, &spans, |s| s.bar).iter().sum())
        }
        Walks::Transmittance(tracker) => {
            let spans = spans(tracker, sigma, &ray, (t0, t1), SPANS, &mut unused)?;
            Ok(spans.iter().map(crossing).sum())
        }
        Walks::Radiance(shadow, wanted) => {
            let spans = spans(Tracker::Delta, sigma, &ray, (t0, t1), SPANS, &mut unused)?;
            let light = scene.light.filter(|_| wanted.light);
            let scoring = light.is_some() || (wanted.emission && scene.emission.is_some());
            // radiance's rate: the bound, or one per span where it is 0 and
            // a walk scores there.
            let rate = |s: &Span| match (s.bar > 0.0, scoring) {
                (true, _) => s.bar,
                (false, true) => 1.0 / (s.b - s.a),
                (false, false) => 0.0,
            };
            let eye = delta_lookups(sigma, &ray, &spans, rate);
            let Some(l) = light else {
                return Ok(eye.iter().sum());
            };
            // A shadow ray's look-ups from the point at `t` of the eye ray.
            let mut shadow_from = |t: f64| -> Result<f64, QuadError> {
                let shadow_ray = Ray {
                    origin: ray.at(t),
                    dir: l.toward_light,
                };
                let closed = shadow == ShadowMethod::ClosedFormWhereAvailable
                    && medium
                        .density_integral(&shadow_ray, 0.0, f64::INFINITY)
                        .is_some();
                // A shadow ray that tracking refuses (too deep a bound)
                // counts at the refusal's threshold: walks that collide
                // near it fail when they run.
                Ok(if closed {
                    0.0
                } else {
                    spans_of_shadow(sigma, &shadow_ray, &mut unused)
                        .map_or((MAX_COLLISIONS / 2) as f64, |s| {
                            s.iter().map(crossing).sum()
                        })
                })
            };
            let mut total = 0.0;
            let mut before = spans.first().map_or(Ok(0.0), |s| shadow_from(s.a))?;
            for (span, eye) in spans.iter().zip(eye) {
                let after = shadow_from(span.b)?;
                total += eye * (1.0 + before.max(after));
                before = after;
            }
            Ok(total)
        }
    }
}

/// The bound of [`expected_lookups`] on a delta-tracking walk's tentative
/// collisions on each of `spans` at the rate `rate(span)`.
fn delta_lookups(
    sigma: Extinction,
    ray: &Ray,
    spans: &[Span],
    rate: impl Fn(&Span) -> f64,
) -> Vec<f64> {
    let mut reach = 1.0;
    let mut each = Vec::with_capacity(spans.len());
    for s in spans {
        let length = s.b - s.a;
        // A span rounded to length 0 takes no collision (its rate may be
        // 1 / 0 where radiance scores on a span without extinction).
        if length <= 0.0 {
            each.push(0.0);
            continue;
        }
        let depth = sigma.lambda * sigma.medium.min_density(ray, s.a, s.b) * length;
        // int_0^L exp(-m t) dt = L (1 - exp(-m L)) / (m L).
        let within = if depth > 0.0 {
            length * (-(-depth).exp_m1() / depth)
        } else {
            length
        };
        each.push(reach * rate(s) * within);
        reach *= (-depth).exp();
    }
    each
}
