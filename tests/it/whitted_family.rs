//! The Whitted family of the experiment layer (src/whitted/experiment/).
//!
//! Layers: (1) the bundled `w-*` experiments validate and run on the real
//! binary, report every quantity, and cover every W-* equation ID; (2) the
//! closed forms against computations written here (a triangle's projected
//! coverage by the pinhole formula and a fine grid of the renderer's own
//! primary rays; a plane's horizon); (3) the rays traced by kind through
//! the family, W-Corner's `(s + 1)(z + 1)`; the jittered order through the
//! renderer on a triangle's edge; (4) bad input refused by `check` with the
//! JSON path, and the energy warning printed; extreme numbers never panic.

use std::fs;

use crate::common;
use common::{bin, bundled, fitted_order, root, scratch, stderr};

use lightquad::experiment::validate::{Experiment, deserialize, validate};
use lightquad::family::{Family, Method};
use lightquad::whitted::experiment::{Scheme, Whitted, WhittedQuantity as Q, evaluate_counted};
use rand::SeedableRng;
use serde_json::{Value, json};

fn load(json: Value) -> Experiment<Whitted> {
    validate::<Whitted>(deserialize(json).expect("parses"), "hash").expect("valid")
}

/// A scene with one white ambient-lit triangle on black, seen by a 8 x 6
/// camera looking down -z from the origin.
fn triangle_scene(pixel: [usize; 2]) -> Value {
    json!({
        "camera": {"eye": [0.0, 0.0, 0.0], "look_at": [0.0, 0.0, -1.0], "up": [0.1, 1.0, 0.0],
                   "fov_y": 50.0, "width": 8, "height": 6},
        "ambient": [1.0, 1.0, 1.0],
        "objects": [{"type": "triangle", "a": [-0.8, -0.6, -2.0], "b": [0.37, -0.5, -2.5],
                     "c": [-0.2, 0.61, -2.2], "material": {"k_a": 0.8, "colour": [1.0, 0.5, 0.25]}}],
        "pixel": pixel
    })
}

fn experiment(scene: Value, quantities: &[&str]) -> Experiment<Whitted> {
    load(json!({
        "name": "t", "family": "whitted", "scene": scene, "quantities": quantities,
        "rules": [{"rule": "grid"}], "budgets": [16], "repeats": 1,
        "reference": {"type": "closed-form"}
    }))
}

fn by(exp: &Experiment<Whitted>, method: Value, budget: usize, q: Q, seed: u64) -> (Vec<f64>, u64) {
    let method: Method<Scheme> = serde_json::from_value(method).expect("a method");
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let (m, rays) = evaluate_counted(&exp.scene, &method, budget, &mut rng, q).expect("evaluates");
    (m.value, rays.total())
}

// ---------------------------------------------------------------- (1) binary

#[test]
fn the_bundled_whitted_experiments_validate_run_and_cover_every_equation() {
    let files = bundled("w-");
    assert!(files.len() >= 4, "{} bundled w-* experiments", files.len());
    let check = bin()
        .arg("check")
        .args(files.iter().map(|f| &f.0))
        .output()
        .expect("runs");
    assert!(check.status.success(), "{}", stderr(&check));
    let dir = scratch("bundled-w");
    let out = dir.join("out");
    let run = bin()
        .args(["run", "--out"])
        .arg(&out)
        .args(files.iter().map(|f| &f.0))
        .output()
        .expect("runs");
    assert!(run.status.success(), "{}", stderr(&run));
    let mut ids = std::collections::BTreeSet::new();
    for (path, spec) in &files {
        let name = spec["name"].as_str().expect("name");
        assert_eq!(path.file_stem().and_then(|s| s.to_str()), Some(name));
        let finished = stderr(&run)
            .lines()
            .find(|l| l.starts_with(&format!("finished {name}: ")))
            .map(str::to_string)
            .unwrap_or_else(|| panic!("{name} not run"));
        assert!(finished.contains(" 0 failed"), "{finished}");
        let report = fs::read_to_string(out.join(name).join("report.md")).expect("report");
        for q in spec["quantities"].as_array().expect("quantities") {
            let q = q.as_str().expect("name");
            assert!(
                report.contains(&format!("## {q} (reference")),
                "{name} lacks {q}"
            );
        }
        assert!(!report.contains("NaN"), "{name} reports a NaN");
        if name == "w-6-1-phong-pixel" {
            // On a smooth pixel W-SS's grid is the midpoint product rule,
            // second order per axis like the trapezoid rule: the report's
            // per-axis slope says -2, not the -1 of a slope against N (the
            // per-axis column once held the slope against N for schemes).
            let slope = |rule: &str| -> f64 {
                let row = report
                    .lines()
                    .find(|l| l.starts_with(&format!("| {rule} | -")))
                    .unwrap_or_else(|| panic!("no slope row for {rule}"));
                // The cell is "-2.00 ± 0.01": the slope, then its interval.
                row.split('|')
                    .nth(2)
                    .and_then(|c| c.split_whitespace().next())
                    .and_then(|c| c.parse().ok())
                    .expect("slope")
            };
            for rule in ["grid", "trapezoid"] {
                assert!((slope(rule) + 2.0).abs() < 0.15, "{rule}: {}", slope(rule));
            }
        }
        assert!(report.contains("## Terms and rays of this scene"), "{name}");
        if spec["quantities"]
            .as_array()
            .is_some_and(|q| q.contains(&json!("image")))
        {
            images_are_the_results(&out.join(name), name);
        }
        let description = spec["description"].as_str().expect("description");
        assert!(description.len() > 200, "{name}: say what the report shows");
        for id in spec["equations"].as_array().expect("equations") {
            ids.insert(id.as_str().expect("id").to_string());
        }
    }
    for id in Whitted::EQUATIONS {
        assert!(ids.contains(*id), "no bundled experiment for {id}");
    }
    let _ = fs::remove_dir_all(&dir);
}

