//! A volume term: transmittance (V-tau) and emission (V-E) along an eye ray
//! through a sphere of constant density, with Gauss–Legendre at a few budgets,
//! against the closed forms computed here from the chord length.
//!
//! `cargo run --release --example volume_term`

use std::sync::Arc;

use lightquad::QuadError;
use lightquad::domain::Vec3;
use lightquad::geometry::Ray;
use lightquad::quadrature::GaussLegendre;
use lightquad::volume::{
    ConstantSphere, DepthScheme, EmissionMap, ShadowMethod, VolumeScene, evaluate,
};
use rand::SeedableRng;

fn main() -> Result<(), QuadError> {
    // A ray along +x at height h above the centre of a unit sphere of density
    // kappa (sigma = lambda kappa), emitting c wherever the density is positive.
    let (radius, height, kappa, lambda, c) = (1.0_f64, 0.3_f64, 2.5, 1.0, 1.0);
    let mut scene = VolumeScene::new(Ray::new(Vec3::new(-3.0, height, 0.0), Vec3::x())?);
    scene.medium = Some(Arc::new(ConstantSphere::new(Vec3::zeros(), radius, kappa)?));
    scene.lambda = lambda;
    scene.emission = Some(EmissionMap::Constant(c));

    // Closed forms: the chord is 2 sqrt(R^2 - h^2); tau = exp(-sigma L),
    // I_E = int_0^L exp(-sigma t) c dt = c (1 - exp(-sigma L)) / sigma.
    let sigma = lambda * kappa;
    let chord = 2.0 * (radius * radius - height * height).sqrt();
    let tau = (-sigma * chord).exp();
    let emission = c * (1.0 - tau) / sigma;

    let mut rng = rand_pcg::Pcg64::seed_from_u64(1);
    println!(
        "{:>6} {:>22} {:>10} {:>22} {:>10}",
        "n", "tau", "error", "I_E", "error"
    );
    let mut last = (f64::NAN, f64::NAN);
    for n in [2, 4, 8, 16, 32] {
        let r = evaluate(
            &scene,
            &GaussLegendre::default(),
            n,
            DepthScheme::Cumulative,
            ShadowMethod::ClosedFormWhereAvailable,
            &mut rng,
        )?;
        let e = r.emission.map_or(f64::NAN, |t| t.value);
        last = (
            (r.transmittance - tau).abs() / tau,
            (e - emission).abs() / emission,
        );
        println!(
            "{n:>6} {:>22.16} {:>10.1e} {e:>22.16} {:>10.1e}",
            r.transmittance, last.0, last.1
        );
    }
    println!("closed forms: tau = {tau:.16}, I_E = {emission:.16}");
    // A constant density is a polynomial along the chord: the optical depth is
    // exact at any n, and the emission integrand exp(-sigma t) converges
    // spectrally.
    assert!(last.0 < 1e-13, "tau relative error {:e}", last.0);
    assert!(last.1 < 1e-13, "I_E relative error {:e}", last.1);
    Ok(())
}
