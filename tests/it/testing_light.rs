//! A renderer's light sampler tested as its author would with
//! `lightquad::testing`: area sampling of a disk light, partly hidden by a
//! disk occluder, against its density (chi-square) and its irradiance
//! estimate against the rendering family's converged reference, with a
//! planted bug caught by both; and the ground truth itself against closed
//! forms computed here.

use std::f64::consts::PI;

use lightquad::QuadError;
use lightquad::domain::{Disk, Vec3};
use lightquad::rand::RngExt;
use lightquad::rand_pcg::Pcg64;
use lightquad::rendering::experiment::{
    BrdfSpec, DiskLightSpec, DiskSpec, EmitterSpec, LambertSpec, OccluderSpec, ReceiverSpec,
    Rendering, RenderingQuantity, SceneSpec,
};
use lightquad::testing::{ChiSquare, EstimatorTest, Order, truth};

/// The light: a disk of radius 1 at height 2 facing down, radiance 3.
const LIGHT: (f64, f64, f64) = (2.0, 1.0, 3.0);
/// The occluder: a disk of radius 0.4 at height 1, centred at x = 0.5.
const BLOCKER: (f64, f64, f64) = (0.5, 1.0, 0.4);

/// The scene as the rendering family reads it.
fn scene(blocker: Option<([f64; 3], f64)>) -> SceneSpec {
    let (h, r, l) = LIGHT;
    SceneSpec {
        receiver: ReceiverSpec {
            point: [0.0; 3],
            normal: [0.0, 0.0, 1.0],
            brdf: None,
            toward_viewer: None,
        },
        emitters: vec![EmitterSpec::Disk(DiskLightSpec {
            centre: [0.0, 0.0, h],
            normal: [0.0, 0.0, -1.0],
            radius: r,
            radiance: l,
        })],
        occluders: blocker
            .map(|(centre, radius)| {
                OccluderSpec::Disk(DiskSpec {
                    centre,
                    normal: [0.0, 0.0, 1.0],
                    radius,
                })
            })
            .into_iter()
            .collect(),
    }
}

/// The renderer's area sampling of the light: uniform in area (radius
/// `R sqrt(u_0)`), or, the planted bug, radius `R u_0` with the same pdf.
fn sample_light(u: [f64; 2], buggy: bool) -> (Vec3, f64) {
    let (h, r, _) = LIGHT;
    let radius = if buggy { r * u[0] } else { r * u[0].sqrt() };
    let phi = 2.0 * PI * u[1];
    (
        Vec3::new(radius * phi.cos(), radius * phi.sin(), h),
        1.0 / (PI * r * r),
    )
}

/// The renderer's shadow ray from the origin to `y` against the blocker.
fn visible(y: Vec3) -> bool {
    let (cx, h, r) = BLOCKER;
    let t = h / y.z;
    let p = y * t;
    (p.x - cx).powi(2) + p.y * p.y > r * r
}

/// The renderer's estimate of the irradiance at the origin from `n` light
/// samples, with its standard error:
/// `E = (1/n) sum L V cos_x cos_y / (d^2 pdf_area)`.
fn irradiance(n: usize, rng: &mut Pcg64, buggy: bool) -> (f64, f64) {
    let l = LIGHT.2;
    let xs: Vec<f64> = (0..n)
        .map(|_| {
            let (y, pdf) = sample_light([rng.random(), rng.random()], buggy);
            let d2 = y.norm_squared();
            let cos = y.z / d2.sqrt();
            if visible(y) {
                l * cos * cos / (d2 * pdf)
            } else {
                0.0
            }
        })
        .collect();
    let mean = xs.iter().sum::<f64>() / n as f64;
    let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
    (mean, (var / n as f64).sqrt())
}

