//! The rendering family's closed forms (src/exact/rendering.rs) against
//! independent references: Lambert's contour formula for the same polygon,
//! the summation and reciprocity rules of form factors, published table
//! values, and Gauss–Legendre quadrature of the defining integrals with the
//! integrand's kinks placed at piece ends.

use std::f64::consts::PI;

use lightquad::domain::Vec3;
use lightquad::exact::rendering::*;
use lightquad::quadrature::{GaussLegendre, Rule};
use rand::{RngExt, SeedableRng};

/// `int_a^b f` by Gauss–Legendre with `m` nodes (smooth `f`).
fn gl(a: f64, b: f64, m: usize, mut f: impl FnMut(f64) -> f64) -> f64 {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
    let e = GaussLegendre::default()
        .integrate(m, &mut rng, |[u]: [f64; 1]| f(a + (b - a) * u))
        .expect("integrates");
    e.value * (b - a)
}

fn rect(corners: [[f64; 3]; 4]) -> [Vec3; 4] {
    corners.map(|[x, y, z]| Vec3::new(x, y, z))
}

/// The perpendicular configuration's defining integral with the inner
/// (height) integral done in closed form and the outer one, after `x = d tan
/// phi` and `w = pi/2 - phi`, by quadrature: `F = 1/(2 pi) int_atan(1/X)^(pi/2)
/// Y^2 sin^2 w / (1 + Y^2 sin^2 w) dw`, free of the cancellation both closed
/// forms suffer. The integrand rises over `w ~ 1/Y`: the range is cut at
/// `2^k / Y` so every piece resolves it.
fn perpendicular_by_quadrature(a: f64, b: f64, d: f64) -> f64 {
    let (x, y) = (a / d, b / d);
    if x <= 1.0 {
        // phi <= pi/4: cos^2 phi >= 1/2, nothing to resolve; integrating in
        // phi from 0 keeps the short range's length exact.
        return gl(0.0, x.atan(), 40, |phi| {
            let c2 = (y * phi.cos()).powi(2);
            c2 / (1.0 + c2)
        }) / (2.0 * PI);
    }
    let h = |w: f64| {
        let s2 = (y * w.sin()).powi(2);
        s2 / (1.0 + s2)
    };
    let start = (1.0 / x).atan();
    let mut cuts = vec![start];
    cuts.extend(
        (-80..80)
            .map(|k| 2f64.powi(k) / y)
            .filter(|w| *w > start && *w < PI / 2.0),
    );
    cuts.push(PI / 2.0);
    cuts.windows(2).map(|c| gl(c[0], c[1], 40, h)).sum::<f64>() / (2.0 * PI)
}

/// Howell B-3 against Lambert's contour formula over the same rectangle,
/// and the perpendicular configuration against the contour formula and its
/// defining integral, for random sizes from 1e-6 to 1e6 of the distance
/// (receivers close to and far from the emitter).
#[test]
fn rectangle_formulas_match_the_contour_formula() -> Result<(), lightquad::QuadError> {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
    for _ in 0..500 {
        let a = 10f64.powf(rng.random_range(-6.0..6.0));
        let b = 10f64.powf(rng.random_range(-6.0..6.0));
        let c = 10f64.powf(rng.random_range(-3.0..3.0));
        let corner = rectangle_corner(a, b, c)?;
        let poly = polygon_form_factor(
            Vec3::zeros(),
            Vec3::z(),
            &rect([[0.0, 0.0, c], [a, 0.0, c], [a, b, c], [0.0, b, c]]),
        )?;
        assert!(
            (corner - poly).abs() <= 1e-14 * poly.max(1e-300) + 1e-300,
            "B-3 {a} {b} {c}: {corner} vs {poly}"
        );
        let perp = rectangle_perpendicular(a, b, c)?;
        let poly = polygon_form_factor(
            Vec3::zeros(),
            Vec3::z(),
            &rect([[0.0, c, 0.0], [a, c, 0.0], [a, c, b], [0.0, c, b]]),
        )?;
        // The contour formula cancels where the rectangle is thin seen from
        // the point (its terms are O(atan X), F much smaller): compare it
        // at that scale, and the closed form at full relative precision
        // against the cancellation-free integral.
        assert!(
            (perp - poly).abs() <= 1e-15 * (a / c).atan(),
            "perpendicular {a} {b} {c}: {perp} vs contour {poly}"
        );
        let numeric = perpendicular_by_quadrature(a, b, c);
        assert!(
            (perp - numeric).abs() <= 1e-13 * numeric,
            "perpendicular {a} {b} {c}: {perp} vs quadrature {numeric}"
        );
    }
    // A point under the rectangle's corner sees a quarter of the hemisphere's
    // projected area when the rectangle is huge: F -> 1/4.
    assert!((rectangle_corner(1e9, 1e9, 1.0)? - 0.25).abs() < 1e-9);
    Ok(())
}

