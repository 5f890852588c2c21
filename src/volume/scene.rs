//! A volume-rendering scene along one eye ray: only the parts it has.
//! (docs/EQUATIONS.md, `V-*`: a medium, an emission map, a background, a directional
//! light, optionally with single scattering.)
//!
//! ```
//! use std::sync::Arc;
//! use lightquad::domain::Vec3;
//! use lightquad::geometry::Ray;
//! use lightquad::volume::{ConstantSphere, EmissionMap, TransferTable, VolumeScene};
//!
//! // An eye ray from x = -3 through a unit sphere, emitting through a transfer
//! // function c(v) linear from (0, 0) to (2, 1), in front of a background.
//! let mut scene = VolumeScene::new(Ray::new(Vec3::new(-3.0, 0.0, 0.0), Vec3::x())?);
//! scene.medium = Some(Arc::new(ConstantSphere::new(Vec3::zeros(), 1.0, 0.5)?));
//! let table = TransferTable::new(vec![(0.0, 0.0), (2.0, 1.0)])?;
//! assert_eq!(table.at(0.5), 0.25);
//! scene.emission = Some(EmissionMap::Table(table));
//! scene.background = Some(1.0);
//! scene.validate()?;
//! // A medium emits only where its density is positive: c(0) = 0.
//! assert_eq!(EmissionMap::Constant(2.0).at(0.0), 0.0);
//! // Re-anchored at the start of the medium's support (t* = 2): the same
//! // integrals, with the chord's parameters small and their rounding with them.
//! let (anchored, shift) = scene.anchored();
//! assert!((shift - 2.0).abs() < 1e-15);
//! assert!((anchored.ray.origin - Vec3::new(-1.0, 0.0, 0.0)).norm() < 1e-15);
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use std::sync::Arc;

use super::medium::Medium;
use crate::domain::Vec3;
use crate::error::QuadError;
use crate::geometry::{Ray, normalize};

/// The emission of V-E: `c(v)`, emitted radiance per unit length as a
/// function of the density, or an emission field `Le(p)` of its own.
///
/// Convention for the maps of the density (`Constant`, `Table`): a medium
/// emits where its density is positive, so `c(0) = 0` whatever the map says
/// at `0+`. Quadrature applies it per smooth piece of the ray
/// ([`EmissionMap::on_piece`]): on a piece whose density is positive inside
/// (at its midpoint) the map's formula for `v > 0` is used up to and
/// including the piece's ends, so an end node where the density reaches 0
/// reads the one-sided limit, not the jump; a piece of zero density emits
/// nothing. (Every medium here is either positive in a piece's interior or
/// zero on all of it.)
#[derive(Debug, Clone)]
pub enum EmissionMap {
    /// `c(v) = c0` where `v > 0`, 0 elsewhere.
    Constant(f64),
    /// `c(v) = k v`.
    Proportional(f64),
    /// A transfer function: `c(v)` piecewise linear through a table, held at
    /// its end values outside it, 0 where `v = 0` ([`TransferTable`]).
    Table(TransferTable),
    /// An emission field of its own (pbrt's media take `Le` apart from
    /// `sigma`): `I_E = int tau(t_0, t) Le(r(t)) dt` with `Le` the field's
    /// "density", emitting wherever it is positive, also where the medium's
    /// density is zero (there `tau` is the transmittance up to that point).
    Field(Arc<dyn Medium>),
}

impl EmissionMap {
    /// `c(v)` of a map of the density; 0 for [`EmissionMap::Field`], which
    /// does not depend on the density.
    #[inline]
    pub fn at(&self, v: f64) -> f64 {
        self.on_piece(v, v > 0.0)
    }

    /// `c(v)` at a node of a smooth piece whose density is positive inside
    /// (`emitting`) or zero on all of it: on an emitting piece the map's
    /// formula for `v > 0`, extended to the piece's ends (see the type's
    /// convention); on a piece of zero density 0 (`k v` for `Proportional`,
    /// which is continuous). 0 for [`EmissionMap::Field`].
    #[inline]
    pub fn on_piece(&self, v: f64, emitting: bool) -> f64 {
        match self {
            EmissionMap::Constant(c0) => {
                if emitting {
                    *c0
                } else {
                    0.0
                }
            }
            EmissionMap::Proportional(k) => k * v,
            EmissionMap::Table(table) => {
                if emitting {
                    table.positive(v)
                } else {
                    0.0
                }
            }
            EmissionMap::Field(_) => 0.0,
        }
    }
}

