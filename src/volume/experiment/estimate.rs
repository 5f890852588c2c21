//! A job's evaluation: the scene cut to the terms its quantities need, the
//! trackers' estimates, and the terms collected into measured values.

use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::family::{self, Family, Flag, Measured, Outcome};
use crate::volume::terms::transmittance_error;
use crate::volume::tracking::{Extinction, Tracked, Tracker, Wanted, radiance, transmittance};
use crate::volume::{Term, VolumeResult, VolumeScene};

use super::{Built, Volume, VolumeQuantity};

/// The scene with only the terms `quantities` need (every term feeds V-I;
/// V-tau is always evaluated): asking for tau alone costs no emission or
/// light integral.
pub(super) fn needed(scene: &VolumeScene, quantities: &[VolumeQuantity]) -> VolumeScene {
    let wants = |q: VolumeQuantity| {
        quantities
            .iter()
            .any(|&x| x == q || x == VolumeQuantity::Total)
    };
    let mut out = scene.clone();
    if !wants(VolumeQuantity::Emission) {
        out.emission = None;
    }
    if !wants(VolumeQuantity::Background) {
        out.background = None;
    }
    if !wants(VolumeQuantity::Light) {
        out.light = None;
    }
    out
}

/// `quantities` by `tracker` with `budget` walks: `tau` and `I_B` from
/// [`transmittance`] alone, anything else from one set of delta-tracking
/// walks ([`radiance`]); a quantity the tracker does not estimate is an error
/// (validation refuses it first, [`Volume::estimates`]).
pub(super) fn estimate(
    built: &Built,
    tracker: Tracker,
    budget: usize,
    rng: &mut rand_pcg::Pcg64,
    quantities: &[VolumeQuantity],
) -> Result<Outcome<VolumeQuantity>, QuadError> {
    let can = <Volume as Family>::estimates(&tracker);
    if let Some(q) = quantities.iter().find(|q| !can.contains(q)) {
        let names: Vec<_> = can.iter().map(family::Quantity::name).collect();
        return Err(QuadError::invalid(
            "quantity",
            family::Quantity::name(q),
            format!("one of {} for {}", names.join(", "), tracker.name()),
        ));
    }
    // Measured from the start of the medium's support, as the quadrature terms are
    // (VolumeScene::anchored).
    let (anchored, _) = built.scene.anchored();
    let scene = &anchored;
    let background = scene.background.unwrap_or(0.0);
    let only_tau = quantities
        .iter()
        .all(|q| matches!(q, VolumeQuantity::Tau | VolumeQuantity::Background));
    let out: Vec<(VolumeQuantity, Tracked)> = if only_tau {
        let tau = match scene.medium.as_deref() {
            // No medium: tau = 1 with no work.
            None => Tracked {
                value: 1.0,
                error: 0.0,
                evaluations: 0,
                walks: budget as u64,
                all_alike: false,
                heavy: false,
                underflows: false,
            },
            Some(medium) => {
                let sigma = Extinction {
                    medium,
                    lambda: scene.lambda,
                };
                let (t0, t1) = (scene.t_min, scene.t_max);
                transmittance(tracker, sigma, &scene.ray, t0, t1, budget, rng)?
            }
        };
        quantities
            .iter()
            .map(|&q| {
                let s = if q == VolumeQuantity::Background {
                    background
                } else {
                    1.0
                };
                let t = Tracked {
                    value: s * tau.value,
                    error: s * tau.error,
                    ..tau
                };
                (q, t)
            })
            .collect()
    } else {
        let wanted = Wanted {
            emission: quantities
                .iter()
                .any(|q| matches!(q, VolumeQuantity::Emission | VolumeQuantity::Total)),
            light: quantities
                .iter()
                .any(|q| matches!(q, VolumeQuantity::Light | VolumeQuantity::Total)),
        };
        let r = radiance(scene, built.shadow, wanted, budget, rng)?;
        quantities
            .iter()
            .filter_map(|&q| {
                let t = match q {
                    VolumeQuantity::Tau => r.tau,
                    VolumeQuantity::Background => r.background,
                    VolumeQuantity::Emission => r.emission,
                    VolumeQuantity::Light => r.light,
                    VolumeQuantity::Total => r.total,
                    // Refused above.
                    VolumeQuantity::LnTau => return None,
                };
                Some((q, t))
            })
            .collect()
    };
    Ok(out
        .into_iter()
        .map(|(q, t)| {
            let m = Measured::scalar(t.value, t.error, t.evaluations);
            let m = if t.all_alike {
                m.flagged(Flag::AllWalksAlike { walks: t.walks })
            } else {
                m
            };
            let m = if t.heavy {
                m.flagged(Flag::HeavyWalks { walks: t.walks })
            } else {
                m
            };
            let m = if t.underflows {
                m.flagged(Flag::Underflow)
            } else {
                m
            };
            (q, m)
        })
        .collect())
}