/// A point under the middle of a rectangle split into four corner pieces
/// (B-3 four times) against the contour formula of the whole.
#[test]
fn four_corner_pieces_add_up_to_the_whole_rectangle() -> Result<(), lightquad::QuadError> {
    let (a, b, c) = (3.0, 2.0, 0.7);
    let (x, y) = (1.1, 0.4);
    let pieces = rectangle_corner(x, y, c)?
        + rectangle_corner(a - x, y, c)?
        + rectangle_corner(x, b - y, c)?
        + rectangle_corner(a - x, b - y, c)?;
    let whole = polygon_form_factor(
        Vec3::new(x, y, 0.0),
        Vec3::z(),
        &rect([[0.0, 0.0, c], [a, 0.0, c], [a, b, c], [0.0, b, c]]),
    )?;
    assert!((pieces - whole).abs() < 1e-15, "{pieces} vs {whole}");
    Ok(())
}

/// The contour formula with horizon clipping: a square standing across the
/// receiver's tangent plane counts only its upper half, which is the
/// perpendicular configuration.
#[test]
fn the_contour_formula_clips_at_the_horizon() -> Result<(), lightquad::QuadError> {
    let (a, b, d) = (1.3, 0.8, 0.5);
    let across = polygon_form_factor(
        Vec3::zeros(),
        Vec3::z(),
        &rect([[0.0, d, -5.0], [a, d, -5.0], [a, d, b], [0.0, d, b]]),
    )?;
    let upper = rectangle_perpendicular(a, b, d)?;
    assert!((across - upper).abs() < 1e-15, "{across} vs {upper}");
    // Wholly below: nothing.
    let below = polygon_form_factor(
        Vec3::zeros(),
        Vec3::z(),
        &rect([
            [0.0, 0.0, -1.0],
            [1.0, 0.0, -1.0],
            [1.0, 1.0, -1.0],
            [0.0, 1.0, -1.0],
        ]),
    )?;
    assert_eq!(below, 0.0);
    Ok(())
}

/// Disk: the defining ring integral `(1/pi) int_0^R h^2 / (h^2 + rho^2)^2 2 pi
/// rho d rho` by 64-node Gauss–Legendre (analytic integrand), at receiver
/// distances from 1e-6 to 1e3 of the radius.
#[test]
fn coaxial_disk_matches_its_ring_integral() -> Result<(), lightquad::QuadError> {
    for h in [1e-6, 1e-3, 0.1, 1.0, 10.0, 1e3] {
        let r: f64 = 1.0;
        // rho = h tan(phi) spreads the peak of width h: the integrand becomes
        // 2 sin(phi) cos(phi) on [0, atan(R/h)].
        let top = (r / h).atan();
        let by_quadrature = gl(0.0, top, 64, |phi| 2.0 * phi.sin() * phi.cos());
        let closed = disk_coaxial(h, r)?;
        assert!(
            (closed - by_quadrature).abs() <= 1e-14 * closed,
            "h {h}: {closed} vs {by_quadrature}"
        );
    }
    Ok(())
}