/// An image experiment's report shows each rule's mean image at its largest
/// budget as PNG, with an error map: checked here against results.jsonl
/// with W-Grey written out (`round(255 clamp(v, 0, 1))`) and the
/// reference's PFM read back (f32, rows from the bottom): the PNG holds the
/// mean's bytes, the map's white pixel is the one of the largest error, and
/// the page shows every file.
fn images_are_the_results(dir: &std::path::Path, name: &str) {
    let decode = |path: &std::path::Path| -> (usize, Vec<u8>) {
        let file = fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let mut reader = png::Decoder::new(std::io::BufReader::new(file))
            .read_info()
            .expect("a PNG");
        let mut buf = vec![0; reader.output_buffer_size().expect("size")];
        let info = reader.next_frame(&mut buf).expect("a frame");
        buf.truncate(info.buffer_size());
        (info.width as usize, buf)
    };
    let grey = |v: f64| (255.0 * v.clamp(0.0, 1.0)).round() as u8;
    let html = fs::read_to_string(dir.join("index.html")).expect("page");
    let pfm = fs::read(dir.join(format!("{name}-image-reference.pfm"))).expect("reference PFM");
    let header: Vec<&[u8]> = pfm.splitn(4, |&b| b == b'\n').collect();
    let dims: Vec<usize> = std::str::from_utf8(header[1])
        .expect("text")
        .split(' ')
        .map(|x| x.parse().expect("a size"))
        .collect();
    let (w, h) = (dims[0], dims[1]);
    let floats: Vec<f64> = header[3]
        .chunks_exact(4)
        .map(|b| f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])))
        .collect();
    // Rows from the top.
    let reference: Vec<f64> = (0..h)
        .rev()
        .flat_map(|row| floats[row * 3 * w..(row + 1) * 3 * w].to_vec())
        .collect();
    let mut by_rule: std::collections::BTreeMap<(usize, usize), Vec<Vec<f64>>> = Default::default();
    let mut labels = std::collections::BTreeMap::new();
    for line in fs::read_to_string(dir.join("results.jsonl"))
        .expect("results")
        .lines()
    {
        let job: Value = serde_json::from_str(line).expect("a job");
        let (i, n) = (
            job["rule_index"].as_u64().expect("i") as usize,
            job["budget"].as_u64().expect("n") as usize,
        );
        labels.insert(i, job["rule"].as_str().expect("rule").to_string());
        let value: Vec<f64> = job["quantities"]["image"]["value"]
            .as_array()
            .expect("image values")
            .iter()
            .map(|v| v.as_f64().expect("a number"))
            .collect();
        by_rule.entry((i, n)).or_default().push(value);
    }
    for (i, rule) in &labels {
        let (&(_, n), repeats) = by_rule
            .range((*i, 0)..=(*i, usize::MAX))
            .next_back()
            .expect("a row");
        let mean: Vec<f64> = (0..3 * w * h)
            .map(|c| repeats.iter().map(|v| v[c]).sum::<f64>() / repeats.len() as f64)
            .collect();
        let label: String = rule
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
            .collect();
        let stem = format!("{name}-image-{i}-{label}-n{n}");
        let (width, bytes) = decode(&dir.join(format!("{stem}.png")));
        assert_eq!(width, w);
        let mine: Vec<u8> = mean.iter().map(|&v| grey(v)).collect();
        let off = bytes.iter().zip(&mine).filter(|(a, b)| a != b).count();
        assert_eq!(off, 0, "{stem}: {off} bytes differ from the mean's");
        let (_, map) = decode(&dir.join(format!("{stem}-error.png")));
        let errors: Vec<f64> = (0..w * h)
            .map(|p| {
                (0..3)
                    .map(|c| (mean[3 * p + c] - reference[3 * p + c]).abs())
                    .fold(0.0, f64::max)
            })
            .collect();
        let largest = errors.iter().copied().fold(0.0, f64::max);
        if largest > 1e-6 {
            let white = (0..w * h)
                .find(|&p| map[3 * p..3 * p + 3] == [255, 255, 255])
                .unwrap_or_else(|| panic!("{stem}: no white pixel in the error map"));
            assert!(
                errors[white] >= 0.999 * largest,
                "{stem}: white at {white}, error {} of {largest}",
                errors[white]
            );
        }
        for file in [
            format!("{stem}.png"),
            format!("{stem}-error.png"),
            format!("{stem}.pfm"),
        ] {
            assert!(
                html.contains(&format!("\"{file}\"")),
                "{name}: the page does not show {file}"
            );
        }
    }
}

// ------------------------------------------------------- (2) closed forms

