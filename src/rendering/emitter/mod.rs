//! Emitters of the rendering family: Lambertian area lights (rectangle,
//! disk, triangle, sphere) of radiance `L_e`, a uniform environment and a
//! spherical-cap light (uniform radiance from a cone of directions at
//! infinity: a distant sphere, the sun), each of scalar or RGB radiance
//! ([`Value`]).
//!
//! Each emitter can
//!
//! - say whether the ray from `x` along `w` hits it, at what distance and
//!   with what radiance toward `x` ([`Emitter::hit`]: `L_e` on the emitting
//!   side, 0 on the back of a one-sided planar light or from inside a
//!   sphere);
//! - give the domain of the area form R-A seen from a receiver
//!   ([`Emitter::surface`]): its own surface through the parameterisations
//!   of [`crate::domain`] (a rectangle, the polar map of a disk, the Duffy
//!   map of a triangle) with their Jacobians, for a sphere the cap of it
//!   visible from `x` ([`Cap`], uniform in area, `1 - cos = (d - R)/d`), for
//!   lights at infinity their cap of directions (whose measure is solid
//!   angle);
//! - give the cone of directions from `x` that contains it
//!   ([`Emitter::cone`]): exact for a sphere, a cap light and a disk seen
//!   from its axis, the cone of a bounding sphere otherwise;
//! - be sampled ([`Emitter::sample`]) by area through its surface map or by
//!   its cone, uniformly in solid angle, with the density in solid angle
//!   [`Emitter::pdf`]: by area `pdf_w = pdf_A r^2 / cos theta'` with
//!   `pdf_A = 1 / |J(u)|` (R-A's change of variables `d omega = cos theta'
//!   dA / r^2`), by cone `pdf_w = 1 / (2 pi (1 - cos alpha))`. Cone sampling
//!   is the better one for a small or distant sphere, whose visible cap's
//!   area samples have nearly equal weight only when `r` and `cos theta'`
//!   vary little.
//!
//! Planar lights emit from the side their normal points to (rectangle: `e_1
//! x e_2`; triangle `(b - a) x (c - b)`; disk: its normal) and block light
//! on both sides.
//!
//! One file per light: `rectangle`, `disk`, `triangle`, `sphere`, and
//! `distant` for the lights at infinity (environment and cap); the trait,
//! the domains and [`AnyEmitter`] are here.
//!
//! ```
//! use std::f64::consts::PI;
//! use lightquad::domain::Vec3;
//! use lightquad::rendering::emitter::{DiskLight, Emitter, LightSampling};
//! use lightquad::rendering::receiver::Receiver;
//!
//! // A disk light of radius 1 at height 1 facing down onto the origin.
//! let disk = DiskLight::new(Vec3::new(0.0, 0.0, 1.0), -Vec3::z(), 1.0, 2.0)?;
//! let hit = disk.hit(Vec3::zeros(), Vec3::z(), 0.0).ok_or(lightquad::QuadError::invalid("hit", 0, "a hit"))?;
//! assert_eq!((hit.distance, hit.radiance), (1.0, 2.0));
//! // Sampled through its cone (exact on the axis): pdf 1 / (2 pi (1 - cos 45°)).
//! let x = Receiver::new(Vec3::zeros(), Vec3::z())?;
//! let s = disk.sample(&x, LightSampling::Cone, [0.5, 0.5]).ok_or(lightquad::QuadError::invalid("u", 0, "a sample"))?;
//! assert!((s.pdf * 2.0 * PI * (1.0 - 0.5f64.sqrt()) - 1.0).abs() < 1e-13);
//! assert!((disk.pdf(&x, LightSampling::Cone, s.wi) - s.pdf).abs() < 1e-12 * s.pdf);
//! // Negative radiance is an error naming the parameter.
//! assert!(DiskLight::new(Vec3::zeros(), Vec3::z(), 1.0, -1.0).is_err());
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use crate::domain::{Disk, Domain, Rectangle, Triangle, Vec3};
use crate::error::QuadError;
use crate::rendering::cap::{Cap, one_minus_cos_from_sin};
use crate::rendering::occluder::Occluder;
use crate::rendering::receiver::Receiver;
use crate::value::Value;

mod disk;
mod distant;
mod rectangle;
mod sphere;
mod triangle;

pub use disk::DiskLight;
pub use distant::{CapLight, EnvironmentLight};
pub use rectangle::RectangleLight;
pub use sphere::SphereLight;
pub use triangle::TriangleLight;