/// Howell's tabulated values: directly opposed unit squares at distance 1,
/// 0.19982; perpendicular unit squares sharing an edge, 0.20004 (Howell et
/// al., Thermal Radiation Heat Transfer, tables of C-11 and C-14).
#[test]
fn unit_square_values_match_the_published_tables() -> Result<(), lightquad::QuadError> {
    let parallel = parallel_rectangles(1.0, 1.0, 1.0)?;
    let perpendicular = perpendicular_rectangles(1.0, 1.0, 1.0)?;
    assert!((parallel - 0.19982).abs() < 5e-6, "{parallel}");
    assert!((perpendicular - 0.20004).abs() < 5e-6, "{perpendicular}");
    Ok(())
}

/// Summation: from the top face of an `a x b x c` box, the opposite face and
/// the four side faces take everything (`F_opposite + sum F_sides = 1`);
/// reciprocity: `A_1 F_12 = A_2 F_21` for perpendicular faces.
#[test]
fn box_faces_sum_to_one_and_are_reciprocal() -> Result<(), lightquad::QuadError> {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(5);
    for _ in 0..300 {
        let [a, b, c] = [(); 3].map(|_| 10f64.powf(rng.random_range(-1.5..1.5)));
        let opposite = parallel_rectangles(a, b, c)?;
        // Sides along the edges of length a (depth c, top face width b) and b.
        let sides =
            2.0 * perpendicular_rectangles(a, b, c)? + 2.0 * perpendicular_rectangles(b, a, c)?;
        let total = opposite + sides;
        assert!((total - 1.0).abs() < 1e-12, "{a} {b} {c}: {total}");
        // l x w face to l x h face: (l w) F(l, w, h) = (l h) F(l, h, w).
        let (f12, f21) = (
            perpendicular_rectangles(a, b, c)?,
            perpendicular_rectangles(a, c, b)?,
        );
        assert!((b * f12 - c * f21).abs() < 1e-13 * b * f12, "{a} {b} {c}");
    }
    Ok(())
}

/// `E / L = int_cap max(0, cos theta) d omega` by quadrature in coordinates
/// about the cap's axis: for each azimuth the polar range is split where the
/// cosine crosses 0, and the azimuth range where that crossing enters the
/// cap, so every piece's integrand is smooth.
fn cap_by_quadrature(omega: f64, alpha: f64) -> f64 {
    // Receiver normal n = (sin omega, 0, cos omega) in the cap's frame (axis z):
    // n . w = sin omega sin t cos p + cos omega cos t.
    let (so, co) = (omega.sin(), omega.cos());
    let inner = |p: f64| {
        let cosine = |t: f64| (so * t.sin() * p.cos() + co * t.cos()).max(0.0) * t.sin();
        // Zero of the cosine in t: tan t = -co / (so cos p).
        let denom = so * p.cos();
        let cut = if denom.abs() > 0.0 {
            let t = (-co / denom).atan();
            let t = if t < 0.0 { t + PI } else { t };
            Some(t).filter(|t| *t > 0.0 && *t < alpha)
        } else {
            None
        };
        match cut {
            Some(t) => gl(0.0, t, 64, cosine) + gl(t, alpha, 64, cosine),
            None => gl(0.0, alpha, 64, cosine),
        }
    };
    // Azimuths where the crossing sits at t = alpha: cos p = -co / (so tan alpha).
    let c = -co / (so * alpha.tan());
    let mut cuts = vec![0.0];
    if so > 0.0 && c.abs() < 1.0 {
        cuts.push(c.acos());
    }
    cuts.push(PI);
    // Symmetric in p: twice the integral over [0, pi].
    2.0 * cuts
        .windows(2)
        .map(|w| gl(w[0], w[1], 64, inner))
        .sum::<f64>()
}