/// The triangle's coverage of every pixel: the closed form against the
/// projection written here (`x = W/2 (1 + X / (Z tan(fov/2) W/H))` with the
/// camera's frame built here from `up`) and a 512 x 512 grid of the
/// renderer's own primary rays (error below 1/512 per pixel edge length).
#[test]
fn a_triangles_coverage_is_its_projection_clipped_to_the_pixel() {
    let scene = triangle_scene([0, 0]);
    let mut total_exact = 0.0;
    let mut covered = 0;
    for j in 0..6 {
        for i in 0..8 {
            let mut s = scene.clone();
            s["pixel"] = json!([i, j]);
            let exp = experiment(s, &["coverage", "pixel"]);
            let exact = Whitted::closed_form(&exp.scene, Q::Coverage).expect("closed form")[0];
            let (fine, _) = by(&exp, json!({"rule": "grid"}), 512 * 512, Q::Coverage, 0);
            assert!(
                (fine[0] - exact).abs() < 2.0 / 512.0,
                "pixel {i} {j}: {} vs {exact}",
                fine[0]
            );
            // The pixel value: background 0 + (0.8 (1, 0.5, 0.25)) coverage.
            let px = Whitted::closed_form(&exp.scene, Q::Pixel).expect("closed form");
            for (c, k) in px.iter().zip([0.8, 0.4, 0.2]) {
                assert!((c - k * exact).abs() < 1e-15);
            }
            total_exact += exact;
            covered += usize::from(exact > 0.0 && exact < 1.0);
        }
    }
    // The triangle's projected area, by the shoelace formula here.
    let (w, h, fov) = (8.0_f64, 6.0_f64, 50f64.to_radians());
    let forward = [0.0, 0.0, -1.0_f64];
    let upv = [0.1, 1.0, 0.0_f64];
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let right = cross(forward, upv);
    let rn = dot(right, right).sqrt();
    let right = right.map(|x| x / rn);
    let up = cross(right, forward);
    let t = (fov / 2.0).tan();
    let project = |p: [f64; 3]| {
        let z = dot(p, forward);
        [
            w / 2.0 * (1.0 + dot(p, right) / z / (t * w / h)),
            h / 2.0 * (1.0 - dot(p, up) / z / t),
        ]
    };
    let v = [[-0.8, -0.6, -2.0], [0.37, -0.5, -2.5], [-0.2, 0.61, -2.2]].map(project);
    // Inside the image, so the pixels' coverages add up to its area.
    assert!(
        v.iter()
            .all(|p| p[0] > 0.0 && p[0] < w && p[1] > 0.0 && p[1] < h),
        "{v:?}"
    );
    let area = 0.5
        * ((v[1][0] - v[0][0]) * (v[2][1] - v[0][1]) - (v[2][0] - v[0][0]) * (v[1][1] - v[0][1]))
            .abs();
    assert!(area < 48.0 && area > 1.0, "{area}");
    println!(
        "projected triangle area {area:.6}, sum of pixel coverages {total_exact:.6}, {covered} edge pixels"
    );
    assert!(
        (total_exact - area).abs() < 1e-12,
        "{total_exact} vs {area}"
    );
}

/// A floor plane seen toward its horizon with the camera rolled by 20
/// degrees: the covered film is a half-plane; its closed form matches a fine
/// grid of primary rays at every pixel.
#[test]
fn a_planes_horizon_is_a_straight_edge_across_the_pixels() {
    for j in 0..6 {
        for i in 0..8 {
            let exp = experiment(
                json!({
                    "camera": {"eye": [0.0, 1.0, 0.0], "look_at": [0.0, 1.0, -1.0],
                               "up": [0.34202, 0.93969, 0.0], "fov_y": 4.0, "width": 8, "height": 6},
                    "ambient": [1.0, 1.0, 1.0],
                    "objects": [{"type": "plane", "point": [0.0, 0.0, 0.0], "normal": [0.0, 1.0, 0.0],
                                 "material": {"k_a": 1.0}}],
                    "pixel": [i, j]
                }),
                &["coverage"],
            );
            let exact = Whitted::closed_form(&exp.scene, Q::Coverage).expect("closed form")[0];
            let (fine, _) = by(&exp, json!({"rule": "grid"}), 256 * 256, Q::Coverage, 0);
            assert!(
                (fine[0] - exact).abs() < 2.0 / 256.0,
                "{i} {j}: {} vs {exact}",
                fine[0]
            );
        }
    }
}

/// The 3-D point at depth 2 whose pinhole image is film point `[x, y]` of
/// an 8 x 6 camera at the origin looking down -z with up +y and a 50 degree
/// field (the pinhole formula, written out here).
fn on_film(x: f64, y: f64) -> [f64; 3] {
    let t = (25.0_f64).to_radians().tan();
    let (sx, sy) = (
        (2.0 * x / 8.0 - 1.0) * t * 8.0 / 6.0,
        (1.0 - 2.0 * y / 6.0) * t,
    );
    [2.0 * sx, 2.0 * sy, -2.0]
}

/// Pixel [3, 2] of a scene holding the one triangle whose film image has
/// the corners `film`.
fn film_triangle(film: [[f64; 2]; 3]) -> Experiment<Whitted> {
    let [a, b, c] = film.map(|p| on_film(p[0], p[1]));
    experiment(
        json!({
            "camera": {"eye": [0.0, 0.0, 0.0], "look_at": [0.0, 0.0, -1.0], "up": [0.0, 1.0, 0.0],
                       "fov_y": 50.0, "width": 8, "height": 6},
            "ambient": [1.0, 1.0, 1.0],
            "objects": [{"type": "triangle", "a": a, "b": b, "c": c, "material": {"k_a": 1.0}}],
            "pixel": [3, 2]
        }),
        &["coverage"],
    )
}

