//! The BRDFs of src/rendering/brdf.rs against independent references: the
//! normalisation of every sampling density over the sphere and the
//! closed-form albedos (Lambert, Phong at normal incidence, the
//! clamped-cosine product, the GGX furnaces) by Gauss–Legendre quadrature in
//! spherical coordinates with the lobe's peak and every kink at piece ends;
//! the sampling routines by chi-square goodness of fit (Mitsuba 3 and
//! pbrt-v4 style); the inverse of each sampling map by a round trip;
//! reciprocity (R-rec) and energy conservation by proptest.

use crate::common;

use std::f64::consts::PI;

use lightquad::QuadError;
use lightquad::domain::{Frame, Vec3};
use lightquad::exact::rendering::{clamped_cosine_product, phong_albedo_normal};
use lightquad::quadrature::gauss_legendre::table;
use lightquad::rendering::brdf::{Brdf, Ggx, Lambert, NormalizedPhong, Phong};
use proptest::prelude::*;
use rand::{RngExt, SeedableRng};

/// The viewer at polar angle `theta` (degrees) in the xz-plane.
fn wo_at(theta_deg: f64) -> Vec3 {
    let t = theta_deg.to_radians();
    Vec3::new(t.sin(), 0.0, t.cos())
}

/// The mirror direction of `wo` about `+z`, written out here independently.
fn reflect_z(wo: Vec3) -> Vec3 {
    2.0 * wo.z * Vec3::z() - wo
}

/// `int_{S^2} f(w) dw` in spherical coordinates `(a, phi)` about `axis`:
/// `f(w(a, phi)) sin a`, `a` in `[0, pi]` in Gauss–Legendre pieces (20
/// nodes) cut at `pi/2`, at `scale 2^k` (`k >= -10`, resolving a peak of
/// width `scale` at the pole), at the kinks of the clamps `max(0, w . k)`
/// for `k` in `planes` and at the kinks `extra(e, axis)` returns for the
/// azimuthal direction `e(phi)`. `phi` in pieces of 20 nodes cut at the
/// azimuths where a plane's kink sweeps from near the pole to near the
/// antipole (`e . k = 0`), refined geometrically toward them (a plane
/// almost through the axis moves its kink over an azimuth range of
/// `|axis . k|`).
fn sphere_integral(
    axis: Vec3,
    scale: f64,
    planes: &[Vec3],
    extra: impl Fn(Vec3, Vec3) -> Vec<f64>,
    f: impl Fn(Vec3) -> f64,
) -> f64 {
    let frame = Frame::from_normal(axis).expect("unit axis");
    let gl = table(20).expect("20 nodes");
    let mut base: Vec<f64> = vec![0.0, PI / 2.0, PI];
    base.extend(
        (-10..40)
            .map(|k| scale * 2f64.powi(k))
            .filter(|a| *a > 0.0 && *a < PI),
    );
    let mut phi_cuts: Vec<f64> = (0..=8).map(|p| 2.0 * PI * p as f64 / 8.0).collect();
    for k in planes {
        let (a, b) = (frame.s.dot(k), frame.t.dot(k));
        if a == 0.0 && b == 0.0 {
            continue;
        }
        let phi0 = a.atan2(-b);
        for centre in [phi0, phi0 + PI] {
            phi_cuts.push(centre);
            for j in 0..45 {
                let d = 2f64.powi(-j);
                phi_cuts.extend([centre - d, centre + d]);
            }
        }
    }
    let mut phi_cuts: Vec<f64> = phi_cuts
        .into_iter()
        .map(|p| p.rem_euclid(2.0 * PI))
        .chain([2.0 * PI])
        .collect();
    phi_cuts.sort_by(f64::total_cmp);
    phi_cuts.dedup();
    let mut total = 0.0;
    for pc in phi_cuts.windows(2) {
        let (p0, p1) = (pc[0], pc[1]);
        for (&xp, &wp) in gl.x().iter().zip(gl.w().iter()) {
            let phi = p0 + (p1 - p0) * (xp + 1.0) / 2.0;
            let e = frame.s * phi.cos() + frame.t * phi.sin();
            let mut cuts = base.clone();
            for k in planes {
                let (kz, c) = (frame.n.dot(k), e.dot(k));
                if kz != 0.0 {
                    cuts.push(kz.abs().atan2(-kz.signum() * c));
                }
            }
            cuts.extend(extra(e, frame.n));
            cuts.retain(|a| *a >= 0.0 && *a <= PI);
            cuts.sort_by(f64::total_cmp);
            cuts.dedup();
            let mut inner = 0.0;
            for c in cuts.windows(2) {
                let (a0, a1) = (c[0], c[1]);
                for (&xa, &wa) in gl.x().iter().zip(gl.w().iter()) {
                    let a = a0 + (a1 - a0) * (xa + 1.0) / 2.0;
                    let w = frame.n * a.cos() + e * a.sin();
                    inner += wa * (a1 - a0) / 2.0 * f(w) * a.sin();
                }
            }
            total += wp * (p1 - p0) / 2.0 * inner;
        }
    }
    total
}