/// The quantities asked for from one evaluation of the terms. A term the
/// scene does not have is 0 at no cost.
pub(super) fn collect(
    res: &VolumeResult,
    quantities: &[VolumeQuantity],
) -> Outcome<VolumeQuantity> {
    let term = |t: Option<Term>| t.map_or(Measured::scalar(0.0, 0.0, 0), measured);
    quantities
        .iter()
        .map(|&q| {
            let m = match q {
                VolumeQuantity::Tau => {
                    let tau = measured(Term {
                        value: res.transmittance,
                        error: transmittance_error(
                            res.transmittance,
                            res.optical_depth.error,
                            res.optical_depth.kind,
                        ),
                        ..res.optical_depth
                    });
                    if res.underflow {
                        tau.flagged(Flag::Underflow)
                    } else {
                        tau
                    }
                }
                VolumeQuantity::LnTau => measured(Term {
                    value: res.log_transmittance,
                    ..res.optical_depth
                }),
                VolumeQuantity::Emission => term(res.emission),
                // I_B = B tau underflows with tau: flagged as tau is
                // (`ln I_B = ln B + ln tau`).
                VolumeQuantity::Background => {
                    let b = term(res.background);
                    if res.underflow && b.value.iter().all(|v| v.abs() < f64::MIN_POSITIVE) {
                        b.flagged(Flag::Underflow)
                    } else {
                        b
                    }
                }
                VolumeQuantity::Light => term(res.light),
                VolumeQuantity::Total => total(res),
            };
            (q, m)
        })
        .collect()
}

/// A term as a measured value, flagged when the rule doubted its estimate.
fn measured(t: Term) -> Measured {
    let m = Measured::scalar(t.value, t.error, t.evaluations);
    if t.reliable {
        m
    } else {
        m.flagged(Flag::UnreliableEstimate)
    }
}

/// V-I with the errors and costs of its terms, flagged when the sum lost
/// digits to cancellation. The terms' errors combine as their kinds do
/// ([`Estimate::combine`]): independent standard errors in quadrature.
fn total(res: &VolumeResult) -> Measured {
    let terms = [res.emission, res.background, res.light];
    let sum = terms
        .iter()
        .flatten()
        .map(|t| Estimate {
            value: t.value,
            error: t.error,
            evaluations: t.evaluations,
            kind: t.kind,
            reliable: t.reliable,
            alike: false,
        })
        .fold(Estimate::zero(), Estimate::combine);
    // V-B reuses tau's evaluations: count them once.
    let shared = res.background.map_or(0, |b| b.evaluations);
    let evaluations = res.optical_depth.evaluations + sum.evaluations - shared;
    let parts = terms.iter().flatten().map(|t| t.value.abs()).sum::<f64>();
    let m = measured(Term {
        id: "V-I",
        value: res.total,
        error: sum.error,
        evaluations,
        kind: sum.kind,
        reliable: sum.reliable,
    });
    if parts > 0.0 && res.total.abs() < 1e-6 * parts {
        m.flagged(Flag::Cancellation { parts })
    } else {
        m
    }
}