/// The relative slack of an emitter's outline in [`Emitter::hit`]: a ray
/// passing within `RIM_TOL R` outside the rim of a disk or sphere light (or
/// `RIM_TOL k` outside a cap light's cone) counts as a hit. The outline of
/// a light is closed, and a rule that puts nodes on the exact outline of its
/// cone (trapezoid, Simpson: `u_1 = 1`) must see the limit from inside, not
/// a coin flip of rounding (the trapezoid rule over a coaxial disk's cone
/// kept 1.8e-3 relative error at 64 x 64 nodes from it). The light grows by
/// at most `RIM_TOL` relative: far below the 1e-10 the tests ask.
pub const RIM_TOL: f64 = 1e-12;

/// The largest radiance accepted. The integrands multiply `L` by their
/// maps' Jacobians (`2 pi` over the hemisphere) and by BRDF values (a
/// normalized Phong lobe of exponent 1e4 peaks near 1.6e3, GGX at `1 / (pi
/// alpha^2)`): a radiance of 1e308 overflowed them to infinity in 10 of 14
/// jobs. 1e290 leaves eighteen orders of magnitude.
pub const MAX_RADIANCE: f64 = 1e290;

/// Checks a radiance: every channel finite, `>= 0` and at most
/// [`MAX_RADIANCE`].
pub fn check_radiance<V: Value>(name: &str, radiance: V) -> Result<V, QuadError> {
    if (0..V::CHANNELS).all(|c| {
        let x = radiance.channel(c);
        (0.0..=MAX_RADIANCE).contains(&x)
    }) {
        Ok(radiance)
    } else {
        Err(QuadError::invalid(
            name,
            format!("{radiance:?}"),
            format!(
                "a radiance with every channel in [0, {MAX_RADIANCE:e}] (larger ones overflow the \
                 integrands' products)"
            ),
        ))
    }
}

/// Where a ray meets an emitter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EmitterHit<V: Value> {
    /// Distance along the unit direction; `f64::INFINITY` for a light at
    /// infinity.
    pub distance: f64,
    /// The radiance the emitter sends back along the ray: `L_e` on its
    /// emitting side, zero on its back.
    pub radiance: V,
}

/// A direction sampled toward an emitter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightSample<V: Value> {
    /// Unit world direction from the receiver toward the light.
    pub wi: Vec3,
    /// Distance to the light's surface (`f64::INFINITY` at infinity).
    pub distance: f64,
    /// The point on the light (`x + distance wi`; for a light at infinity,
    /// `wi`).
    pub point: Vec3,
    /// The density in solid angle of the sampling map at `wi`.
    pub pdf: f64,
    /// For area sampling of a finite light, the density per unit area
    /// `pdf_A = 1 / |J(u)|` of the point (`pdf = pdf_A r^2 / cos theta'`);
    /// `None` for cone sampling and lights at infinity.
    pub pdf_area: Option<f64>,
    /// `L_e` toward the receiver (zero where a cone sample meets the back).
    pub radiance: V,
}

/// How an emitter is sampled for light sampling and MIS.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LightSampling {
    /// Through the surface map of [`Emitter::surface`], `pdf_w = r^2 /
    /// (|J(u)| cos theta')` (R-A's change of variables).
    Area,
    /// Uniformly over the cone of [`Emitter::cone`], `pdf_w = 1 / (2 pi (1
    /// - cos alpha))`.
    Cone,
}

/// The domain of R-A for one emitter: its surface through a map of the
/// unit square, or a cap of directions for a light at infinity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LightDomain {
    /// A parallelogram, `|J| = |e_1 x e_2|`.
    Rectangle(Rectangle),
    /// A disk, polar map, `|J| = 2 pi R^2 u_1`.
    Disk(Disk),
    /// A triangle, Duffy map, `|J| = 2 A u_1`.
    Triangle(Triangle),
    /// A cap of a sphere (or of the sphere of directions), `|J| = 2 pi R^2 k`.
    Cap(Cap),
}

impl Domain<2> for LightDomain {
    type Point = Vec3;

    fn map(&self, u: [f64; 2]) -> (Vec3, f64) {
        match self {
            LightDomain::Rectangle(d) => d.map(u),
            LightDomain::Disk(d) => d.map(u),
            LightDomain::Triangle(d) => d.map(u),
            LightDomain::Cap(d) => d.map(u),
        }
    }

    fn invert(&self, p: &Vec3) -> Option<[f64; 2]> {
        match self {
            LightDomain::Rectangle(d) => d.invert(p),
            LightDomain::Disk(d) => d.invert(p),
            LightDomain::Triangle(d) => d.invert(p),
            LightDomain::Cap(d) => d.invert(p),
        }
    }

    fn measure(&self) -> f64 {
        match self {
            LightDomain::Rectangle(d) => d.measure(),
            LightDomain::Disk(d) => d.measure(),
            LightDomain::Triangle(d) => d.measure(),
            LightDomain::Cap(d) => d.measure(),
        }
    }
}