fn no_kink(_: Vec3, _: Vec3) -> Vec<f64> {
    vec![]
}

/// GGX over the half vector: `int_{S^2} g(wi) dwi = int_{wo . h > 0} g(2 (wo
/// . h) h - wo) 4 (wo . h) dh` (reflection about `h` maps the hemisphere
/// `wo . h > 0` onto the sphere with Jacobian `4 wo . h`), in coordinates
/// about `+z` with the peak of width `alpha` resolved and the kinks at `wo .
/// h = 0` and at `wi_z = 0`, where `tan 2a = -wo_z / (e . wo)`.
fn ggx_half_vector_integral(alpha: f64, wo: Vec3, g: impl Fn(Vec3) -> f64) -> f64 {
    sphere_integral(
        Vec3::z(),
        alpha,
        &[wo],
        |e, _| vec![wo.z.atan2(-e.dot(&wo)) / 2.0],
        |h| {
            let c = wo.dot(&h);
            if c > 0.0 {
                g(h * (2.0 * c) - wo) * 4.0 * c
            } else {
                0.0
            }
        },
    )
}

/// `int_{S^2} pdf(wo, wi) dwi` for any of the four BRDFs.
fn pdf_integral(kind: &Kind, wo: Vec3) -> f64 {
    match kind {
        Kind::Lambert(b) => sphere_integral(Vec3::z(), 1.0, &[], no_kink, |w| b.pdf(wo, w)),
        Kind::Phong(b) => sphere_integral(
            reflect_z(wo),
            1.0 / (b.exponent() + 1.0).sqrt(),
            &[],
            no_kink,
            |w| b.pdf(wo, w),
        ),
        Kind::NormalizedPhong(b) => sphere_integral(
            reflect_z(wo),
            1.0 / (b.exponent() + 1.0).sqrt(),
            &[],
            no_kink,
            |w| b.pdf(wo, w),
        ),
        Kind::Ggx(b) => ggx_half_vector_integral(b.alpha, wo, |wi| b.pdf(wo, wi)),
    }
}

/// `int_H f(wi, wo) cos theta_i dwi`, the directional albedo (R-H).
fn albedo(kind: &Kind, wo: Vec3) -> f64 {
    match kind {
        Kind::Lambert(b) => sphere_integral(Vec3::z(), 1.0, &[], no_kink, |w| b.eval(w, wo) * w.z),
        Kind::Phong(b) => sphere_integral(
            reflect_z(wo),
            1.0 / (b.exponent() + 1.0).sqrt(),
            &[Vec3::z()],
            no_kink,
            |w| b.eval(w, wo) * w.z.max(0.0),
        ),
        Kind::NormalizedPhong(b) => sphere_integral(
            reflect_z(wo),
            1.0 / (b.exponent() + 1.0).sqrt(),
            &[Vec3::z()],
            no_kink,
            |w| b.eval(w, wo) * w.z.max(0.0),
        ),
        Kind::Ggx(b) => ggx_half_vector_integral(b.alpha, wo, |wi| b.eval(wi, wo) * wi.z.max(0.0)),
    }
}

#[derive(Debug, Clone, Copy)]
enum Kind {
    Lambert(Lambert),
    Phong(Phong),
    NormalizedPhong(NormalizedPhong),
    Ggx(Ggx),
}

impl Kind {
    fn brdf(&self) -> &dyn Brdf {
        match self {
            Kind::Lambert(b) => b,
            Kind::Phong(b) => b,
            Kind::NormalizedPhong(b) => b,
            Kind::Ggx(b) => b,
        }
    }
}

fn lambert(a: f64) -> Kind {
    Kind::Lambert(Lambert::new(a).expect("valid"))
}
fn phong(k: f64, n: f64) -> Kind {
    Kind::Phong(Phong::new(k, n).expect("valid"))
}
fn nphong(k: f64, n: f64) -> Kind {
    Kind::NormalizedPhong(NormalizedPhong::new(k, n).expect("valid"))
}
fn ggx(a: f64) -> Kind {
    Kind::Ggx(Ggx::new(a).expect("valid"))
}