#[test]
fn a_disk_light_sampler_with_an_occluder_passes_and_its_planted_bug_is_caught()
-> Result<(), Box<dyn std::error::Error>> {
    let (cx, h, r) = BLOCKER;
    let reference = truth::<Rendering>(
        &scene(Some(([cx, 0.0, h], r))),
        RenderingQuantity::EArea,
        1e-12,
    )?;
    println!("reference E = {:?}: {}", reference.value, reference.how);
    // Independently: the unit disk less its part in the blocker's shadow
    // (a disk of radius 0.8 about x = 1 on the light's plane), by mpmath at
    // 30 digits over the shadow's angles, radially in closed form.
    let independent = 1.392_596_048_186_321_6;
    assert!((reference.value[0] - independent).abs() < 1e-12 * independent);
    // The family's evaluation doubts its error estimate at the shadow's
    // edge, and the truth says so.
    assert!(!reference.verified);
    // Four tests in all (two per sampler), one alpha for the suite.
    let light = Disk::new(Vec3::new(0.0, 0.0, LIGHT.0), -Vec3::z(), LIGHT.1)?;
    let chi2 = ChiSquare::new(light).cells([20, 40]).tests(4);
    let estimator = EstimatorTest::new(400).seed(11).tests(4);
    let pdf = |_: &Vec3| 1.0 / (PI * LIGHT.1 * LIGHT.1);
    for buggy in [false, true] {
        let fit = chi2.run(pdf, |u| Some(sample_light(u, buggy).0), 3)?;
        let est = estimator.run(&reference, |rng| irradiance(64, rng, buggy))?;
        println!("buggy {buggy}:\n{fit}\n{est}");
        assert_eq!(fit.passed, !buggy, "{fit}");
        assert_eq!(est.passed, !buggy, "{est}");
    }
    // The correct estimator's RMS error falls as n^-1/2.
    let order = Order::measure(
        &[16, 64, 256, 1024, 4096],
        64,
        5,
        reference.value[0],
        |n, rng| irradiance(n, rng, false).0,
    )?;
    println!("order {order}");
    order.assert_near(-0.5, 0.1);
    Ok(())
}

/// `pi L rho^2 / (h^2 + rho^2)`: the irradiance at the origin from a
/// coaxial disk of radius `rho` at height `h`, radiance `L` (Lambert).
fn coaxial(l: f64, h: f64, rho: f64) -> f64 {
    PI * l * rho * rho / (h * h + rho * rho)
}

#[test]
fn ground_truth_agrees_with_closed_forms_computed_here() -> Result<(), Box<dyn std::error::Error>> {
    let (h, r, l) = LIGHT;
    let open = truth::<Rendering>(&scene(None), RenderingQuantity::EArea, 1e-12)?;
    let exact = coaxial(l, h, r);
    assert!((open.value[0] - exact).abs() < 1e-14 * exact, "{open:?}");
    assert!(
        open.how.contains("closed form") && open.verified,
        "{}",
        open.how
    );
    // A coaxial blocker of radius 0.3 at height 1 hides the disk of radius
    // 0.6 of the light: the rest is an annulus.
    let hidden = truth::<Rendering>(
        &scene(Some(([0.0, 0.0, 1.0], 0.3))),
        RenderingQuantity::EArea,
        1e-12,
    )?;
    let annulus = exact - coaxial(l, h, 0.6);
    let err = (hidden.value[0] - annulus).abs();
    println!("annulus {annulus}: {hidden:?}, error {err:.2e}");
    assert!(err < 1e-10 * annulus && err <= hidden.accuracy[0].max(1e-14 * annulus) * 10.0);
    // The same truth through its other form (over the light's cone).
    let cone = truth::<Rendering>(
        &scene(Some(([0.0, 0.0, 1.0], 0.3))),
        RenderingQuantity::ECone,
        1e-12,
    )?;
    assert!(
        (cone.value[0] - annulus).abs() < 1e-10 * annulus,
        "{cone:?}"
    );
    // Reflected radiance off a Lambertian receiver of albedo 0.6: rho / pi
    // times the irradiance, with the blocker off the axis (converged).
    let mut lit = scene(Some(([0.5, 0.0, 1.0], 0.4)));
    lit.receiver.brdf = Some(BrdfSpec::Lambert(LambertSpec { albedo: 0.6 }));
    lit.receiver.toward_viewer = Some([0.0, 0.0, 1.0]);
    let radiance = truth::<Rendering>(&lit, RenderingQuantity::LArea, 1e-12)?;
    let want = 0.6 / PI * 1.392_596_048_186_321_6;
    assert!(
        (radiance.value[0] - want).abs() < 1e-12 * want,
        "{radiance:?} vs {want}"
    );
    Ok(())
}