/// Snyder's spherical-cap irradiance, above, across and below the horizon,
/// against quadrature of its definition; the horizon-centred value
/// `alpha - sin alpha cos alpha`.
#[test]
fn spherical_cap_irradiance_matches_quadrature_across_the_horizon()
-> Result<(), lightquad::QuadError> {
    for alpha in [0.05, 0.3, 0.9, 1.4] {
        for omega in [
            0.0,
            0.4,
            1.2,
            PI / 2.0 - alpha,
            1.5,
            PI / 2.0,
            1.8,
            PI / 2.0 + alpha * 0.9,
            2.9,
        ] {
            let closed = spherical_cap_irradiance(omega.cos(), alpha.sin())?;
            let numeric = cap_by_quadrature(omega, alpha);
            assert!(
                (closed - numeric).abs() <= 1e-12 * (PI * alpha.sin().powi(2)),
                "alpha {alpha} omega {omega}: {closed} vs {numeric}"
            );
        }
        let centred = spherical_cap_irradiance(0.0, alpha.sin())?;
        let want = alpha - alpha.sin() * alpha.cos();
        assert!((centred - want).abs() < 1e-15, "{centred} vs {want}");
    }
    Ok(())
}

/// Phong's directional albedo at normal incidence against
/// `2 pi int_0^(pi/2) cos^(n+1) t sin t dt` by quadrature, and the clamped
/// cosine product against its azimuth integral done in closed form and the
/// polar one by quadrature (split where the lune's edge reaches the pole).
#[test]
fn lobe_integrals_match_quadrature() -> Result<(), lightquad::QuadError> {
    for n in [0.0, 1.0, 10.0, 100.0] {
        let numeric = gl(0.0, PI / 2.0, 400, |t| {
            2.0 * PI * t.cos().powf(n + 1.0) * t.sin()
        });
        let closed = phong_albedo_normal(n)?;
        assert!(
            (closed - numeric).abs() < 1e-13 * closed,
            "n {n}: {closed} vs {numeric}"
        );
    }
    for gamma in [0.0, 0.3, 1.0, PI / 2.0, 2.5, PI] {
        // Pole a; b . w = cos g cos t + sin g sin t cos p >= 0 for |p| <= p*(t).
        let (sg, cg) = (f64::sin(gamma), f64::cos(gamma));
        let ring = |t: f64| {
            let c = if sg * t.sin() > 0.0 {
                (-cg * t.cos() / (sg * t.sin())).clamp(-1.0, 1.0)
            } else if cg >= 0.0 {
                -1.0
            } else {
                1.0
            };
            let p = c.acos();
            t.cos() * t.sin() * 2.0 * (cg * t.cos() * p + sg * t.sin() * p.sin())
        };
        // Below `edge` the whole ring is lit (p* = pi) for gamma < pi/2, or
        // none of it (p* = 0) beyond; above it p* has a square-root onset at
        // `edge`, which t = edge + L u^2 removes.
        let edge = (PI / 2.0 - gamma).abs();
        let span = PI / 2.0 - edge;
        let numeric = gl(0.0, edge, 200, ring)
            + gl(0.0, 1.0, 200, |u| {
                ring(edge + span * u * u) * 2.0 * span * u
            });
        let closed = clamped_cosine_product(gamma)?;
        assert!(
            (closed - numeric).abs() < 1e-13,
            "gamma {gamma}: {closed} vs {numeric}"
        );
    }
    Ok(())
}

/// The furnace against its Neumann series summed term by term
/// (compensated), and the truncation's tail.
#[test]
fn furnace_is_its_neumann_series() -> Result<(), lightquad::QuadError> {
    for rho in [0.0, 0.5, 0.9, 0.999] {
        let (le, mut sum, mut term, mut carry) = (2.0, 0.0f64, 2.0f64, 0.0f64);
        for _ in 0..200_000 {
            // Kahan summation of le rho^k.
            let y = term - carry;
            let t = sum + y;
            carry = (t - sum) - y;
            sum = t;
            term *= rho;
        }
        let closed = furnace(le, rho)?;
        assert!(
            (closed - sum).abs() < 1e-12 * closed,
            "rho {rho}: {closed} vs {sum}"
        );
        let (partial, tail) = furnace_truncated(le, rho, 9)?;
        let direct: f64 = (0..10).map(|k| le * rho.powi(k)).sum();
        assert!(
            (partial - direct).abs() < 1e-13 * closed,
            "{partial} vs {direct}"
        );
        assert!((partial + tail - closed).abs() < 1e-13 * closed);
    }
    assert!(furnace(1.0, 1.0).is_err());
    Ok(())
}

