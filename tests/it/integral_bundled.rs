//! The bundled `experiments/integral-*.json`: each file's `exact` against a
//! closed form derived here, independently, from this file's own copy of the
//! integral's parameters (not parsed from the file's expression), and the
//! file's integrand, integrated by the library, against that closed form.
//!
//! Every file must have its row in [`CASES`], so a new bundled integral
//! without an independent check fails. `cargo test --release --test it
//! integral_bundled:: -- --nocapture` prints the figures.

use std::f64::consts::{E, PI};

use lightquad::experiment::validate::{deserialize, validate};
use lightquad::family::{Family, Method};
use lightquad::integral::{Built, Integral, Quantity};
use lightquad::quadrature::{AnyRule, BaseRule, GaussLegendre};

use crate::common::{self, bin, rel, scratch};

/// How a file's integrand is integrated to check it.
#[derive(Debug, Clone, Copy)]
enum Check {
    /// The family's converged evaluation at this `n` (adaptive
    /// Gauss–Kronrod in 1-D, Genz–Malik in 2-D to 6-D).
    Converged(usize),
    /// Gauss–Legendre's product rule with this many nodes per axis and its
    /// error estimate.
    GaussLegendre(usize),
}

/// One bundled file: its name, its value by an independent closed form,
/// whether the integrand is smooth (its integral must then agree to 1e-10)
/// and how it is integrated.
struct Case {
    name: &'static str,
    exact: fn() -> f64,
    smooth: bool,
    check: Check,
}

const CASES: &[Case] = &[
    Case {
        name: "integral-pixel-texture",
        exact: pixel_texture,
        smooth: true,
        check: Check::Converged(100),
    },
    Case {
        name: "integral-box-4d-smooth",
        exact: box_4d,
        smooth: true,
        check: Check::Converged(400),
    },
    Case {
        name: "integral-cube-6d-smooth",
        exact: cube_6d,
        smooth: true,
        check: Check::GaussLegendre(10),
    },
    Case {
        name: "integral-1d-kink",
        exact: kink_1d,
        smooth: false,
        check: Check::Converged(100),
    },
    Case {
        name: "integral-2d-jump",
        exact: jump_2d,
        smooth: false,
        check: Check::Converged(300),
    },
    Case {
        name: "integral-genz-oscillatory-4d",
        exact: genz_oscillatory,
        smooth: true,
        check: Check::GaussLegendre(24),
    },
    Case {
        name: "integral-genz-product-peak-2d",
        exact: genz_product_peak,
        smooth: true,
        check: Check::Converged(300),
    },
    Case {
        name: "integral-genz-corner-peak-6d",
        exact: genz_corner_peak,
        smooth: true,
        check: Check::GaussLegendre(12),
    },
    Case {
        name: "integral-genz-gaussian-4d",
        exact: genz_gaussian,
        smooth: true,
        check: Check::GaussLegendre(24),
    },
    Case {
        name: "integral-genz-c0-2d",
        exact: genz_c0,
        smooth: false,
        check: Check::Converged(300),
    },
    Case {
        name: "integral-genz-discontinuous-6d",
        exact: genz_discontinuous,
        smooth: false,
        check: Check::Converged(600),
    },
];

// ---------------------------------------------------------------------------
// The closed forms, derived here.

/// `1/2 + 1/2 sin(7x + 1) cos(5y)` over the pixel `[12, 13] x [7, 8]`: the
/// product of `int sin(kx x + p) dx = (cos a - cos b) / kx
/// = 2 sin((a + b)/2) sin((b - a)/2) / kx` (a, b the phases at the pixel's
/// edges) and `int cos(ky y) dy = (sin d - sin c) / ky
/// = 2 cos((c + d)/2) sin((d - c)/2) / ky`, plus half the pixel's area.
fn pixel_texture() -> f64 {
    let (kx, phase, ky) = (7.0_f64, 1.0_f64, 5.0_f64);
    let (x0, y0, width, height) = (12.0_f64, 7.0_f64, 1.0_f64, 1.0_f64);
    let (a, b) = (kx * x0 + phase, kx * (x0 + width) + phase);
    let along_x = 2.0 * ((a + b) / 2.0).sin() * ((b - a) / 2.0).sin() / kx;
    let (c, d) = (ky * y0, ky * (y0 + height));
    let along_y = 2.0 * ((c + d) / 2.0).cos() * ((d - c) / 2.0).sin() / ky;
    0.5 * width * height + 0.5 * along_x * along_y
}

