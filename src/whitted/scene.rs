//! A scene of Whitted's model: objects (spheres, planes, triangles) with
//! materials, point and directional lights, an ambient intensity, a
//! background and a pinhole camera.
//!
//! A material holds the coefficients of W-6.1 and W-Phong: `k_a` (ambient),
//! `k_d` (diffuse), `k_s` (specular: the Phong highlight and the mirror
//! ray), `k_t` (transmission), the Phong exponent `n`, the index of
//! refraction (used where `k_t > 0`), and an RGB `colour` that scales the
//! ambient and diffuse terms (W-Grey: colour images apply W-6.1 per R, G,
//! B). Whitted's lights have no fall-off: a light's intensity `I_q` reaches
//! every point it sees unchanged (W-6.1 has no distance term).
//!
//! ```
//! use lightquad::domain::Vec3;
//! use lightquad::whitted::scene::{Camera, Material};
//!
//! // A 4 x 3 image with a 90 degree vertical field of view, looking down -z:
//! // the ray through the image's centre is the viewing direction.
//! let cam = Camera::new(Vec3::zeros(), -Vec3::z(), Vec3::y(), 90.0, 4, 3)?;
//! let ray = cam.ray([2.0, 1.5]);
//! assert!((ray.direction - (-Vec3::z())).norm() < 1e-15);
//! // The top edge of the image is 45 degrees up.
//! let top = cam.ray([2.0, 0.0]).direction;
//! assert!((top.y - top.z.abs()).abs() < 1e-15);
//! // k_d + k_s + k_t above 1 is not energy conserving: built, with a warning.
//! let m = Material { k_d: 0.7, k_s: 0.5, ..Material::default() };
//! assert!(m.energy_warning().is_some());
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use crate::domain::Vec3;
use crate::error::{QuadError, require_finite};
use crate::geometry::{normalize, require_finite_vec};
use crate::value::Rgb;

use super::coverage::HalfPlane;
use super::intersect::{Hit, Ray, Shape};

/// The deepest recursion of reflected and transmitted rays a scene may ask
/// for: a binary tree of depth 16 already holds 131071 rays per primary ray.
pub const MAX_DEPTH: usize = 16;

/// The coefficients of W-6.1 and W-Phong for one object.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// `k_a`, ambient, in `[0, 1]`.
    pub k_a: f64,
    /// `k_d`, Lambert diffuse, in `[0, 1]`.
    pub k_d: f64,
    /// `k_s`, specular (Phong highlight and mirror ray), in `[0, 1]`.
    pub k_s: f64,
    /// `k_t`, transmission, in `[0, 1]`.
    pub k_t: f64,
    /// The Phong exponent `n >= 0`; `n = 0` is a constant lobe, the
    /// highlight `k_s I_j` from every unshadowed light above the horizon,
    /// wherever the viewer is (`max(0, R . V)^0 = 1`, as IEEE's `0^0`).
    pub phong: f64,
    /// The index of refraction inside the object, `> 0`.
    pub ior: f64,
    /// The RGB colour of the ambient and diffuse terms, each in `[0, 1]`.
    pub colour: Rgb,
}

impl Default for Material {
    /// A white diffuse surface: `k_a = 0.1`, `k_d = 0.9`, no specular or
    /// transmitted part, `n = 1`, index 1.
    fn default() -> Self {
        Material {
            k_a: 0.1,
            k_d: 0.9,
            k_s: 0.0,
            k_t: 0.0,
            phong: 1.0,
            ior: 1.0,
            colour: Rgb::new(1.0, 1.0, 1.0),
        }
    }
}