/// Bad input: an error naming the parameter, never a panic or NaN.
#[test]
fn bad_input_is_refused_by_name() {
    let named = |r: Result<f64, lightquad::QuadError>, name: &str| {
        let e = r.expect_err("refused").to_string();
        assert!(e.contains(&format!("invalid {name} =")), "{e}");
    };
    named(disk_coaxial(0.0, 1.0), "h");
    named(rectangle_corner(1.0, f64::NAN, 1.0), "b");
    named(parallel_rectangles(1.0, 1.0, -1.0), "c");
    named(perpendicular_rectangles(f64::INFINITY, 1.0, 1.0), "l");
    named(spherical_cap_irradiance(1.5, 0.5), "cos_omega");
    named(spherical_cap_irradiance(0.5, 0.0), "sin_alpha");
    named(phong_albedo_normal(-1.0), "n");
    named(clamped_cosine_product(4.0), "gamma");
    named(furnace(1.0, 1.2), "rho");
    named(
        polygon_form_factor(Vec3::zeros(), Vec3::zeros(), &rect([[0.0; 3]; 4])),
        "n",
    );
    named(
        polygon_form_factor(Vec3::zeros(), Vec3::z(), &[Vec3::x()]),
        "corners",
    );
}

/// The R-S audit (seed 002 prints the parameterized surface integral
/// without its area element): the printed values against closed forms and
/// a 1-D reduction computed here, and the forms with the element against
/// the surfaces' closed forms.
#[test]
fn the_rs_audit_printed_form_misses_the_area_element() {
    use lightquad::rendering::audit::rows;
    let rows = rows();
    let find = |prefix: &str, g: &str| {
        rows.iter()
            .find(|r| r.surface.starts_with(prefix) && r.g.starts_with(g))
            .unwrap_or_else(|| panic!("no row {prefix} / {g}"))
    };
    for r in &rows {
        assert!(
            (r.with_element - r.exact).abs() <= 1e-12 * r.exact,
            "{}: {} vs {}",
            r.surface,
            r.with_element,
            r.exact
        );
    }
    // Areas: the printed form integrates 1 over the parameter box.
    assert!((find("unit square", "1").printed - 1.0).abs() < 1e-14);
    assert!((find("rectangle", "1").printed - 1.0).abs() < 1e-14);
    assert!((find("sphere of radius", "1").printed - 2.0 * PI * PI).abs() < 1e-12);
    // The disk at height 1: cos theta = cos theta' = 1 / rho, rho^2 = 1 +
    // r^2, so printed = 2 pi int_0^1 dr / (1 + r^2)^2 = 2 pi (1/4 + pi/8).
    let disk = find("disk light", "R-A");
    assert!(
        (disk.printed - 2.0 * PI * (0.25 + PI / 8.0)).abs() < 1e-12,
        "{}",
        disk.printed
    );
    // The sphere light: by symmetry about the axis, printed = 2 pi int g
    // d theta over the lit cap cos theta < -1/3, with r^2 = 10 + 6 cos
    // theta, cos theta_x = (3 + cos theta) / r, cos theta' = -(1 + 3 cos
    // theta) / r (Simpson's rule, 20000 intervals).
    let g = |t: f64| {
        let c = t.cos();
        (3.0 + c) * (-(1.0 + 3.0 * c)) / (10.0 + 6.0 * c).powi(2)
    };
    let (a, b) = ((-1.0f64 / 3.0).acos(), PI);
    let m = 20_000;
    let h = (b - a) / f64::from(m);
    let simpson: f64 = (0..=m)
        .map(|i| {
            let w = if i == 0 || i == m {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            w * g(a + h * f64::from(i))
        })
        .sum::<f64>()
        * h
        / 3.0;
    let sphere = find("sphere light", "R-A");
    assert!(
        (sphere.printed - 2.0 * PI * simpson).abs() < 1e-10,
        "{} vs {}",
        sphere.printed,
        2.0 * PI * simpson
    );
    // The printed irradiance is 2.8 times the true pi / 9: no constant of
    // the sphere (R^2 = 1 here) repairs it.
    assert!(sphere.printed / sphere.exact > 2.5);
}