/// The converged reference finds what a pixel's covered sliver is, where
/// an adaptive rule over the whole square never sampled it: an edge a
/// millionth of the pixel inside its left side (area 1e-6), a corner
/// covering (6e-8)^2 = 3.6e-15 of it, an edge from the middle of its left
/// side at 0.001 degrees (area 1/2 + tan(0.001 deg) / 2). The areas are
/// written here from the film polygons; the closed form (clipping) agrees.
#[test]
fn the_converged_coverage_finds_slivers_the_whole_square_misses() {
    let far = 400.0;
    let theta = 0.001_f64.to_radians();
    let cases = [
        (
            "edge 1e-6 inside the left side",
            [[3.0 + 1e-6, -far], [3.0 + 1e-6, far], [-far, 2.5]],
            1e-6,
        ),
        (
            "corner of (6e-8)^2",
            [
                [3.0 + 6e-8, 2.0 + 6e-8],
                [3.0 + 6e-8 - far, 2.0 + 6e-8],
                [3.0 + 6e-8, 2.0 + 6e-8 - far],
            ],
            3.6e-15,
        ),
        (
            "edge at 0.001 degrees",
            [
                [3.0, 2.5],
                [3.0 + far, 2.5 + far * theta.tan()],
                [3.0, -far],
            ],
            0.5 + theta.tan() / 2.0,
        ),
    ];
    for (what, film, area) in cases {
        let exp = film_triangle(film);
        let closed = Whitted::closed_form(&exp.scene, Q::Coverage).expect("a closed form")[0];
        assert!(
            (closed / area - 1.0).abs() < 1e-6,
            "{what}: closed form {closed:e} against {area:e}"
        );
        let converged = Whitted::converged(&exp.scene, 400, &[Q::Coverage]).expect("converges");
        let got = converged[&Q::Coverage].value[0];
        assert!(
            (got / area - 1.0).abs() < 1e-6,
            "{what}: converged {got:e} against {area:e}"
        );
    }
}

/// Gauss–Legendre and Genz–Malik on a pixel whose covered part is a sliver
/// 1e-6 of its width: no node lands in it, so both read 0 +- 0, and the
/// value carries the flag that every node gave the same value (the clipped
/// area is 1e-6, not 0).
#[test]
fn zero_from_nodes_that_all_missed_a_sliver_is_flagged() {
    let far = 400.0;
    let exp = film_triangle([[3.0 + 1e-6, -far], [3.0 + 1e-6, far], [-far, 2.5]]);
    for rule in ["gauss-legendre", "genz-malik"] {
        let method: Method<Scheme> =
            serde_json::from_value(json!({ "rule": rule })).expect("method");
        let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
        let (m, _) =
            evaluate_counted(&exp.scene, &method, 65536, &mut rng, Q::Coverage).expect("evaluates");
        assert_eq!((m.value[0], m.error[0]), (0.0, 0.0), "{rule}");
        assert!(
            m.flags
                .iter()
                .any(|f| matches!(f, lightquad::family::Flag::AllNodesAlike { .. })),
            "{rule}: {:?}",
            m.flags
        );
    }
}

// ------------------------------------------------- (3) rays and orders

/// Through the family: W-Corner on the 8 x 6 image traces 9 x 7 primary
/// rays and nothing else (no lights, no mirrors, nothing transparent); the
/// image's RMS error against the closed form falls as the corner lattice is
/// refined, and the centre scheme traces one ray per pixel.
#[test]
fn the_family_counts_the_corner_schemes_rays_and_its_image_error_falls() {
    let exp = experiment(triangle_scene([3, 2]), &["image"]);
    let exact = Whitted::closed_form(&exp.scene, Q::Image).expect("closed form");
    assert_eq!(exact.len(), 3 * 8 * 6);
    let (_, rays) = by(&exp, json!({"rule": "corner"}), 1, Q::Image, 0);
    assert_eq!(rays, 9 * 7);
    let (_, rays) = by(&exp, json!({"rule": "centre"}), 1, Q::Image, 0);
    assert_eq!(rays, 48);
    let rms = |v: &[f64]| {
        (v.iter()
            .zip(&exact)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            / v.len() as f64)
            .sqrt()
    };
    let mut points = Vec::new();
    for budget in [1, 16, 256, 4096] {
        let (v, rays) = by(&exp, json!({"rule": "corner"}), budget, Q::Image, 0);
        let m = (budget as f64).sqrt() as u64;
        assert_eq!(rays, (8 * m + 1) * (6 * m + 1));
        points.push((rays as f64, rms(&v)));
    }
    let order = fitted_order(&points);
    println!("corner scheme on the triangle image: {points:?}, order {order:.3} in rays");
    assert!(points.windows(2).all(|w| w[1].1 < w[0].1), "{points:?}");
    assert!(order < -0.4, "{order}");
}

/// Jittered sampling through the renderer on the triangle's edge pixel:
/// RMS over 64 seeds against the closed form, fitted on a sweep: about
/// `N^-3/4`.
#[test]
fn jittered_sampling_of_a_rendered_edge_pixel_goes_as_n_to_the_minus_three_quarters() {
    // Pixels the triangle's edges cross.
    let edge_pixels: Vec<[usize; 2]> = (0..48)
        .map(|k| [k % 8, k / 8])
        .filter(|&p| {
            let exp = experiment(triangle_scene(p), &["coverage"]);
            let f = Whitted::closed_form(&exp.scene, Q::Coverage).expect("closed")[0];
            f > 0.05 && f < 0.95
        })
        .collect();
    assert!(edge_pixels.len() >= 6, "{edge_pixels:?}");
    let mut points = Vec::new();
    for m in [4usize, 8, 16, 32, 64] {
        let mut sum = 0.0;
        let mut count = 0.0;
        for (k, p) in edge_pixels.iter().enumerate() {
            let exp = experiment(triangle_scene(*p), &["coverage"]);
            let exact = Whitted::closed_form(&exp.scene, Q::Coverage).expect("closed")[0];
            for seed in 0..16 {
                let (v, _) = by(
                    &exp,
                    json!({"rule": "stratified"}),
                    m * m,
                    Q::Coverage,
                    seed * 100 + k as u64,
                );
                sum += (v[0] - exact).powi(2);
                count += 1.0;
            }
        }
        points.push(((m * m) as f64, (sum / count).sqrt()));
    }
    let order = fitted_order(&points);
    println!("rendered edge pixels, jittered: {points:?}, order {order:.3}");
    assert!((order + 0.75).abs() < 0.1, "{order}");
}