impl Material {
    /// Checks every coefficient; the error names it.
    pub fn check(&self) -> Result<(), QuadError> {
        for (name, k) in [
            ("k_a", self.k_a),
            ("k_d", self.k_d),
            ("k_s", self.k_s),
            ("k_t", self.k_t),
        ] {
            if !(k.is_finite() && (0.0..=1.0).contains(&k)) {
                return Err(QuadError::invalid(name, k, "a number in [0, 1]"));
            }
        }
        if !(self.phong.is_finite() && (0.0..=1e8).contains(&self.phong)) {
            return Err(QuadError::invalid(
                "phong",
                self.phong,
                "a Phong exponent in [0, 1e8]",
            ));
        }
        if !(self.ior.is_finite() && (1e-3..=1e3).contains(&self.ior)) {
            return Err(QuadError::invalid(
                "ior",
                self.ior,
                "an index of refraction in [0.001, 1000]",
            ));
        }
        for c in 0..3 {
            let v = self.colour[c];
            if !(v.is_finite() && (0.0..=1.0).contains(&v)) {
                return Err(QuadError::invalid(
                    "colour",
                    format!("{:?}", self.colour.as_slice()),
                    "three numbers in [0, 1]",
                ));
            }
        }
        Ok(())
    }

    /// A warning when `k_d + k_s + k_t > 1`: the surface can send back more
    /// than it receives (not energy conserving). Allowed, as the document
    /// does not forbid it.
    pub fn energy_warning(&self) -> Option<String> {
        let sum = self.k_d + self.k_s + self.k_t;
        (sum > 1.0).then(|| {
            format!(
                "k_d + k_s + k_t = {} + {} + {} = {sum} > 1: not energy conserving (the surface \
                 can reflect and transmit more than it receives); expected a sum <= 1",
                self.k_d, self.k_s, self.k_t
            )
        })
    }
}

/// A light of W-6.1: `I_q` per R, G, B, from a point or a direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Light {
    /// A point light at `position`.
    Point {
        /// Where it is.
        position: Vec3,
        /// `I_q`.
        intensity: Rgb,
    },
    /// A light at infinity in direction `toward_light` (unit) from every point.
    Directional {
        /// Unit direction from the scene toward the light.
        toward_light: Vec3,
        /// `I_q`.
        intensity: Rgb,
    },
}

/// The largest intensity of a light, the ambient light or the background.
/// Images are written as 32-bit floats (PFM, at most 3.4e38); a pixel gains
/// at most a few times the intensities per bounce (each `k <= 1`, their sum
/// at most 3), so below 1e20 every pixel of a scene with fewer than 1e10
/// lights stays finite there, up to the deepest recursion.
pub const MAX_INTENSITY: f64 = 1e20;

fn require_rgb(name: &str, v: Rgb) -> Result<Rgb, QuadError> {
    if v.iter()
        .all(|c| c.is_finite() && (0.0..=MAX_INTENSITY).contains(c))
    {
        Ok(v)
    } else {
        Err(QuadError::invalid(
            name,
            format!("{:?}", v.as_slice()),
            format!(
                "three finite numbers in [0, {MAX_INTENSITY:.0e}] (images are written as \
                 32-bit floats)"
            ),
        ))
    }
}

impl Light {
    /// A point light (finite position, intensities finite and `>= 0`).
    pub fn point(position: Vec3, intensity: Rgb) -> Result<Self, QuadError> {
        Ok(Light::Point {
            position: require_finite_vec("position", position)?,
            intensity: require_rgb("intensity", intensity)?,
        })
    }

    /// A directional light (`toward_light` normalised).
    pub fn directional(toward_light: Vec3, intensity: Rgb) -> Result<Self, QuadError> {
        Ok(Light::Directional {
            toward_light: normalize("toward_light", toward_light)?,
            intensity: require_rgb("intensity", intensity)?,
        })
    }

    /// `I_q`.
    pub fn intensity(&self) -> Rgb {
        match self {
            Light::Point { intensity, .. } | Light::Directional { intensity, .. } => *intensity,
        }
    }

    /// The unit `L_q` from `p` toward the light and the shadow ray that
    /// tests it from `hit` (to the light's position, or unbounded).
    pub fn toward(&self, hit: &Hit) -> Option<(Vec3, Ray)> {
        match *self {
            Light::Point { position, .. } => {
                let l = (position - hit.point).try_normalize(0.0)?;
                Some((l, hit.spawn_to(position)))
            }
            Light::Directional { toward_light, .. } => {
                Some((toward_light, hit.spawn(toward_light)))
            }
        }
    }
}