#[test]
fn ground_truth_refuses_bad_scenes_naming_the_field() {
    let mut bad = scene(None);
    if let EmitterSpec::Disk(d) = &mut bad.emitters[0] {
        d.radius = -1.0;
    }
    let e = truth::<Rendering>(&bad, RenderingQuantity::EArea, 1e-12)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(e.contains("scene.emitters[0].radius"), "{e}");
    let e = truth::<Rendering>(&scene(None), RenderingQuantity::EArea, f64::NAN)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(e.contains("goal"), "{e}");
    // A reflected radiance needs a BRDF at the receiver.
    let e = truth::<Rendering>(&scene(None), RenderingQuantity::LArea, 1e-12)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(e.contains("L_area"), "{e}");
}

#[test]
fn the_api_reports_its_failures_without_panicking() -> Result<(), QuadError> {
    // A sampler that lands on the light's plane but outside its rim.
    let light = Disk::new(Vec3::new(0.0, 0.0, 2.0), -Vec3::z(), 1.0)?;
    let out = ChiSquare::new(light).cells([4, 8]).samples(1000).run(
        |_: &Vec3| 1.0 / PI,
        |_| Some(Vec3::new(1.5, 0.0, 2.0)),
        0,
    );
    let e = out.err().map(|e| e.to_string()).unwrap_or_default();
    assert!(e.contains("sample 0") && e.contains("1.5"), "{e}");
    Ok(())
}

#[test]
fn ground_truth_of_the_volume_and_furnace_families() -> Result<(), Box<dyn std::error::Error>> {
    use lightquad::family::Family;
    use lightquad::rendering::closed::{Furnace, FurnaceQuantity};
    use lightquad::volume::experiment::{Volume, VolumeQuantity};
    // Transmittance through a constant sphere along a chord at offset b:
    // exp(-kappa 2 sqrt(R^2 - b^2)).
    let (kappa, b) = (2.5, 0.3);
    let sphere: <Volume as Family>::SceneSpec = serde_json::from_value(serde_json::json!({
        "ray": {"origin": [-3.0, b, 0.0], "direction": [1.0, 0.0, 0.0]},
        "medium": {"type": "constant-sphere", "centre": [0.0, 0.0, 0.0], "radius": 1.0, "kappa": kappa}
    }))?;
    let tau = truth::<Volume>(&sphere, VolumeQuantity::Tau, 1e-12)?;
    let exact = (-kappa * 2.0 * (1.0f64 - b * b).sqrt()).exp();
    assert!(
        (tau.value[0] - exact).abs() < 1e-14 * exact,
        "{tau:?} vs {exact}"
    );
    // The white furnace: L = L_e / (1 - rho).
    let furnace: <Furnace as Family>::SceneSpec = serde_json::from_value(serde_json::json!({
        "albedo": 0.9, "emission": 2.0, "point": [0.0, 0.0, -1.0]
    }))?;
    let l = truth::<Furnace>(&furnace, FurnaceQuantity::L, 1e-12)?;
    assert!((l.value[0] - 20.0).abs() < 1e-12 * 20.0, "{l:?}");
    Ok(())
}

#[test]
fn ground_truth_takes_a_loose_goal() -> Result<(), Box<dyn std::error::Error>> {
    let (cx, h, r) = BLOCKER;
    let occluded = scene(Some(([cx, 0.0, h], r)));
    for goal in [0.05, 0.5, f64::MAX] {
        let t = truth::<Rendering>(&occluded, RenderingQuantity::EArea, goal)?;
        assert!(
            (t.value[0] - 1.392_596_048_186_321_6).abs() < goal.min(1e-3),
            "{goal}: {t:?}"
        );
    }
    Ok(())
}