// ------------------------------------------------------------ (4) bad input

const GOOD: &str = r#"{
  "name": "b", "family": "whitted",
  "scene": {
    "camera": {"eye": [0.0, 0.0, 5.0], "look_at": [0.0, 0.0, 0.0], "up": [0.0, 1.0, 0.0],
               "fov_y": 40.0, "width": 4, "height": 3},
    "ambient": [0.1, 0.1, 0.1],
    "lights": [{"type": "point", "position": [3.0, 3.0, 3.0], "intensity": [1.0, 1.0, 1.0]}],
    "objects": [{"type": "sphere", "centre": [0.0, 0.0, 0.0], "radius": 1.0,
                 "material": {"k_a": 0.2, "k_d": 0.5, "k_s": 0.3, "phong": 10.0}}],
    "max_depth": 3,
    "pixel": [1, 1]
  },
  "quantities": ["pixel"],
  "rules": [{"rule": "grid"}], "budgets": [16], "repeats": 1,
  "reference": {"type": "converged"}
}"#;

/// `GOOD` with the JSON pointer `at` set to `value` (added to its parent
/// object when absent).
fn broken(at: &str, value: Value) -> String {
    let mut v: Value = serde_json::from_str(GOOD).expect("json");
    let (parent, key) = at.rsplit_once('/').expect("a pointer");
    match v.pointer_mut(parent).expect("a pointer into GOOD") {
        Value::Array(items) => items[key.parse::<usize>().expect("an index")] = value,
        Value::Object(fields) => {
            fields.insert(key.to_string(), value);
        }
        _ => panic!("{at} is not in GOOD"),
    }
    v.to_string()
}

fn checked(text: &str) -> std::process::Output {
    let dir = scratch("bad-w");
    let file = dir.join("e.json");
    fs::write(&file, text).expect("write");
    let o = bin().arg("check").arg(&file).output().expect("runs");
    let _ = fs::remove_dir_all(&dir);
    o
}

fn refused(text: &str, path: &str, what: &[&str]) {
    let o = checked(text);
    let msg = stderr(&o);
    assert!(!o.status.success(), "accepted: {text}");
    assert!(
        msg.contains(&format!("at `{path}`")),
        "no `{path}` in: {msg}"
    );
    for w in what {
        assert!(msg.contains(w), "no {w:?} in: {msg}");
    }
    assert!(!msg.contains("panicked"), "{msg}");
}

#[test]
fn the_good_file_is_accepted_and_an_energy_gain_is_a_warning_with_its_path() {
    let o = checked(GOOD);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));
    let hot = broken("/scene/objects/0/material/k_t", json!(0.5));
    let o = checked(&hot);
    assert!(o.status.success(), "{}", stderr(&o));
    let msg = stderr(&o);
    assert!(msg.contains("warning"), "{msg}");
    assert!(msg.contains("at `scene.objects[0].material`"), "{msg}");
    assert!(
        msg.contains("1.3 > 1") && msg.contains("not energy conserving"),
        "{msg}"
    );
}

/// A scene moved far from the origin keeps its shape in the JSON but not in
/// f64: an eye 5 from a unit sphere, both at x = 1e16 (where f64's spacing
/// is 2), rendered 0.4352 for the 0.4376 of the same scene at the origin.
/// `check` warns at the object's path; the same scene at x = 1e3 is quiet.
#[test]
fn a_scene_far_from_the_origin_is_a_warning_with_its_path() {
    let moved = |x: f64| {
        let mut v: Value = serde_json::from_str(GOOD).expect("json");
        for at in [
            "/scene/camera/eye",
            "/scene/camera/look_at",
            "/scene/lights/0/position",
            "/scene/objects/0/centre",
        ] {
            let p = v.pointer_mut(at).expect("a point");
            p[0] = json!(p[0].as_f64().expect("a number") + x);
        }
        v.to_string()
    };
    let o = checked(&moved(1e16));
    assert!(o.status.success(), "{}", stderr(&o));
    let msg = stderr(&o);
    assert!(
        msg.contains("warning") && msg.contains("at `scene.objects[0]`"),
        "{msg}"
    );
    assert!(msg.contains("1.0e-16 of the coordinates"), "{msg}");
    let o = checked(&moved(1e3));
    assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));
}