/// `1/(1 + x1 x2 x3 x4)` over `[0, s1] x ... x [0, s4]`: with `x_i = s_i u_i`
/// it is `V int_[0,1]^4 1/(1 + P u1 u2 u3 u4)`, `V = P = prod s_i`, and
/// expanding `1/(1 + t) = sum (-t)^k` term by term, `int u^k = 1/(k + 1)`
/// per axis: `V sum_k (-P)^k / (k + 1)^4`. Summed from the smallest term up
/// (20000 terms: the alternating tail is below 1/20001^4 ~ 6e-18).
fn box_4d() -> f64 {
    let sides = [2.0_f64, 1.0, 1.0, 0.5];
    let p: f64 = sides.iter().product();
    let volume = p;
    let terms = 20_000;
    let sum = (0..terms).rev().fold(0.0, |acc, k| {
        let m = (k + 1) as f64;
        acc + (-p).powi(k) / (m * m * m * m)
    });
    volume * sum
}

/// `exp(x1 x2 + x3 x4 + x5 x6)` on `[0, 1]^6`: the cube of
/// `int_[0,1]^2 e^(xy) = sum_k int (xy)^k / k! = sum_(k >= 0) 1/((k + 1)^2 k!)
/// = sum_(k >= 1) 1/(k k!)`, summed from the smallest term up.
fn cube_6d() -> f64 {
    let mut terms = Vec::new();
    let mut factorial = 1.0_f64;
    for k in 1..=30 {
        factorial *= k as f64;
        terms.push(1.0 / (k as f64 * factorial));
    }
    let pair: f64 = terms.iter().rev().sum();
    pair * pair * pair
}

/// `|e^x - L|` on `[0, 1]`, L = 3/2, kinked at `c = ln L`:
/// `int_0^c (L - e^x) + int_c^1 (e^x - L) = (L c - (L - 1)) + ((e - L) - L (1 - c))`.
fn kink_1d() -> f64 {
    let level = 1.5_f64;
    let c = level.ln();
    (level * c - (level - 1.0)) + ((E - level) - level * (1.0 - c))
}

/// `e^(x + y)` above the line `y = m x + b` (m = 1/2, b = 3/10, inside the
/// unit square for every x) on `[0, 1]^2`:
/// `int_0^1 e^x (e - e^(m x + b)) dx = e (e - 1) - e^b (e^(1 + m) - 1)/(1 + m)`.
fn jump_2d() -> f64 {
    let (m, b) = (0.5_f64, 0.3_f64);
    E * (E - 1.0) - b.exp() * (1.0 + m).exp_m1() / (1.0 + m)
}

/// Genz's oscillatory `cos(2 pi w1 + sum a_i x_i)` on `[0, 1]^4`: the real
/// part of `e^(i 2 pi w1) prod_i int_0^1 e^(i a_i x) dx`, each factor
/// `(e^(i a) - 1)/(i a) = sin(a)/a + i (1 - cos a)/a`, multiplied out as
/// complex numbers.
fn genz_oscillatory() -> f64 {
    let a = [3.0_f64, 2.5, 2.0, 1.5];
    let w1 = 0.3_f64;
    let mul = |(p, q): (f64, f64), (r, s): (f64, f64)| (p * r - q * s, p * s + q * r);
    let start = ((2.0 * PI * w1).cos(), (2.0 * PI * w1).sin());
    let product = a.iter().fold(start, |z, &ai| {
        let half = (ai / 2.0).sin();
        mul(z, (ai.sin() / ai, 2.0 * half * half / ai))
    });
    product.0
}

/// Genz's product peak `prod (a_i^-2 + (x_i - w_i)^2)^-1` on `[0, 1]^2`:
/// per axis `a (atan(a (1 - w)) + atan(a w))`, the sum of the two arctangents
/// taken as the argument of `(1 + i p)(1 + i q)`: `atan2(p + q, 1 - p q)`.
fn genz_product_peak() -> f64 {
    let a = [5.0_f64, 10.0];
    let w = [0.4_f64, 0.7];
    a.iter()
        .zip(w)
        .map(|(&ai, wi)| {
            let (p, q) = (ai * (1.0 - wi), ai * wi);
            ai * (p + q).atan2(1.0 - p * q)
        })
        .product()
}