/// The cone of directions from `x` that contains the sphere about `centre`
/// of radius `radius`: `sin alpha = R / d`, or the whole sphere of
/// directions for `x` inside it.
pub fn bounding_cone(x: Vec3, centre: Vec3, radius: f64) -> Result<Cap, QuadError> {
    let to_centre = centre - x;
    let d = to_centre.norm();
    if d <= radius {
        return Cap::directions(Vec3::z(), 2.0);
    }
    Cap::directions(to_centre / d, one_minus_cos_from_sin(radius / d)?)
}

/// An emitter (R-H's `L_e`, R-A's emitting surface).
pub trait Emitter<V: Value> {
    /// The emitted radiance `L_e`.
    fn radiance(&self) -> V;

    /// True for lights at infinity (the environment, a cap light): they
    /// have no surface in the scene, block nothing, and are reached by every
    /// ray that no finite surface stops.
    fn at_infinity(&self) -> bool {
        false
    }

    /// The first point beyond `t_min` at which the ray `x + t w` (unit `w`)
    /// meets the emitter, with the radiance it sends back along the ray.
    fn hit(&self, x: Vec3, w: Vec3, t_min: f64) -> Option<EmitterHit<V>>;

    /// The domain of R-A seen from the receiver (module documentation).
    fn surface(&self, receiver: &Receiver) -> Result<LightDomain, QuadError>;

    /// The unit normal of the emitting side at a point `y` of the surface
    /// (for a light at infinity, `-y`, so that `cos theta' = 1`).
    fn normal_at(&self, y: Vec3) -> Vec3;

    /// The cone of directions from the receiver that contains the emitter
    /// (module documentation).
    fn cone(&self, receiver: &Receiver) -> Result<Cap, QuadError>;

    /// The emitter as an occluder of other emitters' light (`None` at
    /// infinity).
    fn occluder(&self) -> Option<Occluder>;

    /// A direction toward the emitter from `u` in `[0, 1]^2` by `how`, with
    /// its density in solid angle; `None` where the map's point sends no
    /// light toward `x` (the back of the light, its rim, a cone direction
    /// that misses it) or the receiver's domain cannot be built (`x` inside
    /// a sphere light).
    ///
    /// By area (R-A's change of variables): `y = map(u)`, `r = |y - x|`,
    /// `pdf_w = r^2 / (|J(u)| cos theta')`; by cone: `w = map(u)`, `pdf_w =
    /// 1 / |J|`.
    fn sample(
        &self,
        receiver: &Receiver,
        how: LightSampling,
        u: [f64; 2],
    ) -> Option<LightSample<V>> {
        let x = receiver.point();
        match how {
            LightSampling::Area if !self.at_infinity() => {
                let (y, jacobian) = self.surface(receiver).ok()?.map(u);
                let d = y - x;
                let r = d.norm();
                if !(jacobian > 0.0 && r > 0.0) {
                    return None;
                }
                let wi = d / r;
                let cos_light = -self.normal_at(y).dot(&wi);
                if cos_light <= 0.0 || cos_light.is_nan() {
                    return None;
                }
                Some(LightSample {
                    wi,
                    distance: r,
                    point: y,
                    pdf: r * r / (jacobian * cos_light),
                    pdf_area: Some(1.0 / jacobian),
                    radiance: self.radiance(),
                })
            }
            _ => {
                let domain = match how {
                    LightSampling::Area => self.surface(receiver).ok()?,
                    LightSampling::Cone => LightDomain::Cap(self.cone(receiver).ok()?),
                };
                let (wi, jacobian) = domain.map(u);
                if jacobian <= 0.0 || jacobian.is_nan() {
                    return None;
                }
                let hit = self.hit(x, wi, 0.0)?;
                Some(LightSample {
                    wi,
                    distance: hit.distance,
                    point: if hit.distance.is_finite() {
                        x + wi * hit.distance
                    } else {
                        wi
                    },
                    pdf: 1.0 / jacobian,
                    pdf_area: None,
                    radiance: hit.radiance,
                })
            }
        }
    }

