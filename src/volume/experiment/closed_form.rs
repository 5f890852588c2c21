//! The closed forms `exact` has for a scene's quantities.

use crate::exact::volume as exact;
use crate::volume::{EmissionMap, Medium};

use super::{Built, VolumeQuantity};

/// The closed form of a quantity for this scene, when `exact` has one.
pub(super) fn closed_form(built: &Built, q: VolumeQuantity) -> Option<f64> {
    // The chord from the start of the medium's support, where its length
    // keeps its digits (VolumeScene::anchored).
    let (scene, _) = built.scene.anchored();
    let scene = &scene;
    let ray = scene.ray;
    // `ln tau = -lambda int v_r dt` (V-tau), kept in log space.
    let ln_tau = match &scene.medium {
        None => 0.0,
        Some(m) => -scene.lambda * m.density_integral(&ray, scene.t_min, scene.t_max)?,
    };
    let tau = ln_tau.exp();
    // The constant sphere's chord inside the looked-at part, and whether that
    // part holds the whole chord (the light closed forms need it).
    let sphere = match built.sphere_kappa {
        Some(kappa) => scene
            .medium
            .as_ref()
            .and_then(|m| {
                m.support(&ray, scene.t_min, scene.t_max)
                    .first()
                    .map(|s| (s.start(), s.end()))
            })
            .map(|(a, b)| {
                (
                    scene.lambda * kappa,
                    b - a,
                    a > scene.t_min && b < scene.t_max,
                )
            }),
        _ => None,
    };
    // A ray that misses the medium: the density-driven terms (emission by a
    // map of the density, single scattering) are 0 along it.
    let missed = scene
        .medium
        .as_ref()
        .is_some_and(|m| m.support(&ray, scene.t_min, scene.t_max).is_empty());
    let emission = || -> Option<f64> {
        let Some(map) = &scene.emission else {
            return Some(0.0);
        };
        if let EmissionMap::Field(field) = map {
            // Nothing absorbs along the ray (ln tau = 0 exactly): I_E is the
            // field's line integral.
            if ln_tau == 0.0 {
                return field.density_integral(&ray, scene.t_min, scene.t_max);
            }
            // A constant-sphere field through a constant-sphere medium: a
            // constant on one interval seen through a constant extinction on
            // another (exact::emission_field_interval).
            let c = built.field_sphere_value?;
            let chord = |m: &dyn Medium| {
                m.support(&ray, scene.t_min, scene.t_max)
                    .first()
                    .map(|s| (s.start(), s.end()))
            };
            let Some(emits) = chord(field.as_ref()) else {
                return Some(0.0);
            };
            let (sigma, _, _) = sphere?;
            let absorbs = chord(scene.medium.as_deref()?)?;
            return Some(exact::emission_field_interval(sigma, absorbs, c, emits));
        }
        if scene.medium.is_none() || missed {
            return Some(0.0);
        }
        let (sigma, chord, _) = sphere?;
        let kappa = built.sphere_kappa?;
        // `c(v)` on the chord, where `v = kappa` (a map of the density emits
        // only where it is positive: nothing from a sphere of kappa 0).
        Some(exact::emission(sigma, chord, map.at(kappa)))
    };
    let light = || -> Option<f64> {
        let Some(light) = scene.light else {
            return Some(0.0);
        };
        if scene.medium.is_none() || missed {
            return Some(0.0);
        }
        let (sigma, chord, whole) = sphere?;
        if !whole {
            return None;
        }
        let cos = light.toward_light.dot(&ray.dir);
        if (cos - 1.0).abs() < 1e-12 {
            Some(exact::light_ahead(
                sigma,
                chord,
                light.intensity,
                light.albedo,
            ))
        } else if (cos + 1.0).abs() < 1e-12 {
            Some(exact::light_behind(
                sigma,
                chord,
                light.intensity,
                light.albedo,
            ))
        } else {
            None
        }
    };
    let background = scene.background.unwrap_or(0.0) * tau;
    match q {
        VolumeQuantity::Tau => Some(tau),
        VolumeQuantity::LnTau => Some(ln_tau),
        VolumeQuantity::Background => Some(background),
        VolumeQuantity::Emission => emission(),
        VolumeQuantity::Light => light(),
        VolumeQuantity::Total => Some(emission()? + background + light()?),
    }
}
