//! A ray segment `[a, b]` of the ray parameter, with optional break points
//! (medium boundaries, voxel faces) where the integrand is not smooth.
//!
//! ```
//! use lightquad::domain::Segment;
//! use lightquad::quadrature::GaussLegendre;
//! use rand::SeedableRng;
//!
//! // |t - 1| on [0, 3] has a kink at t = 1. Cut there, both pieces are linear,
//! // and 2 Gauss–Legendre nodes per piece are exact: 1/2 + 2 = 5/2.
//! let seg = Segment::with_breaks(0.0, 3.0, vec![1.0])?;
//! assert_eq!(seg.pieces().collect::<Vec<_>>(), [(0.0, 1.0), (1.0, 3.0)]);
//! let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
//! let est = seg.integrate(&GaussLegendre::default(), 2, &mut rng, |t: f64| (t - 1.0).abs())?;
//! assert!((est.value - 2.5).abs() < 1e-15);
//! // Across the kink, the same rule is not exact.
//! let whole = Segment::new(0.0, 3.0)?.integrate(&GaussLegendre::default(), 2, &mut rng, |t: f64| (t - 1.0).abs())?;
//! assert!((whole.value - 2.5).abs() > 0.05);
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use super::Domain;
use crate::error::{QuadError, require_finite};
use crate::estimate::Estimate;
use crate::quadrature::Rule;
use crate::value::Value;

/// The interval `[a, b]`, `a <= b`, cut at sorted interior break points.
#[derive(Debug, Clone, PartialEq)]
pub struct Segment {
    a: f64,
    b: f64,
    breaks: Vec<f64>,
}

impl Segment {
    /// `[a, b]` with no break points; `a <= b`, both finite.
    pub fn new(a: f64, b: f64) -> Result<Self, QuadError> {
        Self::with_breaks(a, b, Vec::new())
    }

    /// `[a, b]` cut at `breaks`; break points outside `(a, b)` are rejected,
    /// duplicates are merged.
    pub fn with_breaks(a: f64, b: f64, mut breaks: Vec<f64>) -> Result<Self, QuadError> {
        require_finite("a", a)?;
        require_finite("b", b)?;
        if b < a {
            return Err(QuadError::invalid(
                "b",
                b,
                format!("b >= a = {a} (a ray segment runs forward)"),
            ));
        }
        // Its length is a factor of every integral over it.
        if !(b - a).is_finite() {
            return Err(QuadError::invalid(
                "b",
                b,
                format!(
                    "a segment from a = {a} whose length b - a is finite in f64 (below about 1.8e308)"
                ),
            ));
        }
        for (i, &t) in breaks.iter().enumerate() {
            if !(t.is_finite() && a < t && t < b) {
                return Err(QuadError::invalid(
                    format!("breaks[{i}]"),
                    t,
                    format!("a finite point strictly inside ({a}, {b})"),
                ));
            }
        }
        breaks.sort_by(f64::total_cmp);
        breaks.dedup();
        Ok(Segment { a, b, breaks })
    }

    /// Start of the segment.
    pub fn start(&self) -> f64 {
        self.a
    }

    /// End of the segment.
    pub fn end(&self) -> f64 {
        self.b
    }

    /// The part `[lo, hi]` of this segment (`a <= lo <= hi <= b`), keeping the
    /// break points inside it.
    pub fn restrict(&self, lo: f64, hi: f64) -> Result<Segment, QuadError> {
        let (lo, hi) = (lo.max(self.a), hi.min(self.b));
        let breaks = self
            .breaks
            .iter()
            .copied()
            .filter(|&t| lo < t && t < hi)
            .collect();
        Segment::with_breaks(lo, hi, breaks)
    }

    /// The interior break points.
    pub fn breaks(&self) -> &[f64] {
        &self.breaks
    }