/// Every BRDF and viewer the sampling tests use: small and large exponents
/// and roughnesses, normal to grazing incidence (Phong 1e4 at 89.99 degrees).
fn configurations() -> Vec<(Kind, f64)> {
    let mut c = vec![];
    for th in [0.0, 30.0, 89.0] {
        c.push((lambert(0.7), th));
    }
    for n in [0.0, 1.0, 10.0, 1e3, 1e4] {
        for th in [0.0, 45.0, 80.0, 89.99] {
            c.push((phong(1.0, n), th));
        }
    }
    c.push((nphong(0.9, 50.0), 40.0));
    for a in [1e-3, 0.02, 0.1, 0.5, 1.0] {
        for th in [0.0, 45.0, 80.0, 89.9] {
            c.push((ggx(a), th));
        }
    }
    c
}

/// The density of every sampling map integrates to 1 over the sphere
/// (the mass below the horizon, which `sample` returns as `None`, included).
#[test]
fn pdf_integrates_to_one_over_the_sphere() {
    let mut worst = (0.0, String::new());
    for (kind, th) in configurations() {
        let i = pdf_integral(&kind, wo_at(th));
        let err = (i - 1.0).abs();
        if err >= worst.0 {
            worst = (err, format!("{kind:?} at {th} deg: {i:.16}"));
        }
        assert!(err < 1e-10, "{kind:?} at {th} deg: int pdf = {i:.16}");
    }
    println!("largest |int pdf - 1| = {:.2e} ({})", worst.0, worst.1);
}

/// sample -> invert recovers u; the sample's pdf is pdf(wo, wi) and its
/// weight f cos / pdf.
#[test]
fn sampling_round_trip() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
    let (mut worst_u, mut worst_pdf, mut worst_weight) = (0.0_f64, 0.0_f64, 0.0_f64);
    for (kind, th) in configurations() {
        let b = kind.brdf();
        let wo = wo_at(th);
        let mut some = 0;
        for _ in 0..20_000 {
            let u = [rng.random::<f64>(), rng.random::<f64>()];
            let Some(s) = b.sample(wo, u) else { continue };
            some += 1;
            assert!(s.wi.z > 0.0 && (s.wi.norm() - 1.0).abs() < 1e-14);
            let v = b.invert(wo, s.wi).expect("a sample inverts");
            let d1 = (v[0] - u[0]).abs();
            let d2 = (v[1] - u[1]).abs();
            let d = d1.max(d2.min(1.0 - d2));
            assert!(d < 1e-10, "{kind:?} at {th}: u {u:?} -> {v:?}");
            worst_u = worst_u.max(d);
            let p = b.pdf(wo, s.wi);
            let rp = ((p - s.pdf) / p).abs();
            assert!(rp < 1e-10, "{kind:?} at {th}: pdf {} vs {p}", s.pdf);
            worst_pdf = worst_pdf.max(rp);
            let w = b.eval(s.wi, wo) * s.wi.z / p;
            let rw = if w == 0.0 {
                s.weight
            } else {
                ((w - s.weight) / w).abs()
            };
            assert!(rw < 1e-10, "{kind:?} at {th}: weight {} vs {w}", s.weight);
            worst_weight = worst_weight.max(rw);
        }
        assert!(some > 0, "{kind:?} at {th}: no sample above the horizon");
    }
    println!(
        "round trip: largest |u - invert(sample(u))| = {worst_u:.2e}, pdf rel {worst_pdf:.2e}, weight rel {worst_weight:.2e}"
    );
}