#[test]
fn bad_scenes_are_refused_with_the_path_and_what_is_accepted() {
    refused(
        &broken("/scene/camera/fov_y", json!(0.0)),
        "scene.camera.fov_y",
        &["[1e-4, 180)"],
    );
    refused(
        &broken("/scene/camera/fov_y", json!(180.0)),
        "scene.camera.fov_y",
        &["[1e-4, 180)"],
    );
    refused(
        &broken("/scene/camera/width", json!(0)),
        "scene.camera.width",
        &["1..=16384"],
    );
    refused(
        &broken("/scene/camera/height", json!(0)),
        "scene.camera.height",
        &["1..=16384"],
    );
    refused(
        &broken("/scene/camera/look_at", json!([0.0, 0.0, 5.0])),
        "scene.camera.look_at",
        &["the eye"],
    );
    refused(
        &broken("/scene/camera/up", json!([0.0, 0.0, 1.0])),
        "scene.camera.up",
        &["not parallel"],
    );
    refused(
        &broken("/scene/max_depth", json!(17)),
        "scene.max_depth",
        &["0..=16"],
    );
    refused(
        &broken("/scene/objects/0/radius", json!(0.0)),
        "scene.objects[0].radius",
        &["> 0"],
    );
    refused(
        &broken("/scene/objects/0/radius", json!(1e300)),
        "scene.objects[0].radius",
        &["1e100"],
    );
    refused(
        &broken("/scene/objects/0/material/k_d", json!(1.5)),
        "scene.objects[0].material.k_d",
        &["[0, 1]"],
    );
    refused(
        &broken("/scene/objects/0/material/ior", json!(0.0)),
        "scene.objects[0].material.ior",
        &["index of refraction"],
    );
    refused(
        &broken("/scene/lights/0/intensity", json!([1.0, -1.0, 0.0])),
        "scene.lights[0].intensity",
        &["in [0, 1e20]"],
    );
    refused(
        &broken("/scene/ambient", json!([1e200, 0.0, 0.0])),
        "scene.ambient[0]",
        &["1e100"],
    );
    refused(
        &broken("/scene/pixel", json!([4, 0])),
        "scene.pixel",
        &["outside the 4 x 3 image"],
    );
    refused(
        &broken("/scene/objects/0/type", json!("cube")),
        "scene.objects[0].type",
        &["sphere"],
    );
    refused(
        &broken("/rules/0", json!({"rule": "adaptive", "threshold": -1.0})),
        "rules[0].threshold",
        &["-1", "finite spread >= 0"],
    );
    // The one-pixel quantities need scene.pixel.
    let mut v: Value = serde_json::from_str(GOOD).expect("json");
    v["scene"].as_object_mut().expect("scene").remove("pixel");
    refused(&v.to_string(), "quantities[0]", &["scene.pixel"]);
}

/// Extreme numbers in every leaf of the bundled files and of GOOD never
/// panic the validation, and a valid one evaluates without panicking.
#[test]
fn extreme_numbers_anywhere_are_errors_not_panics() {
    let registry = lightquad::families::builtin();
    let mut specs: Vec<Value> = bundled("w-").into_iter().map(|(_, v)| v).collect();
    specs.push(serde_json::from_str(GOOD).expect("json"));
    for spec in specs {
        let mut leaves = Vec::new();
        fn walk(v: &Value, at: String, out: &mut Vec<String>) {
            match v {
                Value::Object(m) => m
                    .iter()
                    .for_each(|(k, c)| walk(c, format!("{at}/{k}"), out)),
                Value::Array(a) => a
                    .iter()
                    .enumerate()
                    .for_each(|(i, c)| walk(c, format!("{at}/{i}"), out)),
                Value::Number(_) => out.push(at),
                _ => {}
            }
        }
        walk(&spec["scene"], "/scene".into(), &mut leaves);
        for leaf in &leaves {
            for x in [0.0, -1.0, 1e308, -1e308, 1e-308, 1e-300] {
                let mut v = spec.clone();
                *v.pointer_mut(leaf).expect("leaf") = json!(x);
                match registry.load(v.clone(), "h") {
                    Ok(_) => {
                        // Render one centre ray per pixel of what was accepted.
                        if let Ok(exp) = validate::<Whitted>(deserialize(v).expect("parses"), "h") {
                            let method: Method<Scheme> = Method::Estimator(Scheme::Centre);
                            let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
                            let q = exp.spec.quantities[0];
                            let _ = Whitted::evaluate(&exp.scene, &method, 1, &mut rng, &[q]);
                        }
                    }
                    Err(e) => assert!(!e.path.is_empty() && e.message.len() > 5, "{e}"),
                }
            }
        }
    }
}

