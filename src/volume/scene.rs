//! A volume-rendering scene along one eye ray: only the parts it has.
//! (docs/EQUATIONS.md, V-*: a medium, an emission map, a background, a directional
//! light, optionally with single scattering.)

use std::sync::Arc;

use super::medium::Medium;
use crate::domain::Vec3;
use crate::error::QuadError;
use crate::geometry::{Ray, normalize};

/// `c(v)`: emitted radiance per unit length as a function of the density.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EmissionMap {
    /// `c(v) = c0` where `v > 0`, 0 elsewhere.
    Constant(f64),
    /// `c(v) = k v`.
    Proportional(f64),
}

impl EmissionMap {
    /// `c(v)`.
    #[inline]
    pub fn at(&self, v: f64) -> f64 {
        match *self {
            EmissionMap::Constant(c0) => {
                if v > 0.0 {
                    c0
                } else {
                    0.0
                }
            }
            EmissionMap::Proportional(k) => k * v,
        }
    }
}

/// A directional light of intensity `I_p` (V-Lp).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DirectionalLight {
    /// Unit direction from a point toward the light (`d` in V-Lp). A renderer's
    /// "direction the light travels" (Mitsuba's `direction`) is its negative.
    pub toward_light: Vec3,
    /// `I_p`.
    pub intensity: f64,
    /// Single scattering (audit point 4): `Some(albedo)` multiplies the light
    /// term by `sigma_s = albedo sigma` and the isotropic phase `1/(4 pi)`;
    /// `None` is the document's reduced form without them.
    pub albedo: Option<f64>,
}

impl DirectionalLight {
    /// A light; `toward_light` non-zero, `intensity >= 0`, `albedo` in [0, 1].
    pub fn new(toward_light: Vec3, intensity: f64, albedo: Option<f64>) -> Result<Self, QuadError> {
        if !(intensity.is_finite() && intensity >= 0.0) {
            return Err(QuadError::invalid(
                "intensity",
                intensity,
                "a finite number >= 0",
            ));
        }
        if let Some(a) = albedo {
            if !(0.0..=1.0).contains(&a) {
                return Err(QuadError::invalid("albedo", a, "a number in [0, 1]"));
            }
        }
        Ok(DirectionalLight {
            toward_light: normalize("toward_light", toward_light)?,
            intensity,
            albedo,
        })
    }
}

/// One eye ray through a scene that holds only the parts it has.
#[derive(Debug, Clone)]
pub struct VolumeScene {
    /// The eye ray `r(t) = e + t v`.
    pub ray: Ray,
    /// `[t_min, t_max]`: the part of the ray that is looked at.
    pub t_min: f64,
    /// End of the looked-at part (may be infinite).
    pub t_max: f64,
    /// The medium, if any.
    pub medium: Option<Arc<dyn Medium>>,
    /// `lambda` in `sigma = lambda v_r`.
    pub lambda: f64,
    /// The emission map `c`, if the medium emits.
    pub emission: Option<EmissionMap>,
    /// The background radiance `I_b`, if any.
    pub background: Option<f64>,
    /// The directional light, if any.
    pub light: Option<DirectionalLight>,
}

impl VolumeScene {
    /// An empty scene along `ray` over `[0, inf)`: nothing but the ray.
    pub fn new(ray: Ray) -> Self {
        VolumeScene {
            ray,
            t_min: 0.0,
            t_max: f64::INFINITY,
            medium: None,
            lambda: 1.0,
            emission: None,
            background: None,
            light: None,
        }
    }

    /// The same scene with its ray re-anchored at the middle `t*` of the
    /// medium's support along it: origin `e + t* v`, looked-at part
    /// `[t_min - t*, t_max - t*]`; returns `t*` with it (0 when there is no
    /// medium or the ray misses it). Every term is an integral over the ray
    /// and does not change. What changes is rounding: the points of a chord
    /// far from the eye, `e + t v` with `|t|` large, carry an absolute error
    /// of `eps |t|`, which for a grazing chord of length `L` is a relative
    /// error of `eps |t| / L` in every depth measured from them (1e-8 at a
    /// chord of 1e-7 three units away). From the re-anchored origin the
    /// chord's parameters are `O(L)`, and so are their errors.
    pub fn anchored(&self) -> (VolumeScene, f64) {
        let support = self
            .medium
            .as_ref()
            .map(|m| m.support(&self.ray, self.t_min, self.t_max))
            .unwrap_or_default();
        let (Some(first), Some(last)) = (support.first(), support.last()) else {
            return (self.clone(), 0.0);
        };
        let t_star = 0.5 * (first.start() + last.end());
        if !t_star.is_finite() || t_star == 0.0 {
            return (self.clone(), 0.0);
        }
        let mut out = self.clone();
        out.ray = Ray {
            origin: self.ray.at(t_star),
            dir: self.ray.dir,
        };
        out.t_min = self.t_min - t_star;
        out.t_max = self.t_max - t_star;
        (out, t_star)
    }

    /// Checks the numbers a user supplies (`lambda >= 0`, `t_min <= t_max`,
    /// finite `I_b` and emission).
    pub fn validate(&self) -> Result<(), QuadError> {
        if !(self.lambda.is_finite() && self.lambda >= 0.0) {
            return Err(QuadError::invalid(
                "lambda",
                self.lambda,
                "a finite number >= 0",
            ));
        }
        if !self.t_min.is_finite() || self.t_min.is_nan() {
            return Err(QuadError::invalid("t_min", self.t_min, "a finite number"));
        }
        if self.t_max.is_nan() || self.t_max < self.t_min {
            return Err(QuadError::invalid(
                "t_max",
                self.t_max,
                format!("a number >= t_min = {} (t_f >= t_n)", self.t_min),
            ));
        }
        if let Some(l) = self.light {
            DirectionalLight::new(l.toward_light, l.intensity, l.albedo)?;
            if ((l.toward_light.norm() - 1.0).abs()) > 1e-12 {
                return Err(QuadError::invalid(
                    "toward_light",
                    format!("{:?}", l.toward_light.as_slice()),
                    "a unit vector (build the light with DirectionalLight::new)",
                ));
            }
        }
        if let Some(b) = self.background {
            if !(b.is_finite() && b >= 0.0) {
                return Err(QuadError::invalid(
                    "background",
                    b,
                    "a finite radiance >= 0",
                ));
            }
        }
        match self.emission {
            Some(EmissionMap::Constant(c)) | Some(EmissionMap::Proportional(c))
                if !c.is_finite() =>
            {
                Err(QuadError::invalid("emission", c, "a finite number"))
            }
            _ => Ok(()),
        }
    }
}
