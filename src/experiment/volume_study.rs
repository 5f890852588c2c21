//! The built-in study of the volume equations (V-*): the audit of the printed
//! `s(t)` and `I_p(t)`, and V-E and V-L on the constant-density sphere by every
//! deterministic rule, nested and cumulative, against the closed forms.

use std::sync::Arc;
use std::time::Instant;

use rand::SeedableRng;

use crate::domain::Vec3;
use crate::exact::volume as exact;
use crate::geometry::Ray;
use crate::quadrature::AnyRule;
use crate::volume::{
    ConstantSphere, DepthScheme, DirectionalLight, EmissionMap, Medium, ShadowMethod, VolumeScene,
    audit, evaluate,
};

/// The study as Markdown.
pub fn markdown() -> String {
    let mut out = String::from("\n# Volume rendering (V-*)\n");
    audit_section(&mut out);
    terms_section(&mut out);
    out
}

fn audit_section(out: &mut String) {
    out.push_str(
        "\n## V-Lp audit: the printed s(t) against the corrected root and a quadrature shadow ray\n\n\
         Sphere of radius 1.5 at the origin, lambda kappa = 0.8, I_p = 1, light direction \
         d = (0.3, 0.8, -0.2)/|.|. `s` by quadrature is the shadow ray's optical depth \
         (64-node Gauss–Legendre) divided by lambda kappa. The printed radicand \
         <p,d>^2 - <p,p><d,d> is never positive (Cauchy–Schwarz): NaN off the line through \
         the centre (docs/EQUATIONS.md audit points 1 and 2).\n\n\
         | point p | s printed | s corrected | s by quadrature | I_p printed | I_p corrected |\n\
         |---|---:|---:|---:|---:|---:|\n",
    );
    let (r, lk) = (1.5, 0.8);
    let d = Vec3::new(0.3, 0.8, -0.2).normalize();
    let Ok(medium) = ConstantSphere::new(Vec3::zeros(), r, 1.0) else {
        return;
    };
    for p in [
        Vec3::new(0.1, 0.2, 0.3),
        Vec3::new(-1.0, 0.5, 0.2),
        Vec3::new(0.0, 0.0, 1.4),
        d * 0.5,
    ] {
        let s_quad = Ray::new(p, d).ok().and_then(|ray| {
            let rule = AnyRule::by_name("gauss-legendre").ok()?;
            let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
            let mut total = 0.0;
            for piece in medium.support(&ray, 0.0, f64::INFINITY) {
                total += piece
                    .integrate(&rule, 64, &mut rng, |t| medium.density(ray.at(t)))
                    .ok()?
                    .value;
            }
            Some(total)
        });
        out.push_str(&format!(
            "| ({:.2}, {:.2}, {:.2}) | {} | {:.15} | {} | {} | {:.15} |\n",
            p.x,
            p.y,
            p.z,
            audit::s_printed(p, d),
            audit::s_corrected(p, d, r),
            s_quad.map_or("failed".into(), |s| format!("{s:.15}")),
            audit::light_printed(p, d, lk, 1.0),
            audit::light_corrected(p, d, r, lk, 1.0),
        ));
    }
}

fn terms_section(out: &mut String) {
    out.push_str(
        "\n## V-E and V-L on the constant sphere, nested against cumulative depth\n\n\
         Ray through a sphere of radius 1 at height 0.3 (chord 1.9079), c = 1, light straight \
         behind the eye (closed form `I_p (1 - e^{-2 sigma L}) / (2 sigma)`), no scattering. \
         Relative error against the closed forms in `exact::volume`; evaluations are density \
         evaluations.\n\n\
         | optical depth | rule | n | scheme | V-E rel. error | V-L rel. error | evaluations (V-E) | time (s) |\n\
         |---:|---|---:|---|---:|---:|---:|---:|\n",
    );
    let (r, h) = (1.0f64, 0.3f64);
    let chord = 2.0 * (r * r - h * h).sqrt();
    for depth in [1.0, 10.0] {
        let sigma = depth / chord;
        let Ok(ray) = Ray::new(Vec3::new(-3.0, h, 0.0), Vec3::x()) else {
            return;
        };
        let mut scene = VolumeScene::new(ray);
        let Ok(medium) = ConstantSphere::new(Vec3::zeros(), r, sigma) else {
            return;
        };
        scene.medium = Some(Arc::new(medium));
        scene.emission = Some(EmissionMap::Constant(1.0));
        scene.light = DirectionalLight::new(-Vec3::x(), 1.0, None).ok();
        let (want_e, want_l) = (
            exact::emission(sigma, chord, 1.0),
            exact::light_behind(sigma, chord, 1.0, None),
        );
        for rule_name in ["trapezoid", "gauss-legendre", "gauss-kronrod"] {
            let Ok(rule) = AnyRule::by_name(rule_name) else {
                continue;
            };
            for n in [15usize, 60, 240] {
                for scheme in [DepthScheme::Nested, DepthScheme::Cumulative] {
                    let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
                    let start = Instant::now();
                    let res = evaluate(
                        &scene,
                        &rule,
                        n,
                        scheme,
                        ShadowMethod::ClosedFormWhereAvailable,
                        &mut rng,
                    );
                    let secs = start.elapsed().as_secs_f64();
                    let Ok(res) = res else { continue };
                    let (Some(e), Some(l)) = (res.emission, res.light) else {
                        continue;
                    };
                    out.push_str(&format!(
                        "| {depth} | {rule_name} | {n} | {scheme:?} | {:.1e} | {:.1e} | {} | {secs:.1e} |\n",
                        ((e.value - want_e) / want_e).abs(),
                        ((l.value - want_l) / want_l).abs(),
                        e.evaluations,
                    ));
                }
            }
        }
    }
}