/// A pinhole camera: the eye, an orthonormal frame (`forward`, `right`,
/// `up`), the vertical field of view, and the image size in pixels. Film
/// coordinates `(x, y)` run over `[0, width] x [0, height]`, `y` down from
/// the top row; pixel `(i, j)` is the square `[i, i + 1] x [j, j + 1]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    eye: Vec3,
    forward: Vec3,
    right: Vec3,
    up: Vec3,
    /// `tan(fov_y / 2)`.
    tan_half: f64,
    width: usize,
    height: usize,
}

/// The largest image side, in pixels.
pub const MAX_SIDE: usize = 1 << 14;

/// The narrowest vertical field of view accepted, in degrees: a pixel of a
/// [`MAX_SIDE`]-pixel-high image then spans about 1e-10 of the unit
/// viewing direction, and a sample 1e-3 of a pixel apart still some 1e3
/// units in the last place (a field of view of 1e-320 degrees has a
/// tangent of 0, and every ray of the image is the same).
pub const MIN_FOV_Y: f64 = 1e-4;

impl Camera {
    /// The camera at `eye` looking along `forward` with `up` as the image's
    /// up (not parallel to `forward`), vertical field of view `fov_y`
    /// degrees in `[MIN_FOV_Y, 180)`, and `width x height` pixels (each in
    /// `1..=16384`).
    pub fn new(
        eye: Vec3,
        forward: Vec3,
        up: Vec3,
        fov_y: f64,
        width: usize,
        height: usize,
    ) -> Result<Self, QuadError> {
        require_finite_vec("eye", eye)?;
        let forward = normalize("forward", forward)?;
        let given_up = up;
        let up = normalize("up", up)?;
        let right = forward.cross(&up).try_normalize(1e-12).ok_or_else(|| {
            QuadError::invalid(
                "up",
                format!("{:?}", given_up.as_slice()),
                "a direction not parallel to the viewing direction",
            )
        })?;
        let up = right.cross(&forward);
        require_finite("fov_y", fov_y)?;
        let tan_half = (0.5 * fov_y.to_radians()).tan();
        if !((MIN_FOV_Y..180.0).contains(&fov_y) && tan_half > 0.0 && tan_half.is_finite()) {
            return Err(QuadError::invalid(
                "fov_y",
                fov_y,
                format!(
                    "a vertical field of view in degrees in [{MIN_FOV_Y:e}, 180) (narrower, the \
                     rays through neighbouring points of a {MAX_SIDE}-pixel-high image differ by \
                     too few digits of f64; 180 and wider has no pinhole image)"
                ),
            ));
        }
        for (name, side) in [("width", width), ("height", height)] {
            if !(1..=MAX_SIDE).contains(&side) {
                return Err(QuadError::invalid(
                    name,
                    side,
                    format!("a number of pixels in 1..={MAX_SIDE}"),
                ));
            }
        }
        Ok(Camera {
            eye,
            forward,
            right,
            up,
            tan_half,
            width,
            height,
        })
    }

    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The eye.
    pub fn eye(&self) -> Vec3 {
        self.eye
    }

    /// The primary ray through film point `[x, y]`: direction `forward +
    /// s_x right + s_y up` normalised, `s_y = (1 - 2 y / H) tan(fov_y / 2)`,
    /// `s_x = (2 x / W - 1) tan(fov_y / 2) W / H`.
    pub fn ray(&self, film: [f64; 2]) -> Ray {
        let d = self.direction(film);
        Ray::new(self.eye, d / d.norm())
    }

    /// The unnormalised direction `forward + s_x right + s_y up` through
    /// film point `[x, y]`: affine in `x` and `y`.
    pub fn direction(&self, film: [f64; 2]) -> Vec3 {
        let (w, h) = (self.width as f64, self.height as f64);
        let sx = (2.0 * film[0] / w - 1.0) * self.tan_half * w / h;
        let sy = (1.0 - 2.0 * film[1] / h) * self.tan_half;
        self.forward + self.right * sx + self.up * sy
    }