    /// The midpoint of the smooth piece `[t_i, t_{i+1}]` that holds `x`:
    /// a parameter well inside that piece, where its smooth field can be
    /// told apart from its neighbours' ([`crate::volume::Medium::density_on`]),
    /// also for an `x` in a sub-interval so short that its own midpoint's
    /// point rounds onto the piece's end. `x` on a break point belongs to the
    /// piece above it.
    pub fn smooth_mid(&self, x: f64) -> f64 {
        let i = self.breaks.partition_point(|&b| b <= x);
        let lo = if i == 0 { self.a } else { self.breaks[i - 1] };
        let hi = self.breaks.get(i).copied().unwrap_or(self.b);
        0.5 * (lo + hi)
    }

    /// The smooth pieces `[t_i, t_{i+1}]` between break points (no allocation).
    pub fn pieces(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        let starts = std::iter::once(self.a).chain(self.breaks.iter().copied());
        let ends = self.breaks.iter().copied().chain(std::iter::once(self.b));
        starts.zip(ends)
    }

    /// `int_a^b g(t) dt` as the sum over the smooth pieces, `n` evaluations
    /// budgeted per piece (composite rules are applied piece by piece).
    pub fn integrate<R: Rule, Rg: rand::Rng + ?Sized, V: Value, G: FnMut(f64) -> V>(
        &self,
        rule: &R,
        n: usize,
        rng: &mut Rg,
        mut g: G,
    ) -> Result<Estimate<V>, QuadError> {
        self.try_integrate(rule, n, rng, |t| Ok(g(t)))
    }

    /// [`Segment::integrate`] for an integrand that may fail: its first error
    /// is returned as is.
    pub fn try_integrate<
        R: Rule,
        Rg: rand::Rng + ?Sized,
        V: Value,
        G: FnMut(f64) -> Result<V, QuadError>,
    >(
        &self,
        rule: &R,
        n: usize,
        rng: &mut Rg,
        mut g: G,
    ) -> Result<Estimate<V>, QuadError> {
        self.try_integrate_pieces(rule, n, rng, |t, _| g(t))
    }

    /// [`Segment::try_integrate`] with the integrand told which smooth piece
    /// `t` belongs to (by the piece's midpoint), so it can evaluate that
    /// piece's own smooth formula at the piece's ends.
    pub fn try_integrate_pieces<
        R: Rule,
        Rg: rand::Rng + ?Sized,
        V: Value,
        G: FnMut(f64, f64) -> Result<V, QuadError>,
    >(
        &self,
        rule: &R,
        n: usize,
        rng: &mut Rg,
        mut g: G,
    ) -> Result<Estimate<V>, QuadError> {
        // One piece, the common case: the rule's estimate as it is.
        if self.breaks.is_empty() {
            let mid = 0.5 * (self.a + self.b);
            return super::try_integrate_over(rule, self, n, rng, |t| g(t, mid));
        }
        let mut total = crate::estimate::PieceSum::new(self.breaks.len() + 1);
        for (lo, hi) in self.pieces() {
            let piece = Segment {
                a: lo,
                b: hi,
                breaks: Vec::new(),
            };
            let mid = 0.5 * (lo + hi);
            total.add(super::try_integrate_over(rule, &piece, n, rng, |t| {
                g(t, mid)
            })?);
        }
        total.finish()
    }
}

impl Domain<1> for Segment {
    type Point = f64;

    /// `t = a + (b - a) u`, `|J| = b - a`. Written as `a + L u` near `a` and
    /// `b - L (1 - u)` near `b`, so the map adds no cancellation at either end.
    /// (Unit-interval nodes near 1 are themselves stored as f64 values near 1,
    /// with absolute precision 1e-16; only nodes near 0 keep full relative
    /// precision, see `gauss_legendre::unit_nodes`.)
    fn map(&self, u: [f64; 1]) -> (f64, f64) {
        let len = self.b - self.a;
        let t = if u[0] <= 0.5 {
            self.a + len * u[0]
        } else {
            self.b - len * (1.0 - u[0])
        };
        (t, len)
    }

    fn invert(&self, t: &f64) -> Option<[f64; 1]> {
        let len = self.b - self.a;
        if !(self.a <= *t && *t <= self.b) {
            return None;
        }
        if len <= 0.0 {
            // The empty segment [a, a]: every u maps to a.
            return Some([0.0]);
        }
        Some([((t - self.a) / len).min(1.0)])
    }

    fn measure(&self) -> f64 {
        self.b - self.a
    }
}
