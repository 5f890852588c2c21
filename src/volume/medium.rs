//! Media: scalar density fields `v_r(x) >= 0` whose extinction is
//! `sigma(x) = lambda v_r(x)` (docs/EQUATIONS.md, V-tau).
//!
//! A medium knows where along a ray it can be non-zero and where its density is
//! not smooth, so quadrature only ever sees smooth pieces; it may know its line
//! integral in closed form, and it bounds its density for the tracking
//! estimators.
//!
//! ```
//! use lightquad::domain::Vec3;
//! use lightquad::geometry::Ray;
//! use lightquad::quadrature::GaussLegendre;
//! use lightquad::volume::{ConstantSphere, Medium};
//! use rand::SeedableRng;
//!
//! // The optical depth of any medium by quadrature over the smooth pieces of
//! // its support along a ray, the way every volume term starts.
//! fn depth(m: &dyn Medium, ray: &Ray, rng: &mut rand_pcg::Pcg64) -> Result<f64, lightquad::QuadError> {
//!     let mut total = 0.0;
//!     for piece in m.support(ray, 0.0, f64::INFINITY) {
//!         let est = piece.integrate(&GaussLegendre::default(), 4, rng, |t| m.density(ray.at(t)))?;
//!         total += est.value;
//!     }
//!     Ok(total)
//! }
//! // Density 2 on the chord 2 sqrt(1 - 0.6^2) = 1.6 of a unit sphere: 3.2.
//! let sphere = ConstantSphere::new(Vec3::zeros(), 1.0, 2.0)?;
//! let ray = Ray::new(Vec3::new(-3.0, 0.6, 0.0), Vec3::x())?;
//! let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
//! assert!((depth(&sphere, &ray, &mut rng)? - 3.2).abs() < 1e-14);
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use crate::domain::{Segment, Vec3};
use crate::geometry::Ray;

/// A density field `v_r`.
pub trait Medium: std::fmt::Debug + Send + Sync {
    /// A short name for reports (`constant-sphere`, `gaussian-blobs`, ...).
    fn name(&self) -> &'static str;

    /// The density `v_r(p) >= 0`.
    fn density(&self, p: Vec3) -> f64;

    /// The densities at `points`, into `out` (of the same length): one call
    /// for a batch of look-ups. The provided loop is compiled for each
    /// medium, so `density` is called directly (and can be inlined), and
    /// neighbouring look-ups overlap in the processor instead of each
    /// waiting for a dynamic call.
    fn densities(&self, points: &[Vec3], out: &mut [f64]) {
        for (v, &p) in out.iter_mut().zip(points) {
            *v = self.density(p);
        }
    }

    /// The work of one density lookup, in lookups of a simple field (a
    /// sphere's, a voxel's): a sum of Gaussian blobs costs one per blob. Cost
    /// estimates multiply by it (2000 blobs made each lookup about 17 us, and
    /// a job the guard let through would have run for 19 days).
    fn lookup_work(&self) -> f64 {
        1.0
    }

    /// The density at `p` as the smooth field of the support piece that holds
    /// `inside` (a point strictly inside the piece): the piece's own formula,
    /// extended to and past its ends, so that a node at an end of the piece
    /// (which rounding may put a hair outside a sphere or a box) reads the
    /// one-sided limit, not the other side of a jump. Fields smooth
    /// everywhere keep the default, `density(p)`.
    fn density_on(&self, p: Vec3, _inside: Vec3) -> f64 {
        self.density(p)
    }

    /// The pieces of `[t_min, t_max]` along `ray` where the density can be
    /// non-zero, each cut at the points where the density is not smooth.
    /// Outside them the density is zero (or below 1e-30 of its peak, for
    /// fields that never vanish; the medium says which in its docs).
    fn support(&self, ray: &Ray, t_min: f64, t_max: f64) -> Vec<Segment>;

    /// The ends `(start, end)` of the pieces of [`Medium::support`], without
    /// the cuts inside them: what tracking needs, which draws collisions,
    /// not nodes. Media whose cuts cost more than their ends (a voxel grid
    /// sorts a crossing per voxel-centre plane) answer it directly.
    fn extent(&self, ray: &Ray, t_min: f64, t_max: f64) -> Vec<(f64, f64)> {
        self.support(ray, t_min, t_max)
            .iter()
            .map(|p| (p.start(), p.end()))
            .collect()
    }

    /// An upper bound of the density on `[t0, t1]` along `ray` (a majorant for
    /// delta and ratio tracking).
    fn max_density(&self, ray: &Ray, t0: f64, t1: f64) -> f64;

    /// A lower bound of the density on `[t0, t1]` along `ray`: how soon a
    /// delta-tracking walk must stop, for the estimate of its cost before a
    /// run (an end on the medium's boundary may still read 0 by rounding).
    /// 0, always a bound, unless the medium knows better.
    fn min_density(&self, _ray: &Ray, _t0: f64, _t1: f64) -> f64 {
        0.0
    }

    /// A point the medium lies around (its centre), if it has one: the
    /// scene re-anchors a ray at its closest approach to it before asking for
    /// the support, so a ray from very far away (`|e| = 1e16`, where one ulp
    /// of `t` is longer than the chord) still finds the medium.
    fn centre(&self) -> Option<crate::domain::Vec3> {
        None
    }

    /// The parameters `t` strictly inside `(lo, hi)` where the density crosses
    /// `level`, in closed form, when the medium can invert its density along
    /// a smooth piece `[lo, hi]` of its support (`inside` a point strictly
    /// inside the piece, as for [`Medium::density_on`]). `None`: no closed
    /// form, the caller brackets the crossings numerically. Used to cut V-E
    /// where a transfer function's knots put kinks into `c(v(t))`.
    fn level_crossings(
        &self,
        _ray: &Ray,
        _lo: f64,
        _hi: f64,
        _inside: Vec3,
        _level: f64,
    ) -> Option<Vec<f64>> {
        None
    }

    /// `int_{t0}^{t1} v_r(ray(t)) dt` in closed form, when the medium has one.
    fn density_integral(&self, _ray: &Ray, _t0: f64, _t1: f64) -> Option<f64> {
        None
    }
}

/// Clips `[t_min, t_max]` to `[a, b]`, `None` when empty.
pub fn overlap(t_min: f64, t_max: f64, a: f64, b: f64) -> Option<(f64, f64)> {
    let (lo, hi) = (t_min.max(a), t_max.min(b));
    (lo < hi).then_some((lo, hi))
}
