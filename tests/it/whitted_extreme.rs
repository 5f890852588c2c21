//! The Whitted family and `lightquad render` on extreme geometry and hostile
//! inputs: closed forms against values derived by hand in the test, and
//! refusals that name the JSON path or the flag.

use crate::common::{bin, root, scratch, stderr};
use lightquad::family::Family;
use lightquad::whitted::experiment::{SceneSpec, Whitted, WhittedQuantity};
use serde_json::{Value as Json, json};

/// The bundled experiment `name` (without `.json`), parsed.
fn bundled(name: &str) -> Json {
    let path = root().join("experiments").join(format!("{name}.json"));
    serde_json::from_str(&std::fs::read_to_string(&path).expect("read")).expect("json")
}

/// The closed form of `q` for the scene of `experiment`.
fn closed_form(experiment: &Json, q: WhittedQuantity) -> Vec<f64> {
    let spec: SceneSpec = serde_json::from_value(experiment["scene"].clone()).expect("scene");
    let built = Whitted::build(&spec).expect("built");
    Whitted::closed_form(&built, q).expect("a closed form")
}

/// An eye 1e20 above a triangle of size 3 sees it 3e-20 radians across,
/// within about 3e-20 radians of the viewing direction: on the 8 x 6 film
/// (50 degrees high, 6 pixels: 1 radian is about 6.4 pixels) its image lies
/// within 1e-18 pixels of the film's centre, the corner (4, 3) of pixel
/// [3, 2], and covers at most (1e-18)^2 of it. The closed form said 1.0
/// (all three vertices rounded onto one film point, a polygon of no area
/// whose edges bounded nothing).
#[test]
fn distant_eye_sees_a_dot() {
    let mut e = bundled("w-ss-edge-coverage");
    e["scene"]["camera"]["eye"] = json!([0.0, 1e20, 0.0]);
    let coverage = closed_form(&e, WhittedQuantity::Coverage)[0];
    assert!((0.0..1e-30).contains(&coverage), "coverage {coverage}");
}

/// Film coordinates near the 6-pixel image are rounded to about 6 x 2.2e-16
/// = 1.3e-15 pixels: the triangle 1e10 from the eye (its size over its
/// distance 2.8e-10) has an image 2.8e-10 x 6.4 pixels a radian = 1.8e-9
/// pixels across, and its closed-form
/// coverage is exact only to about 1.3e-15 / 1.8e-9 = 7e-7 relative (an
/// independent 120-digit projection put its error at 6.9e-6): `check`
/// warns at the object with that bound, and not at the bundled eye.
#[test]
fn a_closed_form_below_the_films_rounding_is_warned() {
    let mut e = bundled("w-ss-edge-coverage");
    let check = |e: &Json| {
        let dir = scratch("film");
        let file = dir.join("e.json");
        std::fs::write(&file, e.to_string()).expect("write");
        let o = bin().arg("check").arg(&file).output().expect("runs");
        assert!(o.status.success(), "{}", stderr(&o));
        stderr(&o)
    };
    assert!(!check(&e).contains("film coordinates"), "{}", check(&e));
    e["scene"]["camera"]["eye"] = json!([0.0, 1e10, 0.0]);
    let msg = check(&e);
    assert!(
        msg.contains("at `scene.objects[0]`") && msg.contains("exact only to about 1e-6 relative"),
        "{msg}"
    );
}

/// A vertex 1e20 up, 2.2 in front of the eye: the triangle's image is, to
/// 1e-19, the part of the film beyond the image of edge a-b between the
/// lines through the images of a and b toward the vanishing point of +y,
/// film direction (y . right, -y . up) = (-0.1, -1) (right = (1, -0.1, 0) /
/// sqrt 1.01, up = (0.1, 1, 0) / sqrt 1.01 for forward -z and the given
/// up). Each pixel's covered fraction by 200 x 200 points against those
/// three lines, by hand, is within 1e-2 of the closed form (the closed form
/// gave an image of RMS 2.6e-2 where this one has 0.41).
#[test]
fn distant_vertex_bounds_a_strip() {
    let mut e = bundled("w-corner-image");
    e["scene"]["objects"][0]["c"] = json!([-0.2, 1e20, -2.2]);
    let image = closed_form(&e, WhittedQuantity::Image);
    let (w, h) = (16usize, 12usize);
    let tan = (25f64).to_radians().tan();
    let s = 1.01f64.sqrt();
    // Film point of p (eye at the origin, looking down -z).
    let film = |p: [f64; 3]| -> [f64; 2] {
        let (r, u, z) = ((p[0] - 0.1 * p[1]) / s, (0.1 * p[0] + p[1]) / s, -p[2]);
        let (sx, sy) = (r / z, u / z);
        let (wf, hf) = (w as f64, h as f64);
        [
            (sx / (tan * wf / hf) + 1.0) * wf / 2.0,
            (1.0 - sy / tan) * hf / 2.0,
        ]
    };
    let (a, b) = (film([-2.0, -1.5, -2.0]), film([0.37, -1.5, -2.5]));
    let dir = [-0.1, -1.0];
    let cross = |o: [f64; 2], d: [f64; 2], p: [f64; 2]| d[0] * (p[1] - o[1]) - d[1] * (p[0] - o[0]);
    // Inside: on the far side of a-b (toward dir), and between the lines
    // through a and b along dir (on b's side of a's, a's side of b's).
    let ab = [b[0] - a[0], b[1] - a[1]];
    let beyond = |p: [f64; 2]| cross(a, ab, p) * cross(a, ab, [a[0] + dir[0], a[1] + dir[1]]) > 0.0;
    let between = |p: [f64; 2]| {
        cross(a, dir, p) * cross(a, dir, b) > 0.0 && cross(b, dir, p) * cross(b, dir, a) > 0.0
    };
    let k = 200;
    let mut worst: f64 = 0.0;
    let mut sum_sq = 0.0;
    for j in 0..h {
        for i in 0..w {
            let mut inside = 0;
            for sj in 0..k {
                for si in 0..k {
                    let p = [
                        i as f64 + (si as f64 + 0.5) / k as f64,
                        j as f64 + (sj as f64 + 0.5) / k as f64,
                    ];
                    inside += usize::from(beyond(p) && between(p));
                }
            }
            let by_hand = inside as f64 / (k * k) as f64;
            // Red is k_a C_r = 0.8 times the coverage (black background).
            let closed = image[3 * (j * w + i)] / 0.8;
            worst = worst.max((closed - by_hand).abs());
            sum_sq += by_hand * by_hand;
        }
    }
    assert!(sum_sq > 10.0, "the strip covers some pixels ({sum_sq})");
    assert!(
        worst < 1e-2,
        "a pixel's coverage is {worst} off the strip's"
    );
}