    /// The film points whose direction `d(x, y)` has `d . normal <= 0`: with
    /// `d = d_0 + x d_x + y d_y` (affine, [`Camera::direction`]), the
    /// half-plane `(d_x . n) x + (d_y . n) y <= -(d_0 . n)`. Its edge is
    /// where the film meets the plane through the eye normal to `normal`.
    pub fn film_half_plane(&self, normal: Vec3) -> HalfPlane {
        let (w, h) = (self.width as f64, self.height as f64);
        let d0 = self.forward - self.right * (self.tan_half * w / h) + self.up * self.tan_half;
        let dx = self.right * (2.0 * self.tan_half / h);
        let dy = -self.up * (2.0 * self.tan_half / h);
        HalfPlane {
            a: dx.dot(&normal),
            b: dy.dot(&normal),
            c: -d0.dot(&normal),
        }
    }

    /// The film half-planes whose common part is the film region whose
    /// primary rays meet the triangle `v`, or none when the eye is in the
    /// triangle's plane (its image has no area).
    ///
    /// The ray `eye + t d`, `t > 0`, meets the triangle where `d` is a
    /// positive combination of the `v_k - eye`: for each edge `(p, q)` with
    /// third vertex `r`, `d . n` has the sign of `(r - p) . n`, `n = (q - p)
    /// x (eye - p)` the normal of the plane through the edge and the eye
    /// (`(r - eye) . n = (r - p) . n` as `n` is normal to `eye - p`). These
    /// are homogeneous tests: no vertex is divided by its depth, so one
    /// behind the eye, or 1e20 beyond it, bounds the region as it should.
    pub fn triangle_half_planes(&self, v: &[Vec3; 3]) -> Option<[HalfPlane; 3]> {
        let mut planes = [HalfPlane {
            a: 0.0,
            b: 0.0,
            c: 0.0,
        }; 3];
        for (k, plane) in planes.iter_mut().enumerate() {
            let (p, q, r) = (v[k], v[(k + 1) % 3], v[(k + 2) % 3]);
            let n = (q - p).cross(&(self.eye - p));
            // Scaled to a largest component of 1: the side tests are
            // unchanged, and no product of them underflows or overflows.
            let n = n / n.amax();
            let side = (r - p).dot(&n);
            if !side.is_finite() || side == 0.0 {
                return None;
            }
            let toward = self.film_half_plane(n);
            *plane = if side < 0.0 {
                toward
            } else {
                toward.complement()
            };
        }
        Some(planes)
    }

    /// The film lines `x = x_0`, `x = x_1`, `y = y_0`, `y = y_1` bounding
    /// the outline of the sphere (`centre`, `radius`) where they exist: the
    /// outline's extreme `s_x = (d . right) / (d . forward)` are the tangents
    /// from the eye to the sphere's section in the (right, forward) plane,
    /// `s_x = tan(alpha +- beta)`, `alpha = atan2(w . right, w . forward)`,
    /// `beta = asin(r / |(w . right, w . forward)|)`, `w = centre - eye`
    /// (likewise `s_y` with `up`). None beside an eye inside the sphere.
    pub fn sphere_bounds(&self, centre: Vec3, radius: f64) -> Vec<HalfPlane> {
        let w = centre - self.eye;
        let (wf, wr, wu) = (w.dot(&self.forward), w.dot(&self.right), w.dot(&self.up));
        let (width, height) = (self.width as f64, self.height as f64);
        let tangents = |across: f64| -> Vec<f64> {
            let reach = across.hypot(wf);
            if reach.is_nan() || reach <= radius {
                return Vec::new();
            }
            let (alpha, beta) = (across.atan2(wf), (radius / reach).asin());
            [alpha - beta, alpha + beta]
                .into_iter()
                .filter(|t| t.abs() < std::f64::consts::FRAC_PI_2)
                .map(f64::tan)
                .collect()
        };
        let mut lines = Vec::new();
        for sx in tangents(wr) {
            let x = (sx / (self.tan_half * width / height) + 1.0) * width / 2.0;
            lines.push(HalfPlane {
                a: 1.0,
                b: 0.0,
                c: x,
            });
        }
        for sy in tangents(wu) {
            let y = (1.0 - sy / self.tan_half) * height / 2.0;
            lines.push(HalfPlane {
                a: 0.0,
                b: 1.0,
                c: y,
            });
        }
        lines.retain(|l| l.c.is_finite());
        lines
    }

