//! The Whitted family and `lightquad render` on extreme geometry and hostile
//! inputs: closed forms against values derived by hand in the test, and
//! refusals that name the JSON path or the flag.

use crate::common::root;
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