/// A transfer function `c(v)` as volume renderers give it: points
/// `(v_0, c_0), .., (v_m, c_m)` with `0 <= v_0 < v_1 < .. < v_m`, `c_i >= 0`
/// finite, `m >= 1`;
///
/// `c(v) = c_i + (c_{i+1} - c_i) (v - v_i) / (v_{i+1} - v_i)` for
/// `v_i <= v <= v_{i+1}`, `c(v) = c_0` for `0 < v < v_0`, `c(v) = c_m` for
/// `v > v_m` (clamped at the end values, as a 1-D texture lookup with clamp
/// addressing does), and `c(0) = 0` (a medium emits where its density is
/// positive). `c(v(t))` has a kink wherever the density along the ray crosses
/// a knot `v_i`; V-E cuts its pieces there.
///
/// Negative `c` is refused: `c` is emitted radiance, and a negative value
/// would be absorption, which belongs to `sigma`.
#[derive(Debug, Clone, PartialEq)]
pub struct TransferTable {
    points: Arc<[(f64, f64)]>,
}

impl TransferTable {
    /// A table; errors name the faulty entry (`points[2][0]` for the `v` of
    /// the third point, `points[2][1]` for its `c`, `points` for too few).
    pub fn new(points: Vec<(f64, f64)>) -> Result<Self, QuadError> {
        if points.len() < 2 {
            return Err(QuadError::invalid(
                "points",
                format!("{} point(s)", points.len()),
                "at least 2 points [v, c]",
            ));
        }
        for (i, &(v, c)) in points.iter().enumerate() {
            if !(v.is_finite() && v >= 0.0) {
                return Err(QuadError::invalid(
                    format!("points[{i}][0]"),
                    v,
                    "a finite density v >= 0",
                ));
            }
            if i > 0 && v <= points[i - 1].0 {
                return Err(QuadError::invalid(
                    format!("points[{i}][0]"),
                    v,
                    format!(
                        "a density > points[{}][0] = {} (v strictly increasing)",
                        i - 1,
                        points[i - 1].0
                    ),
                ));
            }
            if !(c.is_finite() && c >= 0.0) {
                return Err(QuadError::invalid(
                    format!("points[{i}][1]"),
                    c,
                    "a finite emitted radiance c >= 0",
                ));
            }
        }
        Ok(TransferTable {
            points: points.into(),
        })
    }

    /// The points `(v_i, c_i)`.
    pub fn points(&self) -> &[(f64, f64)] {
        &self.points
    }