    /// The film point `[x, y]` where the line from the eye through `p`
    /// meets the image plane, when `p` is in front of the eye.
    pub fn project(&self, p: Vec3) -> Option<[f64; 2]> {
        let v = p - self.eye;
        let z = v.dot(&self.forward);
        if z.is_nan() || z <= 0.0 {
            return None;
        }
        let (w, h) = (self.width as f64, self.height as f64);
        let sx = v.dot(&self.right) / z;
        let sy = v.dot(&self.up) / z;
        Some([
            (sx / (self.tan_half * w / h) + 1.0) * w / 2.0,
            (1.0 - sy / self.tan_half) * h / 2.0,
        ])
    }
}

/// An object: a shape and its material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Object {
    /// The surface.
    pub shape: Shape,
    /// Its coefficients.
    pub material: Material,
}

/// A scene of W-6.1.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// The objects.
    pub objects: Vec<Object>,
    /// The lights `q`.
    pub lights: Vec<Light>,
    /// `I_a`, per R, G, B.
    pub ambient: Rgb,
    /// The intensity of a ray that meets nothing.
    pub background: Rgb,
    /// The camera.
    pub camera: Camera,
    /// The deepest recursion of reflected and transmitted rays (0: primary
    /// rays and shadow rays only), at most [`MAX_DEPTH`].
    pub max_depth: usize,
}

impl Scene {
    /// The scene, each part checked (materials by [`Material::check`],
    /// `ambient` and `background` finite and `>= 0`, `max_depth` at most
    /// [`MAX_DEPTH`]).
    pub fn new(
        objects: Vec<Object>,
        lights: Vec<Light>,
        ambient: Rgb,
        background: Rgb,
        camera: Camera,
        max_depth: usize,
    ) -> Result<Self, QuadError> {
        for o in &objects {
            o.material.check()?;
        }
        require_rgb("ambient", ambient)?;
        require_rgb("background", background)?;
        if max_depth > MAX_DEPTH {
            return Err(QuadError::invalid(
                "max_depth",
                max_depth,
                format!("a recursion depth in 0..={MAX_DEPTH}"),
            ));
        }
        Ok(Scene {
            objects,
            lights,
            ambient,
            background,
            camera,
            max_depth,
        })
    }

    /// The nearest object along `ray` and its hit.
    pub fn nearest(&self, ray: &Ray) -> Option<(usize, Hit)> {
        let mut best: Option<(usize, Hit)> = None;
        let mut r = *ray;
        for (k, o) in self.objects.iter().enumerate() {
            if let Some(h) = o.shape.intersect(&r) {
                r.t_max = h.t;
                best = Some((k, h));
            }
        }
        best
    }

    /// True when some object meets `ray` in `(0, t_max)`.
    pub fn blocked(&self, ray: &Ray) -> bool {
        self.objects
            .iter()
            .any(|o| o.shape.intersect(ray).is_some())
    }

    /// True when some object transmits (`k_t > 0`): only then are
    /// refraction rays traced.
    pub fn has_transparency(&self) -> bool {
        self.objects.iter().any(|o| o.material.k_t > 0.0)
    }

    /// True when some object reflects (`k_s > 0`): only then are reflection
    /// rays traced.
    pub fn has_mirrors(&self) -> bool {
        self.objects.iter().any(|o| o.material.k_s > 0.0)
    }
}