/// Chi-square goodness of fit of `sample` against `pdf` with `n` samples:
/// cells `res_z x 2 res_z` in `(cos theta, phi)` over the whole sphere, the
/// expected count of each cell above the horizon by 10 x 10-node
/// Gauss–Legendre of `pdf` (`dw = d cos theta d phi`); one cell for the
/// lower hemisphere against the count of `None`; cells expecting fewer than
/// 5 are pooled.
/// Returns (statistic, degrees of freedom, p-value).
fn chi_square(b: &dyn Brdf, wo: Vec3, n: usize, seed: u64) -> (f64, usize, f64) {
    let res_z = 50;
    let res_phi = 2 * res_z;
    let gl = table(10).expect("10 nodes");
    let cell = |iz: usize, ip: usize| -> f64 {
        let (z0, z1) = (
            -1.0 + 2.0 * iz as f64 / res_z as f64,
            -1.0 + 2.0 * (iz + 1) as f64 / res_z as f64,
        );
        let (p0, p1) = (
            2.0 * PI * ip as f64 / res_phi as f64,
            2.0 * PI * (ip + 1) as f64 / res_phi as f64,
        );
        let mut s = 0.0;
        for (&xz, &wz) in gl.x().iter().zip(gl.w().iter()) {
            let z = z0 + (z1 - z0) * (xz + 1.0) / 2.0;
            let r = ((1.0 - z) * (1.0 + z)).sqrt();
            for (&xp, &wp) in gl.x().iter().zip(gl.w().iter()) {
                let phi = p0 + (p1 - p0) * (xp + 1.0) / 2.0;
                s += wz * wp * b.pdf(wo, Vec3::new(r * phi.cos(), r * phi.sin(), z));
            }
        }
        s * (z1 - z0) * (p1 - p0) / 4.0
    };
    let mut expected = vec![0.0; res_z * res_phi];
    for iz in res_z / 2..res_z {
        for ip in 0..res_phi {
            expected[iz * res_phi + ip] = cell(iz, ip) * n as f64;
        }
    }
    let mut observed = vec![0.0; res_z * res_phi];
    let mut none = 0.0;
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    for _ in 0..n {
        let u = [rng.random::<f64>(), rng.random::<f64>()];
        match b.sample(wo, u) {
            None => none += 1.0,
            Some(s) => {
                let iz = (((s.wi.z + 1.0) / 2.0 * res_z as f64) as usize).min(res_z - 1);
                let phi = s.wi.y.atan2(s.wi.x).rem_euclid(2.0 * PI);
                let ip = ((phi / (2.0 * PI) * res_phi as f64) as usize).min(res_phi - 1);
                assert!(iz >= res_z / 2, "a sample below the horizon: {:?}", s.wi);
                observed[iz * res_phi + ip] += 1.0;
            }
        }
    }
    // The lower hemisphere against the count of None. Its expectation is
    // n (1 - the upper cells'): GGX's pdf jumps where the half vector crosses
    // the horizon (wi_z = -wo_z, inside a lower cell), which cell quadrature
    // does not resolve, while the normalisation is checked to 1e-13 by
    // `pdf_integrates_to_one_over_the_sphere`.
    let lower = res_z / 2 * res_phi;
    let upper: f64 = expected[lower..].iter().sum();
    assert!(
        upper <= n as f64 * (1.0 + 1e-9),
        "upper cells expect {upper}"
    );
    common::pearson(
        (n as f64 - upper).max(0.0),
        none,
        expected[lower..]
            .iter()
            .copied()
            .zip(observed[lower..].iter().copied()),
    )
}

/// Every sampling routine against its pdf: 10^6 samples, Sidak-corrected
/// significance 0.01 over the ten tests.
#[test]
fn chi_square_goodness_of_fit() {
    let cases = [
        (lambert(0.7), 30.0),
        (phong(1.0, 1.0), 0.0),
        (phong(1.0, 20.0), 60.0),
        (phong(1.0, 1e3), 85.0),
        (phong(1.0, 1e4), 89.0),
        (nphong(0.9, 50.0), 40.0),
        (ggx(0.02), 45.0),
        (ggx(0.05), 70.0),
        (ggx(0.3), 30.0),
        (ggx(1.0), 80.0),
    ];
    let threshold = 1.0 - (1.0 - 0.01_f64).powf(1.0 / cases.len() as f64);
    for (i, (kind, th)) in cases.iter().enumerate() {
        let (stat, dof, p) = chi_square(kind.brdf(), wo_at(*th), 1_000_000, 100 + i as u64);
        println!("chi2 {kind:?} at {th} deg: {stat:.1} on {dof} dof, p = {p:.3}");
        assert!(
            p > threshold,
            "{kind:?} at {th}: chi2 = {stat} on {dof} dof, p = {p} < {threshold}"
        );
    }
}

/// Lambert: albedo = rho at every incidence.
#[test]
fn lambert_albedo_is_rho() {
    for th in [0.0, 30.0, 60.0, 89.9] {
        let a = albedo(&lambert(0.3), wo_at(th));
        assert!((a - 0.3).abs() < 1e-13, "{th}: {a}");
    }
}