    /// The density in solid angle with which [`Emitter::sample`] by `how`
    /// produces the unit direction `w` (0 where it cannot).
    fn pdf(&self, receiver: &Receiver, how: LightSampling, w: Vec3) -> f64 {
        let x = receiver.point();
        match how {
            // A direction of the cone that misses the light is never
            // produced ([`Emitter::sample`] gives `None` there): density 0,
            // so that the density integrates to the chance of a sample.
            LightSampling::Cone => match self.cone(receiver) {
                Ok(cone) if cone.contains_direction(w) && self.hit(x, w, 0.0).is_some() => {
                    1.0 / cone.measure()
                }
                _ => 0.0,
            },
            LightSampling::Area => {
                let Ok(surface) = self.surface(receiver) else {
                    return 0.0;
                };
                if self.at_infinity() {
                    return match surface.invert(&w) {
                        Some(u) => 1.0 / surface.map(u).1,
                        None => 0.0,
                    };
                }
                let Some(hit) = self.hit(x, w, 0.0) else {
                    return 0.0;
                };
                let y = x + w * hit.distance;
                let cos_light = -self.normal_at(y).dot(&w);
                let Some(u) = surface.invert(&y) else {
                    return 0.0;
                };
                let jacobian = surface.map(u).1;
                if cos_light > 0.0 && jacobian > 0.0 {
                    hit.distance * hit.distance / (jacobian * cos_light)
                } else {
                    0.0
                }
            }
        }
    }
}

/// The radiance `value` toward a ray of direction `w` meeting a one-sided
/// planar light of normal `n`: `L_e` when `n . w < 0` (the ray arrives on the
/// emitting side), else zero.
fn one_sided<V: Value>(radiance: V, n: Vec3, w: Vec3) -> V {
    if n.dot(&w) < 0.0 { radiance } else { V::zero() }
}

/// Any emitter of the family, for a scene's list.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AnyEmitter<V: Value> {
    /// [`RectangleLight`].
    Rectangle(RectangleLight<V>),
    /// [`DiskLight`].
    Disk(DiskLight<V>),
    /// [`TriangleLight`].
    Triangle(TriangleLight<V>),
    /// [`SphereLight`].
    Sphere(SphereLight<V>),
    /// [`EnvironmentLight`].
    Environment(EnvironmentLight<V>),
    /// [`CapLight`].
    Cap(CapLight<V>),
}

impl<V: Value> AnyEmitter<V> {
    /// The same emitter with radiance `radiance` (the converged reference
    /// evaluates each light at radiance 1 and scales the value by its own).
    pub(crate) fn with_radiance(self, radiance: V) -> Self {
        match self {
            AnyEmitter::Rectangle(e) => AnyEmitter::Rectangle(e.with_radiance(radiance)),
            AnyEmitter::Disk(e) => AnyEmitter::Disk(e.with_radiance(radiance)),
            AnyEmitter::Triangle(e) => AnyEmitter::Triangle(e.with_radiance(radiance)),
            AnyEmitter::Sphere(e) => AnyEmitter::Sphere(e.with_radiance(radiance)),
            AnyEmitter::Environment(e) => AnyEmitter::Environment(e.with_radiance(radiance)),
            AnyEmitter::Cap(e) => AnyEmitter::Cap(e.with_radiance(radiance)),
        }
    }
}

/// Forwards a method of [`Emitter`] to the variant's type.
macro_rules! forward {
    ($self:ident, $e:ident => $call:expr) => {
        match $self {
            AnyEmitter::Rectangle($e) => $call,
            AnyEmitter::Disk($e) => $call,
            AnyEmitter::Triangle($e) => $call,
            AnyEmitter::Sphere($e) => $call,
            AnyEmitter::Environment($e) => $call,
            AnyEmitter::Cap($e) => $call,
        }
    };
}

impl<V: Value> Emitter<V> for AnyEmitter<V> {
    fn radiance(&self) -> V {
        forward!(self, e => e.radiance())
    }

    fn at_infinity(&self) -> bool {
        forward!(self, e => e.at_infinity())
    }

    fn hit(&self, x: Vec3, w: Vec3, t_min: f64) -> Option<EmitterHit<V>> {
        forward!(self, e => e.hit(x, w, t_min))
    }

    fn surface(&self, receiver: &Receiver) -> Result<LightDomain, QuadError> {
        forward!(self, e => e.surface(receiver))
    }

    fn normal_at(&self, y: Vec3) -> Vec3 {
        forward!(self, e => e.normal_at(y))
    }

    fn cone(&self, receiver: &Receiver) -> Result<Cap, QuadError> {
        forward!(self, e => e.cone(receiver))
    }

    fn occluder(&self) -> Option<Occluder> {
        forward!(self, e => e.occluder())
    }
}

macro_rules! from_light {
    ($($ty:ident => $variant:ident),+) => {
        $(impl<V: Value> From<$ty<V>> for AnyEmitter<V> {
            fn from(e: $ty<V>) -> Self {
                AnyEmitter::$variant(e)
            }
        })+
    };
}

from_light!(
    RectangleLight => Rectangle,
    DiskLight => Disk,
    TriangleLight => Triangle,
    SphereLight => Sphere,
    EnvironmentLight => Environment,
    CapLight => Cap
);
