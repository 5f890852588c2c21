//! The audit of R-S as printed (docs/EQUATIONS.md): the document writes a surface
//! integral through a parameterization as `int_S g dS = int_u int_v g(u, v)
//! dv du`, without the area element `|dp/du x dp/dv|`. That is exact only
//! where the element is 1; elsewhere the printed form integrates another
//! function. The audit evaluates both forms on surfaces whose element is 1,
//! a constant, and varies, against closed forms:
//!
//! | surface | parameters | `|dp/du x dp/dv|` |
//! |---|---|---|
//! | unit square | `(u, v)` in `[0, 1]^2` | 1 |
//! | rectangle 2 x 3 | `(u, v)` in `[0, 1]^2` | 6 |
//! | sphere of radius `R` | `(theta, phi)` in `[0, pi] x [0, 2 pi]` | `R^2 sin theta` |
//! | disk of radius `a` | `(r, phi)` in `[0, a] x [0, 2 pi]` | `r` |
//!
//! ```
//! use lightquad::rendering::audit::{rows, Row};
//!
//! // The sphere's area by the printed form is 2 pi^2 whatever its radius;
//! // with the element R^2 sin theta it is 4 pi R^2.
//! let sphere = rows().into_iter().find(|r| r.surface.starts_with("sphere") && r.g == "1")
//!     .expect("row");
//! assert!((sphere.printed - 2.0 * std::f64::consts::PI.powi(2)).abs() < 1e-9);
//! assert!((sphere.with_element - sphere.exact).abs() < 1e-9 * sphere.exact);
//! ```

use std::f64::consts::PI;
use std::fmt::Write as _;

use crate::domain::Vec3;
use crate::quadrature::{GaussLegendre, Rule};

/// One surface integral by both forms.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// The surface and its parameters.
    pub surface: &'static str,
    /// The area element of its parameterization.
    pub element: &'static str,
    /// The integrand `g`, in words.
    pub g: &'static str,
    /// `int int g(u, v) dv du` (R-S as printed).
    pub printed: f64,
    /// `int int g(p(u, v)) |dp/du x dp/dv| dv du`.
    pub with_element: f64,
    /// The integral's closed form.
    pub exact: f64,
}

/// Gauss–Legendre nodes, 64 per axis: every integrand below is smooth on
/// its box (the sphere light's `g` vanishes past the outline of the cap the
/// receiver sees, a kink at `theta = acos(-R / d)`, so its box starts there),
/// and 64 per axis reach rounding.
const NODES: usize = 64 * 64;

/// `int_{u in [a0, a1]} int_{v in [b0, b1]} f(u, v) dv du` by Gauss–Legendre.
fn box_integral(a: (f64, f64), b: (f64, f64), f: impl Fn(f64, f64) -> f64) -> f64 {
    let rule = GaussLegendre {
        error_estimate: false,
    };
    let mut rng = <rand_pcg::Pcg64 as rand::SeedableRng>::seed_from_u64(0);
    let (wa, wb) = (a.1 - a.0, b.1 - b.0);
    rule.integrate(NODES, &mut rng, |t: [f64; 2]| {
        f(a.0 + wa * t[0], b.0 + wb * t[1]) * wa * wb
    })
    .map_or(f64::NAN, |e| e.value)
}

/// R-A's integrand for a receiver at `x` with normal `n` and a Lambertian
/// emitter of radiance 1 at the point `y` with normal `n_y`:
/// `cos theta cos theta' / r^2`, each cosine clamped at 0.
fn geometry(x: Vec3, n: Vec3, y: Vec3, n_y: Vec3) -> f64 {
    let d = y - x;
    let r2 = d.norm_squared();
    let w = d / r2.sqrt();
    (n.dot(&w).max(0.0)) * ((-n_y.dot(&w)).max(0.0)) / r2
}