/// Phong at normal incidence: k_s 2 pi/(n+2) (unnormalised), k_s
/// (normalised), up to n = 1e4.
#[test]
fn phong_albedo_at_normal_incidence() {
    let mut worst = 0.0_f64;
    for n in [0.0, 1.0, 2.5, 10.0, 100.0, 1e3, 1e4, 1e6] {
        let a = albedo(&phong(0.8, n), Vec3::z());
        let want = 0.8 * phong_albedo_normal(n).expect("n >= 0");
        let r = ((a - want) / want).abs();
        worst = worst.max(r);
        assert!(r < 1e-11, "n = {n}: {a} vs {want}");
        let b = albedo(&nphong(0.8, n), Vec3::z());
        assert!((b - 0.8).abs() < 1e-11, "normalised n = {n}: {b}");
    }
    println!("Phong albedo at normal incidence: largest relative error {worst:.2e}");
}

/// Phong of exponent 1 with the receiver's cosine is the clamped-cosine
/// product over the sphere: `eval` is zero below the horizon exactly where
/// `max(0, n . w)` is, so the whole-sphere closed form applies at every
/// incidence, with `gamma = theta_o` the angle between `r` and the normal.
#[test]
fn phong_exponent_one_is_the_clamped_cosine_product() {
    for th in [0.0, 10.0, 45.0, 80.0, 89.99] {
        let a = albedo(&phong(1.0, 1.0), wo_at(th));
        let want = clamped_cosine_product(th.to_radians()).expect("gamma in [0, pi]");
        assert!((a - want).abs() < 1e-12, "{th}: {a} vs {want}");
    }
}

/// GGX: `int D(h) cos theta_h dh = 1` and the visible normals `int G1(wo)
/// max(0, wo . h) D(h) dh = cos theta_o` (Heitz 2014, eq. 2 and 9).
#[test]
fn ggx_furnaces() {
    for alpha in [1e-4, 1e-3, 0.05, 0.3, 1.0] {
        let g = Ggx::new(alpha).expect("valid");
        let d = sphere_integral(Vec3::z(), alpha, &[], no_kink, |h| g.d(h) * h.z.max(0.0));
        assert!((d - 1.0).abs() < 1e-11, "alpha {alpha}: int D cos = {d}");
        for th in [0.0, 45.0, 80.0, 89.9] {
            let wo = wo_at(th);
            let v = sphere_integral(Vec3::z(), alpha, &[wo], no_kink, |h| {
                g.g1(wo) * wo.dot(&h).max(0.0) * g.d(h)
            });
            assert!(
                (v - wo.z).abs() < 1e-11,
                "alpha {alpha}, {th}: {v} vs {}",
                wo.z
            );
        }
    }
}

/// GGX's D and Lambda against their textbook forms in theta:
/// `D = 1 / (pi alpha^2 cos^4 (1 + tan^2 / alpha^2)^2)`,
/// `Lambda = (-1 + sqrt(1 + alpha^2 tan^2)) / 2`.
#[test]
fn ggx_d_and_lambda_match_textbook_forms() {
    for alpha in [0.01, 0.2, 1.0] {
        let g = Ggx::new(alpha).expect("valid");
        for th in [0.0_f64, 0.3, 1.0, 1.5] {
            let w = Vec3::new(th.sin() * 0.6, th.sin() * 0.8, th.cos());
            let t2 = th.tan().powi(2);
            let d = 1.0
                / (PI * alpha * alpha * th.cos().powi(4) * (1.0 + t2 / (alpha * alpha)).powi(2));
            assert!(((g.d(w) - d) / d).abs() < 1e-12, "D at {th}");
            let l = (-1.0 + (1.0 + alpha * alpha * t2).sqrt()) / 2.0;
            assert!(
                (g.lambda(w) - l).abs() < 1e-12 * (1.0 + l),
                "Lambda at {th}"
            );
        }
    }
}

/// The unnormalised Phong lobe exceeds 1 where k_s 2 pi/(n+2) does: n = 0,
/// k_s = 1 gives pi at normal incidence.
#[test]
fn unnormalised_phong_can_exceed_one() {
    let a = albedo(&phong(1.0, 0.0), Vec3::z());
    assert!((a - PI).abs() < 1e-12, "{a}");
}