/// Genz's corner peak `(1 + sum a_i x_i)^-(d+1)` on `[0, 1]^d`, d = 6:
/// integrating axis by axis (`int_0^1 (c + a x)^-m dx = (c^(1-m) -
/// (c + a)^(1-m)) / (a (m - 1))`) leaves
/// `sum over subsets S of (-1)^|S| / (1 + sum_S a_i)`, divided by `d! prod a_i`.
/// The terms cancel to a small fraction of each, so the sum is taken in
/// exact rational arithmetic (a_i = k_i / 2, each term `2 / (2 + sum_S k_i)`).
fn genz_corner_peak() -> f64 {
    let k: [i128; 6] = [1, 2, 3, 1, 2, 1];
    let gcd = |mut a: i128, mut b: i128| {
        while b != 0 {
            (a, b) = (b, a % b);
        }
        a.abs()
    };
    // The sum as num / den, reduced after each term.
    let (mut num, mut den) = (0_i128, 1_i128);
    for subset in 0..(1u32 << k.len()) {
        let inside: i128 = (0..k.len())
            .filter(|i| subset >> i & 1 == 1)
            .map(|i| k[i])
            .sum();
        let sign = if subset.count_ones() % 2 == 0 { 1 } else { -1 };
        // + sign * 2 / (2 + inside)
        let (p, q) = (sign * 2, 2 + inside);
        num = num * q + p * den;
        den *= q;
        let g = gcd(num, den);
        (num, den) = (num / g, den / g);
    }
    // d! prod a_i = 720 prod k_i / 2^6.
    let prod_k: i128 = k.iter().product();
    let (mut num, mut den) = (num * 64, den * 720 * prod_k);
    let g = gcd(num, den);
    (num, den) = (num / g, den / g);
    assert!(num.abs() < 1 << 53 && den < 1 << 53, "{num}/{den}");
    num as f64 / den as f64
}

/// Genz's Gaussian `exp(-sum a_i^2 (x_i - w_i)^2)` on `[0, 1]^4`: per axis
/// `sqrt(pi) / (2 a) (erf(a (1 - w)) + erf(a w))` (libm's erf).
fn genz_gaussian() -> f64 {
    let a = [4.0_f64, 3.0, 5.0, 2.0];
    let w = [0.3_f64, 0.6, 0.45, 0.8];
    a.iter()
        .zip(w)
        .map(|(&ai, wi)| PI.sqrt() / (2.0 * ai) * (libm::erf(ai * (1.0 - wi)) + libm::erf(ai * wi)))
        .product()
}

/// Genz's C0 `exp(-sum a_i |x_i - w_i|)` on `[0, 1]^2`: per axis
/// `(1 - e^(-a w) + 1 - e^(-a (1 - w))) / a`, by `expm1`.
fn genz_c0() -> f64 {
    let a = [6.0_f64, 4.0];
    let w = [0.35_f64, 0.6];
    a.iter()
        .zip(w)
        .map(|(&ai, wi)| -((-ai * wi).exp_m1() + (-ai * (1.0 - wi)).exp_m1()) / ai)
        .product()
}

/// Genz's discontinuous function on `[0, 1]^6`: 0 where `x1 > w1` or
/// `x2 > w2`, else `exp(sum a_i x_i)`: per axis `(e^(a t) - 1)/a` with `t = w_i`
/// on the first two axes and 1 on the rest.
fn genz_discontinuous() -> f64 {
    let a = [1.5_f64, 1.0, 0.5, 2.0, 1.0, 0.5];
    let w = [0.6_f64, 0.4];
    a.iter()
        .enumerate()
        .map(|(i, &ai)| {
            let top = w.get(i).copied().unwrap_or(1.0);
            (ai * top).exp_m1() / ai
        })
        .product()
}

// ---------------------------------------------------------------------------
// The checks.