/// `lightquad render` refuses what it cannot do rather than hanging or
/// writing undefined pixels, and says the warnings `check` says:
/// `--samples` of `u64::MAX` overflowed the ray count to
/// 0 and ran forever; a mirror sphere of radius 1e30 around the camera
/// wrote 183 NaN pixels of 4800 (black in the PNG) with exit 0; an energy
/// gain was warned of by `check` but not by `render`.
#[test]
fn a_sphere_below_what_f64_resolves_is_warned_and_its_undefined_ray_named() {
    // A sphere of radius 1e-20 seen from 1.8e19: size over distance
    // 1e-20 / 1.8e19 = 5.6e-40, far below the 1e-16 rounding of a ray.
    let dir = scratch("tiny-far");
    let file = dir.join("tiny.json");
    let spec = json!({"name": "tiny", "family": "whitted",
        "scene": {"camera": {"eye": [0, 0, 1.8e19], "look_at": [0, 0, 0], "up": [0, 1, 0],
            "fov_y": 20.0, "width": 8, "height": 8},
          "ambient": [0.2, 0.2, 0.2], "background": [0.1, 0.2, 0.4],
          "lights": [{"type": "point", "position": [2, 3, 5], "intensity": [1, 1, 1]}],
          "objects": [{"type": "sphere", "centre": [0, 0, 0], "radius": 1e-20,
            "material": {"k_a": 0.3, "k_d": 0.5, "k_s": 0.0, "phong": 20.0,
              "colour": [0.9, 0.3, 0.2]}}],
          "max_depth": 0, "pixel": [4, 3]},
        "quantities": ["pixel"], "rules": [{"rule": "trapezoid"}], "budgets": [16],
        "repeats": 1, "reference": {"type": "converged"}});
    fs::write(&file, spec.to_string()).expect("write");
    let check = bin().arg("check").arg(&file).output().expect("runs");
    assert!(check.status.success(), "{}", stderr(&check));
    for want in ["at `scene.objects[0]`", "5.6e-40 of its distance", "1e-12"] {
        assert!(
            stderr(&check).contains(want),
            "no `{want}` in {}",
            stderr(&check)
        );
    }
    // The trapezoid rule's corner [0, 1] of pixel (4, 3) is the image's
    // centre, whose ray passes exactly through the sphere's centre: its hit
    // point and normal are rounding (0/0), and the job fails naming the
    // scene, not the integrand.
    let run = bin()
        .args(["run", "--out"])
        .arg(dir.join("out"))
        .arg(&file)
        .output()
        .expect("runs");
    assert!(!run.status.success(), "{}", stderr(&run));
    let results = fs::read_to_string(dir.join("out/tiny/results.jsonl")).expect("results");
    for want in [
        "invalid scene",
        "not a number",
        "pixel [4, 3] at [0.0, 1.0] of its square",
        "within about 1e12",
    ] {
        assert!(results.contains(want), "no `{want}` in {results}");
    }
    assert!(!results.contains("integrand returned"), "{results}");
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn a_scene_whose_squares_underflow_is_warned_and_every_scheme_names_the_pixel() {
    // A sphere of radius 1e-170 seen from 5e-170: r^2 = 1e-340 is below the
    // smallest normal f64 (2.2e-308), so its hits are undefined.
    let dir = scratch("underflow");
    let file = dir.join("u.json");
    let spec = json!({"name": "u", "family": "whitted",
        "scene": {"camera": {"eye": [0, 0, 5e-170], "look_at": [0, 0, 0], "up": [0, 1, 0],
            "fov_y": 20.0, "width": 8, "height": 8},
          "ambient": [0.2, 0.2, 0.2], "background": [0.1, 0.2, 0.4],
          "lights": [{"type": "point", "position": [2e-170, 3e-170, 5e-170],
            "intensity": [1, 1, 1]}],
          "objects": [{"type": "sphere", "centre": [0, 0, 0], "radius": 1e-170,
            "material": {"k_a": 0.3, "k_d": 0.5, "k_s": 0.4, "phong": 20.0,
              "colour": [0.9, 0.3, 0.2]}}],
          "max_depth": 2, "pixel": [4, 3]},
        "quantities": ["pixel"], "rules": [{"rule": "centre"}, {"rule": "gauss-legendre"}],
        "budgets": [4], "repeats": 1, "reference": {"type": "converged"}});
    fs::write(&file, spec.to_string()).expect("write");
    let check = bin().arg("check").arg(&file).output().expect("runs");
    assert!(check.status.success(), "{}", stderr(&check));
    assert!(
        stderr(&check).contains("its size is 1.0e-170, below 1e-150"),
        "{}",
        stderr(&check)
    );
    let run = bin()
        .args(["run", "--out"])
        .arg(dir.join("out"))
        .arg(&file)
        .output()
        .expect("runs");
    assert!(!run.status.success(), "{}", stderr(&run));
    let results = fs::read_to_string(dir.join("out/u/results.jsonl")).expect("results");
    // Whitted's own scheme and a rule of the core alike name the pixel.
    assert!(
        results.contains("pixel [4, 3] came out not a number"),
        "{results}"
    );
    assert!(results.contains("through pixel [4, 3] at"), "{results}");
    assert!(!results.contains("non-finite pixel"), "{results}");
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn a_background_on_a_display_step_boundary_is_in_doubt() {
    // A pixel of background (0.1, 0.2, 0.4) only: 255 x 0.1 = 25.5 lies on
    // W-Grey's rounding boundary between 25 and 26, while 51 and 102 lie a
    // half step from one. Every ray sees the same value, so the converged
    // reference changes by 0; rounding of a rule's weights still moves 0.1
    // across the boundary, and the report must count that value in doubt.
    let dir = scratch("boundary");
    let file = dir.join("b.json");
    let spec = json!({"name": "b", "family": "whitted",
        "scene": {"camera": {"eye": [0, 0, 5], "look_at": [0, 0, 0], "up": [0, 1, 0],
            "fov_y": 20.0, "width": 8, "height": 8},
          "ambient": [0.2, 0.2, 0.2], "background": [0.1, 0.2, 0.4], "lights": [],
          "objects": [{"type": "sphere", "centre": [0, 0, -100], "radius": 1.0,
            "material": {"k_a": 0.3, "k_d": 0.5, "k_s": 0.0, "phong": 20.0,
              "colour": [0.9, 0.3, 0.2]}}],
          "max_depth": 0, "pixel": [0, 0]},
        "quantities": ["pixel"], "rules": [{"rule": "gauss-legendre"}], "budgets": [16, 64],
        "repeats": 1, "reference": {"type": "converged"}});
    fs::write(&file, spec.to_string()).expect("write");
    let run = bin()
        .args(["run", "--out"])
        .arg(dir.join("out"))
        .arg(&file)
        .output()
        .expect("runs");
    assert!(run.status.success(), "{}", stderr(&run));
    let report = fs::read_to_string(dir.join("out/b/report.md")).expect("report");
    assert!(
        report.contains("leaves 1 of the reference's own displayed values in doubt"),
        "{report}"
    );
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn render_refuses_endless_and_undefined_images_and_warns() {
    let dir = scratch("render-refuses");
    let png = dir.join("r.png");
    let endless = bin()
        .args(["render", "--width", "1", "--height", "1", "--samples"])
        .arg(u64::MAX.to_string())
        .arg("--png")
        .arg(&png)
        .output()
        .expect("runs");
    assert!(!endless.status.success() && !png.exists());
    assert!(
        stderr(&endless).contains("1.845e19 primary rays: expected at most 1e9"),
        "{}",
        stderr(&endless)
    );

    let mut scene: Value = serde_json::from_str(
        &fs::read_to_string(root().join("experiments/w-grey-test-scene.json")).expect("read"),
    )
    .expect("json");
    scene["scene"]["objects"][1]["radius"] = json!(1e30);
    let huge = dir.join("huge.json");
    fs::write(&huge, scene.to_string()).expect("write");
    let undefined = bin()
        .args([
            "render",
            "--width",
            "80",
            "--height",
            "60",
            "--samples",
            "16",
            "--png",
        ])
        .arg(&png)
        .arg(&huge)
        .output()
        .expect("runs");
    assert!(!undefined.status.success() && !png.exists());
    assert!(
        stderr(&undefined).contains("pixels came out undefined"),
        "{}",
        stderr(&undefined)
    );

    scene["scene"]["objects"][1]["radius"] = json!(0.8);
    scene["scene"]["objects"][1]["material"]["k_d"] = json!(0.9);
    scene["scene"]["objects"][1]["material"]["k_s"] = json!(0.6);
    let gain = dir.join("gain.json");
    fs::write(&gain, scene.to_string()).expect("write");
    let warned = bin()
        .args(["render", "--width", "4", "--height", "3", "--png"])
        .arg(&png)
        .arg(&gain)
        .output()
        .expect("runs");
    assert!(
        warned.status.success() && png.exists(),
        "{}",
        stderr(&warned)
    );
    assert!(
        stderr(&warned).contains("warning:")
            && stderr(&warned).contains("scene.objects[1].material"),
        "{}",
        stderr(&warned)
    );
    let _ = fs::remove_dir_all(&dir);
}

/// A render whose PFM cannot be written leaves a PNG that was there as it
/// was: it was removed with "(the PNG was removed)". A device as the PFM
/// (`/dev/full`) is refused before rendering, as a FIFO is (one blocked the
/// render forever).
#[test]
#[cfg(target_os = "linux")]
fn a_render_that_fails_leaves_an_existing_png_as_it_was() {
    let dir = scratch("keep-png");
    let png = dir.join("keep.png");
    fs::write(&png, "precious").expect("write");
    let o = bin()
        .args([
            "render",
            "--width",
            "4",
            "--height",
            "4",
            "--pfm",
            "/dev/full",
            "--png",
        ])
        .arg(&png)
        .output()
        .expect("runs");
    assert!(!o.status.success(), "wrote to /dev/full");
    assert!(
        stderr(&o).contains("--pfm = /dev/full") && stderr(&o).contains("is a device"),
        "{}",
        stderr(&o)
    );
    assert_eq!(fs::read_to_string(&png).expect("kept"), "precious");
    let _ = fs::remove_dir_all(&dir);
}

/// The hostile probe of session 27: an intensity 32-bit images cannot hold
/// (1e100 wrote infinities into the PFM) is refused at its path; a sphere of
/// radius 1e100 around the eye (the job failed with "NaN" in the report) is
/// a warning at its path; a triangle whose `b` is `a` blames `b`; a
/// parallel `up` is echoed as given, not normalised.
#[test]
fn what_images_cannot_hold_and_what_f64_cannot_resolve_are_named_at_their_paths() {
    refused(
        &broken("/scene/lights/0/intensity", json!([1e21, 1.0, 1.0])),
        "scene.lights[0].intensity",
        &["[0, 1e20]", "32-bit"],
    );
    refused(
        &broken("/scene/ambient", json!([0.1, 1e100, 0.1])),
        "scene.ambient",
        &["[0, 1e20]"],
    );
    // The eye is 5 from look_at: 1e100 is 2e99 times that, beyond 1e12.
    let o = checked(&broken("/scene/objects/0/radius", json!(1e100)));
    assert!(o.status.success(), "{}", stderr(&o));
    let msg = stderr(&o);
    assert!(
        msg.contains("warning") && msg.contains("at `scene.objects[0]`") && msg.contains("2.0e99"),
        "{msg}"
    );
    // A sphere of radius 1e12 around a scene 5 across is quiet (2e11).
    let o = checked(&broken("/scene/objects/0/radius", json!(1e12)));
    assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));

    let triangle = |a: [f64; 3], b: [f64; 3], c: [f64; 3]| {
        broken(
            "/scene/objects/0",
            json!({"type": "triangle", "a": a, "b": b, "c": c, "material": {"k_a": 1.0}}),
        )
    };
    refused(
        &triangle([0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0]),
        "scene.objects[0].b",
        &["other than a"],
    );
    refused(
        &triangle([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]),
        "scene.objects[0].c",
        &["off the line through a and b"],
    );
    refused(
        &broken("/scene/camera/up", json!([0.0, 0.0, -6.0])),
        "scene.camera.up",
        &["[0.0, 0.0, -6.0]", "not parallel"],
    );
}