/// `render --png` or `--pfm` naming a FIFO blocked forever (the image was
/// written in place into a pipe no one reads): refused at once with the
/// flag and what the path is, and nothing written.
#[test]
fn render_refuses_a_fifo_as_output() {
    let dir = scratch("render-fifo");
    let fifo = dir.join("pipe");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .expect("mkfifo runs");
    assert!(made.success(), "mkfifo failed");
    for (flag, other) in [("--png", "--pfm"), ("--pfm", "--png")] {
        let mut child = bin()
            .args(["render", "--width", "8", "--height", "6", flag])
            .arg(&fifo)
            .arg(other)
            .arg(dir.join("other.img"))
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("spawns");
        // Ten seconds for a refusal that takes milliseconds; a render
        // blocked on the pipe is killed and fails the test.
        let start = std::time::Instant::now();
        while child.try_wait().expect("waits").is_none() {
            if start.elapsed().as_secs() > 10 {
                let _ = child.kill();
                let _ = child.wait();
                panic!("render {flag} <FIFO> still running after 10 s");
            }
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        let o = child.wait_with_output().expect("output");
        let msg = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{msg}");
        for want in [flag, "FIFO"] {
            assert!(msg.contains(want), "no `{want}` in {msg}");
        }
        assert!(
            !dir.join("other.img").exists(),
            "the other file was written"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `render` under `ulimit -v` 300 000 KiB (as `prlimit --as` sets it).
fn render_capped(dir: &std::path::Path, side: usize) -> std::process::Output {
    std::process::Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v 300000 && exec \"$0\" render --png \"$1\" --width {side} --height {side} \
             --samples 1"
        ))
        .arg(env!("CARGO_BIN_EXE_lightquad"))
        .arg(dir.join("out.png"))
        .output()
        .expect("runs")
}

/// Under a 307 MB address-space cap a 2048 x 2048 render aborted (exit 134,
/// "memory allocation of 100663296 bytes failed"): its 4.2e6 pixels alone
/// hold 4.2e6 x 64 = 268 MB (values, errors, image, file bytes), beside two
/// 64 MiB allocator arenas. It is refused with the cap and the flags named,
/// exit 1, nothing written; a 64 x 64 render (0.26 MB) runs under the same
/// cap.
#[test]
fn render_past_a_memory_cap_is_refused_not_aborted() {
    let dir = scratch("render-cap");
    let o = render_capped(&dir, 2048);
    let msg = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{msg}");
    for want in ["--width", "268.4 MB", "address-space limit"] {
        assert!(msg.contains(want), "no `{want}` in {msg}");
    }
    assert!(!dir.join("out.png").exists(), "a PNG was written");
    let o = render_capped(&dir, 64);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(dir.join("out.png").is_file());
    let _ = std::fs::remove_dir_all(&dir);
}

/// A render of more than 8192 x 8192 = 67 108 864 pixels (4 GiB at 64
/// bytes a pixel) is refused by its flags before anything is traced.
#[test]
fn render_refuses_absurd_sizes_by_flag() {
    let dir = scratch("render-size");
    let o = bin()
        .args(["render", "--width", "16384", "--height", "8193", "--png"])
        .arg(dir.join("out.png"))
        .output()
        .expect("runs");
    let msg = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{msg}");
    for want in ["--width x --height", "16384 x 8193 pixels", "67108864"] {
        assert!(msg.contains(want), "no `{want}` in {msg}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Ten mirror-and-glass spheres (`k_s`, `k_t` > 0) at depth 16, two lights,
/// the pixel looking past them: each primary ray may have 2^17 - 1 =
/// 131071 rays below it, each with 2 shadow rays, each tested against 10
/// objects, and the converged pixel spends 100 n = 40 000 primary rays at n
/// = 400: 40 000 x 131071 x 3 x 10 = 1.57e11 ray-object tests, past the
/// 1e11 a job may cost. Refused at once with `reference.n`, the estimate
/// and `scene.max_depth` named (it ran; four such spheres the pixel sees
/// ran for more than 300 s).
#[test]
fn a_bushy_ray_tree_bounds_the_converged_reference() {
    let mut e = bundled("w-6-1-phong-pixel");
    let glass = json!({"k_a": 0.1, "k_s": 0.5, "k_t": 0.5, "ior": 1.5});
    let spheres: Vec<Json> = (0..10)
        .map(|k| json!({"type": "sphere", "centre": [k as f64, 40.0, -3.0], "radius": 0.4, "material": glass}))
        .collect();
    e["scene"]["objects"] = Json::Array(spheres);
    e["scene"]["max_depth"] = json!(16);
    let spec: SceneSpec = serde_json::from_value(e["scene"].clone()).expect("scene");
    let built = Whitted::build(&spec).expect("built");
    let start = std::time::Instant::now();
    let got = Whitted::converged(&built, 400, &[WhittedQuantity::Pixel]);
    let msg = match got {
        Err(err) => err.to_string(),
        Ok(_) => panic!(
            "the converged pixel ran ({:.1} s) past an estimate of 1.57e11 ray-object tests",
            start.elapsed().as_secs_f64()
        ),
    };
    for want in ["reference.n", "1.6e11", "scene.max_depth", "131071"] {
        assert!(msg.contains(want), "no `{want}` in {msg}");
    }
    // At n = 200 the estimate is 7.9e10: allowed, and it runs (the pixel
    // sees only the background, so few rays are traced).
    let half = Whitted::converged(&built, 200, &[WhittedQuantity::Pixel]).expect("runs");
    let background = [0.1, 0.2, 0.4];
    for (c, v) in half[&WhittedQuantity::Pixel].value.iter().enumerate() {
        assert!((v - background[c]).abs() < 1e-12, "{v}");
    }
    // `check` prices the reference's first two evaluations, at n and 2n: at
    // n = 200 they cost 7.9e10 + 1.57e11, refused at `reference.n`; at n =
    // 50, 2.0e10 + 3.9e10 pass, with a warning at `scene.max_depth` naming
    // the tree's size.
    let dir = scratch("bushy");
    let file = dir.join("e.json");
    let mut check = |n: usize| {
        e["reference"] = json!({"type": "converged", "n": n});
        std::fs::write(&file, e.to_string()).expect("write");
        bin().arg("check").arg(&file).output().expect("runs")
    };
    let o = check(200);
    let msg = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{msg}");
    assert!(msg.contains("at `reference.n`"), "{msg}");
    let o = check(50);
    let msg = stderr(&o);
    assert!(o.status.success(), "{msg}");
    assert!(
        msg.contains("at `scene.max_depth`") && msg.contains("131071"),
        "{msg}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A run of a 1024 x 1024 image under a 300 000 KiB address-space cap: its
/// result line holds 3 x 1024^2 channels of value and error, about 128
/// bytes each while written (3.1e6 x 128 = 403 MB), and the run aborted
/// allocating it (exit 134, in serde_json's writer). It is refused before
/// any job with the cap named, exit 1.
#[test]
fn an_image_run_past_a_memory_cap_is_refused_not_aborted() {
    let dir = scratch("image-cap");
    let file = dir.join("wbig.json");
    let e = json!({"name": "wbig", "family": "whitted",
        "scene": {"camera": {"eye": [0, 0, 0], "look_at": [0, 0, -1], "up": [0, 1, 0],
                             "fov_y": 50.0, "width": 1024, "height": 1024},
                  "ambient": [1, 1, 1],
                  "objects": [{"type": "sphere", "centre": [0, 0, -3], "radius": 1.0,
                               "material": {"k_a": 0.5, "k_s": 0.5}}],
                  "lights": [{"type": "point", "position": [0, 5, 0], "intensity": [1, 1, 1]}]},
        "quantities": ["image"], "rules": [{"rule": "grid"}], "budgets": [1, 4], "repeats": 1,
        "reference": {"type": "converged"}});
    std::fs::write(&file, e.to_string()).expect("write");
    let o = std::process::Command::new("sh")
        .arg("-c")
        .arg("ulimit -v 300000 && exec \"$0\" run \"$1\" --out \"$2\"")
        .arg(env!("CARGO_BIN_EXE_lightquad"))
        .arg(&file)
        .arg(dir.join("out"))
        .output()
        .expect("runs");
    let msg = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{msg}");
    assert!(msg.contains("address-space limit"), "{msg}");
    let _ = std::fs::remove_dir_all(&dir);
}