/// The bundled file `name`, validated: its built scene.
fn scene(name: &str) -> Built {
    let path = common::root()
        .join("experiments")
        .join(format!("{name}.json"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path:?}: {e}"));
    let json: serde_json::Value = serde_json::from_str(&text).expect("json");
    let spec = deserialize::<Integral>(json).unwrap_or_else(|e| panic!("{name}: {e}"));
    validate::<Integral>(spec, "hash")
        .unwrap_or_else(|e| panic!("{name}: {e}"))
        .scene
}

/// The file's `exact` against the independent closed form (1e-13), and
/// its integrand integrated by [`Check`] against the closed form: within
/// its own error estimate, and to 1e-10 where the integrand is smooth.
fn check(name: &str) {
    let case = CASES
        .iter()
        .find(|c| c.name == name)
        .unwrap_or_else(|| panic!("{name} has no row in CASES"));
    let scene = scene(name);
    let independent = (case.exact)();
    let file = Integral::closed_form(&scene, Quantity::Integral).expect("the file's exact")[0];
    let agreement = rel(file, independent);
    println!(
        "{name}: file's exact {file:.17e}, independent {independent:.17e}, relative {agreement:.1e}"
    );
    assert!(
        agreement <= 1e-13,
        "{name}: the file's exact {file:e} against {independent:e} (relative {agreement:e})"
    );
    let measured = match case.check {
        Check::Converged(n) => <Integral as Family>::converged(&scene, n, &[Quantity::Integral])
            .unwrap_or_else(|e| panic!("{name}: {e}")),
        Check::GaussLegendre(m) => {
            let rule = AnyRule::Base(BaseRule::GaussLegendre(GaussLegendre::default()));
            let dim = Integral::dimension(&scene, Quantity::Integral);
            let budget = m.pow(dim as u32);
            Integral::evaluate(
                &scene,
                &Method::Rule(rule),
                budget,
                &mut common::rng(1),
                &[Quantity::Integral],
            )
            .unwrap_or_else(|e| panic!("{name}: {e}"))
        }
    }
    .remove(&Quantity::Integral)
    .expect("the integral");
    let (value, error) = (measured.value[0], measured.error[0]);
    let off = (value - independent).abs();
    println!(
        "{name}: {:?} gave {value:.17e} +- {error:.1e} ({} evaluations): off by {off:.1e}, \
         relative {:.1e}",
        case.check,
        measured.evaluations,
        rel(value, independent)
    );
    assert!(
        error.is_finite() && off <= error,
        "{name}: {value:e} is {off:e} off {independent:e}, beyond its error estimate {error:e}"
    );
    if case.smooth {
        assert!(
            rel(value, independent) <= 1e-10,
            "{name}: {value:e} against {independent:e} (relative {:e})",
            rel(value, independent)
        );
    }
}

#[test]
fn pixel_texture_matches_its_closed_form() {
    check("integral-pixel-texture");
}

#[test]
fn box_4d_matches_its_closed_form() {
    check("integral-box-4d-smooth");
}

#[test]
fn cube_6d_matches_its_closed_form() {
    check("integral-cube-6d-smooth");
}

#[test]
fn kink_1d_matches_its_closed_form() {
    check("integral-1d-kink");
}

#[test]
fn jump_2d_matches_its_closed_form() {
    check("integral-2d-jump");
}

#[test]
fn genz_oscillatory_matches_its_closed_form() {
    check("integral-genz-oscillatory-4d");
}

#[test]
fn genz_product_peak_matches_its_closed_form() {
    check("integral-genz-product-peak-2d");
}

#[test]
fn genz_corner_peak_matches_its_closed_form() {
    check("integral-genz-corner-peak-6d");
}

#[test]
fn genz_gaussian_matches_its_closed_form() {
    check("integral-genz-gaussian-4d");
}

#[test]
fn genz_c0_matches_its_closed_form() {
    check("integral-genz-c0-2d");
}

#[test]
fn genz_discontinuous_matches_its_closed_form() {
    check("integral-genz-discontinuous-6d");
}

/// Every bundled `integral-*.json` has its row in [`CASES`] (and its test
/// above), and every row its file: a new file without an independent check
/// fails here.
#[test]
fn every_bundled_integral_has_an_independent_check() {
    let files: Vec<String> = common::bundled("integral-")
        .iter()
        .map(|(path, json)| {
            let stem = path.file_stem().and_then(|s| s.to_str()).expect("stem");
            assert_eq!(json["name"], stem, "{path:?}: name is the file stem");
            assert_eq!(json["family"], "integral", "{path:?}");
            assert_eq!(json["reference"]["type"], "closed-form", "{path:?}");
            stem.to_string()
        })
        .collect();
    let mut rows: Vec<String> = CASES.iter().map(|c| c.name.to_string()).collect();
    rows.sort();
    assert_eq!(files, rows, "bundled files against the rows of CASES");
    // Each row has its own test (the list above names them all).
    let source = include_str!("integral_bundled.rs");
    for case in CASES {
        assert_eq!(
            source
                .matches(&format!("check(\"{}\");", case.name))
                .count(),
            1,
            "{}: one test calls check on it",
            case.name
        );
    }
}

/// The binary runs one of them and its report's reference line shows the
/// exact value.
#[test]
fn the_report_of_a_bundled_integral_shows_its_exact_value() {
    let name = "integral-1d-kink";
    let out = scratch("integral-bundled");
    let o = bin()
        .arg("run")
        .arg(
            common::root()
                .join("experiments")
                .join(format!("{name}.json")),
        )
        .arg("--out")
        .arg(&out)
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", common::stderr(&o));
    let report = std::fs::read_to_string(out.join(name).join("report.md")).expect("report");
    let line = report
        .lines()
        .find(|l| l.starts_with("## integral (reference "))
        .unwrap_or_else(|| panic!("no reference line in {report}"));
    let shown: f64 = line
        .trim_start_matches("## integral (reference ")
        .trim_end_matches(')')
        .parse()
        .unwrap_or_else(|e| panic!("{line}: {e}"));
    let exact = kink_1d();
    println!("{line}; independent {exact:.17e}");
    // The line shows 16 significant digits.
    assert!(rel(shown, exact) <= 1e-15, "{line} against {exact:e}");
    assert!(
        report.contains("Reference: closed forms of the integral family."),
        "{report}"
    );
    let _ = std::fs::remove_dir_all(&out);
}