/// The audit's rows (module table), each integral by both forms.
pub fn rows() -> Vec<Row> {
    let mut out = Vec::new();
    // Areas: g = 1.
    out.push(Row {
        surface: "unit square, (u, v) in [0, 1]^2",
        element: "1",
        g: "1",
        printed: box_integral((0.0, 1.0), (0.0, 1.0), |_, _| 1.0),
        with_element: box_integral((0.0, 1.0), (0.0, 1.0), |_, _| 1.0),
        exact: 1.0,
    });
    out.push(Row {
        surface: "rectangle 2 x 3, (u, v) in [0, 1]^2",
        element: "6",
        g: "1",
        printed: box_integral((0.0, 1.0), (0.0, 1.0), |_, _| 1.0),
        with_element: box_integral((0.0, 1.0), (0.0, 1.0), |_, _| 6.0),
        exact: 6.0,
    });
    let radius = 2.0;
    out.push(Row {
        surface: "sphere of radius 2, (theta, phi) in [0, pi] x [0, 2 pi]",
        element: "R^2 sin theta",
        g: "1",
        printed: box_integral((0.0, PI), (0.0, 2.0 * PI), |_, _| 1.0),
        with_element: box_integral((0.0, PI), (0.0, 2.0 * PI), |t, _| radius * radius * t.sin()),
        exact: 4.0 * PI * radius * radius,
    });
    // Irradiance from a sphere light of radius 1 and radiance 1, centred 3
    // above a receiver that faces it: E = pi (R / d)^2 = pi / 9.
    let (x, n) = (Vec3::zeros(), Vec3::z());
    let centre = Vec3::new(0.0, 0.0, 3.0);
    let on_sphere = |t: f64, p: f64| {
        let n_y = Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
        (centre + n_y, n_y)
    };
    let g_sphere = |t: f64, p: f64| {
        let (y, n_y) = on_sphere(t, p);
        geometry(x, n, y, n_y)
    };
    // The receiver sees the cap with n_y . (x - y) > 0: cos theta < -1/3;
    // g is 0 on the rest of the box.
    let lit = ((-1.0f64 / 3.0).acos(), PI);
    out.push(Row {
        surface: "sphere light of radius 1 centred 3 above the receiver, (theta, phi)",
        element: "R^2 sin theta",
        g: "R-A's cos theta cos theta' / r^2 (E, radiance 1)",
        printed: box_integral(lit, (0.0, 2.0 * PI), g_sphere),
        with_element: box_integral(lit, (0.0, 2.0 * PI), |t, p| g_sphere(t, p) * t.sin()),
        exact: PI / 9.0,
    });
    // Irradiance from a disk light of radius 1 facing a receiver 1 below its
    // centre: E = pi a^2 / (h^2 + a^2) = pi / 2.
    let g_disk = |r: f64, p: f64| {
        let y = Vec3::new(r * p.cos(), r * p.sin(), 1.0);
        geometry(x, n, y, -Vec3::z())
    };
    out.push(Row {
        surface: "disk light of radius 1 facing the receiver from 1 above, (r, phi)",
        element: "r",
        g: "R-A's cos theta cos theta' / r^2 (E, radiance 1)",
        printed: box_integral((0.0, 1.0), (0.0, 2.0 * PI), g_disk),
        with_element: box_integral((0.0, 1.0), (0.0, 2.0 * PI), |r, p| g_disk(r, p) * r),
        exact: PI / 2.0,
    });
    out
}

/// The audit as a report section.
pub fn markdown() -> String {
    let mut md = String::from(
        "\n## Rendering family: R-S audit: the printed parameterized surface integral against \
         the one with its area element\n\n\
         R-S is printed as `int_S g dS = int_u int_v g(u, v) dv du`, without the area element \
         `|dp/du x dp/dv|` of the parameterization `p(u, v)` (docs/EQUATIONS.md, R-S). Both \
         forms by 64 x 64 Gauss–Legendre nodes over the parameter box (every integrand is \
         smooth there), against closed forms. The printed form is right only where the element \
         is 1; a constant element scales it, and a varying one (the sphere in (theta, phi)) \
         weights the surface unevenly, so no constant repairs it. lightquad's area forms \
         (`E_area`, `L_area`) integrate with the element of each emitter's map.\n\n\
         | surface, parameters | area element | g | printed | with the element | closed form | printed / closed form |\n\
         |---|---|---|---:|---:|---:|---:|\n",
    );
    for r in rows() {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {:.10e} | {:.10e} | {:.10e} | {:.4} |",
            r.surface,
            r.element,
            r.g,
            r.printed,
            r.with_element,
            r.exact,
            r.printed / r.exact
        );
    }
    md
}