/// Bad parameters are errors naming the parameter; bad directions and u
/// give 0 or None, never NaN.
#[test]
fn bad_input() {
    let name = |e: QuadError| match e {
        QuadError::InvalidParameter { name, .. } => name,
        other => panic!("{other}"),
    };
    for a in [-0.1, 1.1, f64::NAN, f64::INFINITY] {
        assert_eq!(name(Lambert::new(a).unwrap_err()), "albedo");
        assert_eq!(name(Phong::new(a, 2.0).unwrap_err()), "k_s");
        assert_eq!(name(NormalizedPhong::new(a, 2.0).unwrap_err()), "k_s");
    }
    for n in [-1.0, f64::NAN, f64::INFINITY, 1e9] {
        assert_eq!(name(Phong::new(0.5, n).unwrap_err()), "n");
        assert_eq!(name(NormalizedPhong::new(0.5, n).unwrap_err()), "n");
    }
    for a in [0.0, -0.1, 1e-5, 1.5, f64::NAN] {
        assert_eq!(name(Ggx::new(a).unwrap_err()), "alpha");
    }
    let kinds = [lambert(0.5), phong(0.5, 1e4), nphong(0.5, 3.0), ggx(0.1)];
    let good = wo_at(30.0);
    for kind in &kinds {
        let b = kind.brdf();
        for bad in [
            Vec3::new(f64::NAN, 0.0, 1.0),
            Vec3::zeros(),
            Vec3::new(0.0, 0.0, 2.0),
            Vec3::new(0.0, 0.0, f64::INFINITY),
        ] {
            assert_eq!(b.eval(bad, good), 0.0);
            assert_eq!(b.eval(good, bad), 0.0);
            assert_eq!(b.pdf(bad, good), 0.0);
            assert_eq!(b.pdf(good, bad), 0.0);
            assert!(b.sample(bad, [0.5, 0.5]).is_none());
            assert!(b.invert(bad, good).is_none() && b.invert(good, bad).is_none());
        }
        for u in [[f64::NAN, 0.5], [1.5, 0.5], [0.5, -0.1]] {
            assert!(b.sample(good, u).is_none());
        }
        // wo below the horizon: nothing to sample.
        assert!(b.sample(-good, [0.5, 0.5]).is_none());
        assert_eq!(b.pdf(-good, good), 0.0);
    }
}

fn direction() -> impl Strategy<Value = Vec3> {
    (-1.0..=1.0_f64, 0.0..(2.0 * PI)).prop_map(|(z, phi)| {
        let r = ((1.0 - z) * (1.0 + z)).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    })
}

fn any_brdf() -> impl Strategy<Value = Kind> {
    prop_oneof![
        (0.0..=1.0_f64).prop_map(lambert),
        (0.0..=1.0_f64, 0.0..=4.0_f64).prop_map(|(k, e)| phong(k, 10f64.powf(e) - 1.0)),
        (0.0..=1.0_f64, 0.0..=4.0_f64).prop_map(|(k, e)| nphong(k, 10f64.powf(e) - 1.0)),
        (-3.0..=0.0_f64).prop_map(|e| ggx(10f64.powf(e))),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// R-rec: f(wi, wo) = f(wo, wi).
    #[test]
    fn reciprocity(kind in any_brdf(), wi in direction(), wo in direction()) {
        let b = kind.brdf();
        let (f, g) = (b.eval(wi, wo), b.eval(wo, wi));
        prop_assert!(f.is_finite() && f >= 0.0);
        prop_assert!((f - g).abs() <= 1e-14 * f.abs().max(g.abs()), "{f} vs {g}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Energy: the normalised lobes conserve (albedo <= k_s <= 1, GGX <= 1);
    /// the unnormalised Phong lobe's albedo is largest at normal incidence,
    /// `<= k_s 2 pi/(n+2)`, which is <= 1 for n >= 2 pi - 2.
    #[test]
    fn energy(kind in any_brdf(), theta in 0.0..89.99_f64) {
        let a = albedo(&kind, wo_at(theta));
        prop_assert!(a.is_finite() && a >= 0.0);
        let bound = match kind {
            Kind::Lambert(b) => {
                prop_assert!((a - b.albedo).abs() < 1e-12);
                b.albedo
            }
            Kind::Phong(b) => {
                let normal = b.k_s * phong_albedo_normal(b.exponent()).expect("n >= 0");
                if b.exponent() >= 2.0 * PI - 2.0 {
                    prop_assert!(normal <= 1.0);
                }
                normal
            }
            Kind::NormalizedPhong(b) => b.k_s,
            Kind::Ggx(_) => 1.0,
        };
        prop_assert!(a <= bound * (1.0 + 1e-10) + 1e-14, "albedo {a} > {bound}");
    }
}