    /// The knots `v_i` where `c` can have a kink, those `> 0` (a density of
    /// 0 lies at an end of a piece, never inside one).
    pub fn knots(&self) -> impl Iterator<Item = f64> + '_ {
        self.points.iter().map(|p| p.0).filter(|&v| v > 0.0)
    }

    /// `c(v)`: 0 where `v <= 0`, else [`TransferTable::positive`].
    pub fn at(&self, v: f64) -> f64 {
        if v > 0.0 { self.positive(v) } else { 0.0 }
    }

    /// The table's formula for `v > 0` at any `v` (clamped at the ends,
    /// linear between the knots), without the cut at `v = 0`.
    pub fn positive(&self, v: f64) -> f64 {
        let p = &self.points;
        let (first, last) = (p[0], p[p.len() - 1]);
        if v.is_nan() || v <= first.0 {
            return first.1;
        }
        if v >= last.0 {
            return last.1;
        }
        // The segment [v_i, v_{i+1}] holding v: the first knot above v is i+1.
        let i = p.partition_point(|q| q.0 <= v) - 1;
        let ((v0, c0), (v1, c1)) = (p[i], p[i + 1]);
        let u = (v - v0) / (v1 - v0);
        c0 + (c1 - c0) * u
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
        if let Some(a) = albedo
            && !(0.0..=1.0).contains(&a)
        {
            return Err(QuadError::invalid("albedo", a, "a number in [0, 1]"));
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

    /// The same scene with its ray re-anchored at the start `t*` of the
    /// medium's support along it (with an emission field's support): origin `e + t* v`, looked-at part
    /// `[t_min - t*, t_max - t*]`; returns `t*` with it (0 when there is no
    /// medium or the ray misses it). Every term is an integral over the ray
    /// and does not change. What changes is rounding: the points of a chord
    /// far from the eye, `e + t v` with `|t|` large, carry an absolute error
    /// of `eps |t|`, which for a grazing chord of length `L` is a relative
    /// error of `eps |t| / L` in every depth measured from them (1e-8 at a
    /// chord of 1e-7 three units away). From the re-anchored origin the
    /// chord's parameters are `O(L)`, and so are their errors.
    pub fn anchored(&self) -> (VolumeScene, f64) {
        // First at the closest approach to the medium's centre, so that a
        // far origin does not round the chord away; then at the start of the
        // support as seen from there.
        let field = self.emission_field();
        let near = self
            .medium
            .iter()
            .chain(field)
            .find_map(|m| m.centre())
            .map(|c| (c - self.ray.origin).dot(&self.ray.dir))
            .filter(|t| t.is_finite() && *t != 0.0);
        let Some(t_near) = near else {
            return self.anchored_at_support();
        };
        let (near_scene, _) = self.shifted(t_near);
        let (out, t_star) = near_scene.anchored_at_support();
        (out, t_near + t_star)
    }

    /// The emission field, when the scene's emission is one.
    fn emission_field(&self) -> Option<&Arc<dyn Medium>> {
        match &self.emission {
            Some(EmissionMap::Field(f)) => Some(f),
            _ => None,
        }
    }

    /// The scene with its ray's origin moved to `e + t v`.
    fn shifted(&self, t: f64) -> (VolumeScene, f64) {
        let mut out = self.clone();
        out.ray = Ray {
            origin: self.ray.at(t),
            dir: self.ray.dir,
        };
        out.t_min = self.t_min - t;
        out.t_max = self.t_max - t;
        (out, t)
    }

    /// Re-anchored at the start of the support along the ray as it is.
    fn anchored_at_support(&self) -> (VolumeScene, f64) {
        let field = self.emission_field();
        let (first, last) = self
            .medium
            .iter()
            .chain(field)
            .flat_map(|m| m.support(&self.ray, self.t_min, self.t_max))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), s| {
                (lo.min(s.start()), hi.max(s.end()))
            });
        if first > last {
            return (self.clone(), 0.0);
        }
        // The start of the support, not its middle: the terms are weighted by
        // the transmittance from there, so their features (optical depths 1,
        // 2, 4, ... where the pieces are graded) sit near it, and measured
        // from the middle of a chord of 1e20 they would round to 8192.
        let t_star = first;
        if !t_star.is_finite() || t_star == 0.0 {
            return (self.clone(), 0.0);
        }
        self.shifted(t_star)
    }

    /// An upper bound of the optical depth along the ray,
    /// `lambda sum_pieces max v (t1 - t0)` over the medium's support, with
    /// the largest extinction `lambda max v` it used: both must be finite for
    /// the terms to be computable (a radius of 1e300 with a density gradient,
    /// or `lambda = 1e308`, overflow them). 0 without a medium.
    pub fn depth_bound(&self) -> (f64, f64) {
        let Some(m) = &self.medium else {
            return (0.0, 0.0);
        };
        // lambda = 0: no extinction whatever the density's bound (0 times an
        // infinite bound is not NaN here).
        if self.lambda == 0.0 {
            return (0.0, 0.0);
        }
        let (mut sigma, mut depth) = (0.0f64, 0.0f64);
        for piece in m.support(&self.ray, self.t_min, self.t_max) {
            let (t0, t1) = (piece.start(), piece.end());
            let s = self.lambda * m.max_density(&self.ray, t0, t1);
            sigma = sigma.max(s);
            depth += s * (t1 - t0);
        }
        (sigma, depth)
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
        if let Some(b) = self.background
            && !(b.is_finite() && b >= 0.0)
        {
            return Err(QuadError::invalid(
                "background",
                b,
                "a finite radiance >= 0",
            ));
        }
        match &self.emission {
            Some(EmissionMap::Constant(c)) | Some(EmissionMap::Proportional(c))
                if !c.is_finite() =>
            {
                Err(QuadError::invalid("emission", c, "a finite number"))
            }
            _ => Ok(()),
        }
    }
}
