//! A voxel grid over an axis-aligned box, reconstructed by trilinear
//! interpolation of values stored at the voxel centres, as Mitsuba 3's
//! `gridvolume` does (Dr.Jit `Texture3f`, linear filter, `clamp` wrap mode).
//!
//! With `n_k` voxels of size `h_k = (max_k - min_k) / n_k` along axis `k`, the
//! lattice coordinate of a point is `u_k = (x_k - min_k) / h_k - 1/2`, so voxel
//! centre `i` sits at `u_k = i`. With `i_k = floor(u_k)` and `w_k = u_k - i_k`,
//!
//! `v_r(x) = sum_{a,b,c in {0,1}} W_x^a W_y^b W_z^c D[z_c][y_b][x_a]`,
//! `W^0 = 1 - w`, `W^1 = w`, `x_a = clamp(i_x + a, 0, n_x - 1)` (likewise y, z),
//!
//! inside the box and 0 outside it. The clamp makes the field constant across
//! the half-voxel margin between the outermost centres and the box faces (edge
//! values). In Mitsuba the cut-off at the box comes from the medium's bounding
//! shape; the texture itself clamps forever.
//!
//! Along `p + t d` each `u_k` is linear in `t`, and between two consecutive
//! crossings of centre planes `x_k = min_k + (i + 1/2) h_k` (where `i_k` or the
//! clamp changes) the weights are fixed linear functions of `t`: the density
//! is a polynomial of degree at most 3 there, so Gauss–Legendre with 2 nodes
//! per piece integrates it exactly. The support is the ray–box chord cut at
//! those crossings. There is no closed-form line integral
//! ([`Medium::density_integral`] is `None`).
//!
//! ```
//! use lightquad::domain::Vec3;
//! use lightquad::geometry::Ray;
//! use lightquad::quadrature::GaussLegendre;
//! use lightquad::volume::{Medium, VoxelGrid};
//! use rand::SeedableRng;
//!
//! // Two voxels along x over the box [0, 2] x [0, 1] x [0, 1], values 1 and 3
//! // at their centres x = 0.5 and 1.5: the field is 1, then linear 1 -> 3, then 3.
//! let grid = VoxelGrid::new(Vec3::zeros(), Vec3::new(2.0, 1.0, 1.0), [2, 1, 1], vec![1.0, 3.0])?;
//! assert_eq!(grid.density(Vec3::new(1.0, 0.5, 0.5)), 2.0);
//! // Along the box's axis: int v dx = 0.5 * 1 + 1 * 2 + 0.5 * 3 = 4, on three
//! // pieces cut at the centre planes; 2 Gauss–Legendre nodes per piece are exact.
//! let ray = Ray::new(Vec3::new(-1.0, 0.5, 0.5), Vec3::x())?;
//! let pieces = grid.support(&ray, 0.0, f64::INFINITY);
//! assert_eq!(pieces.iter().map(|s| s.pieces().count()).sum::<usize>(), 3);
//! let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
//! let mut depth = 0.0;
//! for s in &pieces {
//!     depth += s.integrate(&GaussLegendre::default(), 2, &mut rng, |t| grid.density(ray.at(t)))?.value;
//! }
//! assert!((depth - 4.0).abs() < 1e-14);
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use super::medium::Medium;
use crate::domain::{Segment, Vec3};
use crate::error::QuadError;
use crate::geometry::{Ray, require_finite_vec};

/// Slack, in lattice units, when bounding the voxels a chord can touch, so a
/// lattice coordinate rounded across an integer still counts its neighbour.
const LATTICE_SLACK: f64 = 1e-9;

/// A scalar voxel grid, values at voxel centres, laid out `[z][y][x]` (x
/// fastest), trilinearly interpolated with edge clamping inside the box.
#[derive(Debug, Clone, PartialEq)]
pub struct VoxelGrid {
    min: Vec3,
    max: Vec3,
    resolution: [usize; 3],
    data: Vec<f64>,
    /// Voxel size `h_k` per axis.
    cell: Vec3,
    /// `1 / h_k` per axis.
    per_cell: Vec3,
    /// The largest value in `data`.
    data_max: f64,
    /// The largest value of each block of `BLOCK^3` voxels (fewer at the
    /// grid's far faces), x fastest, and the blocks per axis.
    block_max: Vec<f64>,
    /// The smallest value of each block, as `block_max`.
    block_min: Vec<f64>,
    blocks: [usize; 3],
}

/// Voxels per block edge of [`VoxelGrid`]'s block maxima.
const BLOCK: usize = 4;

/// `floor(u)`, exact for `|u| < 2^63` (beyond it, the nearest of
/// `+-2^63`; NaN gives 0): the truncation toward zero, one less where that
/// rounded a negative number up. x86-64's baseline has no rounding
/// instruction, so `f64::floor` is a libm call: it was 9% of a
/// ratio-tracking walk through a voxel grid.
fn floor(u: f64) -> f64 {
    let t = (u as i64) as f64;
    if t > u { t - 1.0 } else { t }
}

/// The trilinear interpolation of a voxel's eight corner values `v` (x
/// fastest) at the weights `w` of the upper corner per axis:
/// `lerp(a, b, t) = (1 - t) a + t b` along x, then y, then z.
fn trilinear(v: [f64; 8], w: [f64; 3]) -> f64 {
    let lerp = |a: f64, b: f64, t: f64| (1.0 - t) * a + t * b;
    let row = |c: usize| lerp(v[c], v[c + 1], w[0]);
    let plane = |c: usize| lerp(row(c), row(c + 2), w[1]);
    lerp(plane(0), plane(4), w[2])
}

impl VoxelGrid {
    /// True when `p` is in the closed box.
    fn contains(&self, p: Vec3) -> bool {
        (0..3).all(|k| self.min[k] <= p[k] && p[k] <= self.max[k])
    }

    /// A grid over the box `[min, max]` with `resolution = [n_x, n_y, n_z]`
    /// voxels and `data[(z n_y + y) n_x + x]` the value at the centre of voxel
    /// `(x, y, z)`.
    ///
    /// Checks: `min`, `max` finite with `min < max` componentwise and a
    /// positive finite voxel size (`max[k]` named); every `resolution[k] >= 1`;
    /// `data.len()` equal to the product of the resolution (`data`); every
    /// value finite and >= 0 (`data[i]`).
    pub fn new(
        min: Vec3,
        max: Vec3,
        resolution: [usize; 3],
        data: Vec<f64>,
    ) -> Result<Self, QuadError> {
        require_finite_vec("min", min)?;
        require_finite_vec("max", max)?;
        for (k, &n) in resolution.iter().enumerate() {
            if n == 0 {
                return Err(QuadError::invalid(
                    format!("resolution[{k}]"),
                    n,
                    "a voxel count >= 1",
                ));
            }
        }
        let mut cell = Vec3::zeros();
        for k in 0..3 {
            let width = max[k] - min[k];
            if !(max[k] > min[k] && width.is_finite()) {
                return Err(QuadError::invalid(
                    format!("max[{k}]"),
                    max[k],
                    format!("a number > min[{k}] = {} with a finite box width", min[k]),
                ));
            }
            cell[k] = width / resolution[k] as f64;
            if cell[k] <= 0.0 {
                return Err(QuadError::invalid(
                    format!("max[{k}]"),
                    max[k],
                    format!(
                        "a box width {width} that gives a voxel size > 0 over {} voxels",
                        resolution[k]
                    ),
                ));
            }
        }
        let count = resolution
            .iter()
            .try_fold(1usize, |acc, &n| acc.checked_mul(n));
        match count {
            Some(count) if count == data.len() => {}
            _ => {
                return Err(QuadError::invalid(
                    "data",
                    format!("{} values", data.len()),
                    format!(
                        "resolution[0] * resolution[1] * resolution[2] = {} * {} * {} values",
                        resolution[0], resolution[1], resolution[2]
                    ),
                ));
            }
        }
        let mut data_max: f64 = 0.0;
        for (i, &v) in data.iter().enumerate() {
            if !(v.is_finite() && v >= 0.0) {
                return Err(QuadError::invalid(
                    format!("data[{i}]"),
                    v,
                    "a finite density >= 0",
                ));
            }
            data_max = data_max.max(v);
        }
        let blocks = resolution.map(|n| n.div_ceil(BLOCK));
        let mut block_max = vec![0.0f64; blocks.iter().product()];
        let mut block_min = vec![f64::INFINITY; blocks.iter().product()];
        for (i, &v) in data.iter().enumerate() {
            let (x, y, z) = (
                i % resolution[0],
                i / resolution[0] % resolution[1],
                i / (resolution[0] * resolution[1]),
            );
            let b = ((z / BLOCK) * blocks[1] + y / BLOCK) * blocks[0] + x / BLOCK;
            if let Some(m) = block_max.get_mut(b) {
                *m = m.max(v);
            }
            if let Some(m) = block_min.get_mut(b) {
                *m = m.min(v);
            }
        }
        Ok(VoxelGrid {
            min,
            max,
            resolution,
            data,
            cell,
            per_cell: cell.map(|h| 1.0 / h),
            data_max,
            block_max,
            block_min,
            blocks,
        })
    }

    /// The box's lower corner.
    pub fn min(&self) -> Vec3 {
        self.min
    }

    /// The box's upper corner.
    pub fn max(&self) -> Vec3 {
        self.max
    }

    /// Voxels per axis `[n_x, n_y, n_z]`.
    pub fn resolution(&self) -> [usize; 3] {
        self.resolution
    }

    /// The values, `[z][y][x]`, x fastest.
    pub fn data(&self) -> &[f64] {
        &self.data
    }

    /// The voxel size `h_k = (max_k - min_k) / n_k` per axis.
    pub fn cell(&self) -> Vec3 {
        self.cell
    }

    /// The value at voxel `(x, y, z)` (indices already clamped).
    fn value(&self, x: usize, y: usize, z: usize) -> f64 {
        let [nx, ny, _] = self.resolution;
        self.data.get((z * ny + y) * nx + x).copied().unwrap_or(0.0)
    }

    /// The lattice coordinate `u_k = (x_k - min_k) / h_k - 1/2` (times the
    /// stored `1 / h_k`: a division was a fifth of a look-up; the product is
    /// within an ulp or two of the quotient, and the interpolation is
    /// continuous across the voxel-centre planes where `floor(u)` changes).
    fn lattice(&self, p: Vec3, k: usize) -> f64 {
        (p[k] - self.min[k]) * self.per_cell[k] - 0.5
    }

    /// [`Medium::density`] at `p` outside the box of the outer voxel
    /// centres, `u` its lattice coordinate: out of line, so that the common
    /// case inside that box is a short call (and marked cold: it is the
    /// half-voxel margin, about 9% of a 32^3 grid's box and less of finer
    /// ones).
    #[cold]
    #[inline(never)]
    fn density_near_faces(&self, p: Vec3, u: [f64; 3]) -> f64 {
        let [nx, ny, _] = self.resolution;
        let stride = [1, nx, nx * ny];
        if !self.contains(p) {
            return 0.0;
        }
        // Near a face: the two indices around `u` clamp to the grid (the
        // field is constant beyond the outer voxel centres). Inside the box
        // `u` is in [-1/2, n - 1/2], so `floor(u)` converts exactly.
        let f = u.map(|u| floor(u) as i64);
        let w: [f64; 3] = std::array::from_fn(|k| u[k] - f[k] as f64);
        let index =
            |k: usize, i: i64| i.clamp(0, self.resolution[k] as i64 - 1) as usize * stride[k];
        let pair = |k: usize| [index(k, f[k]), index(k, f[k] + 1)];
        let [x, y, z] = [pair(0), pair(1), pair(2)];
        let at = |i: usize| self.data.get(i).copied().unwrap_or(0.0);
        let v = std::array::from_fn(|c| at(x[c & 1] + y[(c >> 1) & 1] + z[c >> 2]));
        trilinear(v, w)
    }

    /// `clamp(floor(u), 0, n - 1)` as an index.
    fn clamp_index(u: f64, n: usize) -> usize {
        // In range after the clamp, so the cast is exact.
        floor(u).clamp(0.0, (n - 1) as f64) as usize
    }

    /// The ray–box chord inside `[t_min, t_max]` by the slab method. An axis
    /// the ray is parallel to constrains nothing when the origin lies within
    /// the slab (faces included) and empties the chord otherwise, so no
    /// `0 * inf` is ever formed.
    pub fn chord(&self, ray: &Ray, t_min: f64, t_max: f64) -> Option<(f64, f64)> {
        let (mut lo, mut hi) = (t_min, t_max);
        for k in 0..3 {
            let (o, d) = (ray.origin[k], ray.dir[k]);
            if d == 0.0 {
                if o < self.min[k] || o > self.max[k] {
                    return None;
                }
                continue;
            }
            let (ta, tb) = ((self.min[k] - o) / d, (self.max[k] - o) / d);
            let (near, far) = if ta <= tb { (ta, tb) } else { (tb, ta) };
            lo = lo.max(near);
            hi = hi.min(far);
        }
        (lo < hi).then_some((lo, hi))
    }
}

impl Medium for VoxelGrid {
    fn name(&self) -> &'static str {
        "voxel-grid"
    }

    /// A trilinear lookup reads eight voxels and weighs them: about four
    /// lookups of a simple field (the nested scheme at 2000 voxels along the
    /// ray ran at 93 ns an evaluation, a constant sphere at 21 to 43; 20000
    /// voxels at 12 repeats passed the guard as 8e11 evaluations and would
    /// have run for about five hours).
    fn lookup_work(&self) -> f64 {
        4.0
    }

    /// The trilinear reconstruction with edge clamping inside the box (faces
    /// included), 0 outside.
    /// Inside the box, the interpolation at `p` moved onto the box: beyond a
    /// face the clamped stencil is constant along its normal, so this is the
    /// field's own extension there.
    fn density_on(&self, p: Vec3, inside: Vec3) -> f64 {
        if !self.contains(inside) {
            return 0.0;
        }
        let clamped = Vec3::from_fn(|k, _| p[k].clamp(self.min[k], self.max[k]));
        self.density(clamped)
    }

    fn density(&self, p: Vec3) -> f64 {
        let [nx, ny, _] = self.resolution;
        let stride = [1, nx, nx * ny];
        // Per axis the lattice coordinate `u` (voxel centres at integers).
        let u: [f64; 3] = std::array::from_fn(|k| self.lattice(p, k));
        // Between the outer voxel centres on every axis (NaN is not) all
        // eight neighbours are in the grid: the truncation is the floor, and
        // the lower and upper planes' two rows are two slices of `data`
        // from the lower corner, of known length (no more checks).
        // (Signed integers: x86-64 converts them to and from floats in one
        // instruction each, unsigned ones in several.)
        if (0..3).all(|k| 0.0 <= u[k] && u[k] < (self.resolution[k] as i64 - 1) as f64) {
            let f = u.map(|u| u as i64);
            let w: [f64; 3] = std::array::from_fn(|k| u[k] - f[k] as f64);
            let base: usize = (0..3).map(|k| f[k] as usize * stride[k]).sum();
            let sy = stride[1];
            let plane = |start: usize| self.data.get(start..)?.get(..sy + 2);
            let (Some(lo), Some(hi)) = (plane(base), plane(base + stride[2])) else {
                return 0.0;
            };
            let v = [
                lo[0],
                lo[1],
                lo[sy],
                lo[sy + 1],
                hi[0],
                hi[1],
                hi[sy],
                hi[sy + 1],
            ];
            return trilinear(v, w);
        }
        self.density_near_faces(p, u)
    }

    /// The ray–box chord, cut at every crossing of a voxel-centre plane
    /// `x_k = min_k + (i + 1/2) h_k` strictly inside it (axes with one voxel
    /// have none: the field is constant along them). Between the cuts the
    /// density is a cubic in `t`.
    fn support(&self, ray: &Ray, t_min: f64, t_max: f64) -> Vec<Segment> {
        let Some((a, b)) = self.chord(ray, t_min, t_max) else {
            return Vec::new();
        };
        let mut breaks = Vec::new();
        for k in 0..3 {
            let (o, d, n) = (ray.origin[k], ray.dir[k], self.resolution[k]);
            if d == 0.0 || n == 1 {
                continue;
            }
            breaks.extend(
                (0..n)
                    .map(|i| (self.min[k] + (i as f64 + 0.5) * self.cell[k] - o) / d)
                    .filter(|&t| a < t && t < b),
            );
        }
        Segment::with_breaks(a, b, breaks)
            .ok()
            .into_iter()
            .collect()
    }

    /// The chord: one piece, whose cuts tracking does not need.
    fn extent(&self, ray: &Ray, t_min: f64, t_max: f64) -> Vec<(f64, f64)> {
        self.chord(ray, t_min, t_max).into_iter().collect()
    }

    fn centre(&self) -> Option<Vec3> {
        Some((self.min + self.max) * 0.5)
    }

    /// The largest value over the voxels whose interpolation stencils the
    /// chord inside `[t0, t1]` can reach (`VoxelGrid::stencil_box`), not
    /// the global maximum. Times `1 + 8 eps` for the rounding of the
    /// interpolation weights; 0 where the ray misses the box.
    fn max_density(&self, ray: &Ray, t0: f64, t1: f64) -> f64 {
        let Some((lo, hi)) = self.stencil_box(ray, t0, t1) else {
            return 0.0;
        };
        let whole = (0..3).all(|k| lo[k] == 0 && hi[k] + 1 == self.resolution[k]);
        let peak = if whole {
            self.data_max
        } else {
            self.fold_box(lo, hi, &self.block_max, (0.0, f64::INFINITY), f64::max)
        };
        peak * (1.0 + 8.0 * f64::EPSILON)
    }

    /// The smallest value over the same voxels (an interpolated value is a
    /// weighted mean of its stencil's), times `1 - 8 eps`, where `[t0, t1]`
    /// lies inside the box; else 0. (An end on a face may round to a point
    /// outside, density 0: a bound for the walks' cost, not for a look-up
    /// there.)
    fn min_density(&self, ray: &Ray, t0: f64, t1: f64) -> f64 {
        if self.chord(ray, t0, t1) != Some((t0, t1)) {
            return 0.0;
        }
        let Some((lo, hi)) = self.stencil_box(ray, t0, t1) else {
            return 0.0;
        };
        self.fold_box(lo, hi, &self.block_min, (f64::INFINITY, 0.0), f64::min)
            * (1.0 - 8.0 * f64::EPSILON)
    }
}

impl VoxelGrid {
    /// The index box of the voxels whose interpolation stencils the chord
    /// inside `[t0, t1]` can reach: spanned by the chord's end points, each
    /// widened to the neighbouring centre; `None` where the ray misses the
    /// box.
    fn stencil_box(&self, ray: &Ray, t0: f64, t1: f64) -> Option<([usize; 3], [usize; 3])> {
        let (a, b) = self.chord(ray, t0, t1)?;
        let (pa, pb) = (ray.at(a), ray.at(b));
        let mut lo = [0usize; 3];
        let mut hi = [0usize; 3];
        for k in 0..3 {
            let n = self.resolution[k];
            let (ua, ub) = (self.lattice(pa, k), self.lattice(pb, k));
            lo[k] = Self::clamp_index(ua.min(ub) - LATTICE_SLACK, n);
            hi[k] = Self::clamp_index(ua.max(ub) + LATTICE_SLACK + 1.0, n);
        }
        Some((lo, hi))
    }

    /// `f` folded from `init` over the values of the voxels in the index box
    /// `lo..=hi`; where it has more than 64 voxels (a long span, a shadow
    /// ray's), over `blocks`' values of the blocks of 4^3 voxels that hold it
    /// instead: a few reads instead of hundreds, and a bound no less safe (it
    /// may take in voxels just outside the box, so it is looser). A block
    /// past the table (which cannot happen) counts as `missing`.
    fn fold_box(
        &self,
        lo: [usize; 3],
        hi: [usize; 3],
        blocks: &[f64],
        (init, missing): (f64, f64),
        f: impl Fn(f64, f64) -> f64,
    ) -> f64 {
        let voxels: usize = (0..3).map(|k| hi[k] + 1 - lo[k]).product();
        let mut m = init;
        if voxels > BLOCK * BLOCK * BLOCK {
            let [bx, by, _] = self.blocks;
            for z in lo[2] / BLOCK..=hi[2] / BLOCK {
                for y in lo[1] / BLOCK..=hi[1] / BLOCK {
                    for x in lo[0] / BLOCK..=hi[0] / BLOCK {
                        let b = (z * by + y) * bx + x;
                        m = f(m, blocks.get(b).copied().unwrap_or(missing));
                    }
                }
            }
        } else {
            for z in lo[2]..=hi[2] {
                for y in lo[1]..=hi[1] {
                    for x in lo[0]..=hi[0] {
                        m = f(m, self.value(x, y, z));
                    }
                }
            }
        }
        m
    }
}

#[cfg(test)]
mod tests {
    use super::floor;

    #[test]
    fn floor_is_the_librarys_in_range_and_saturates_beyond() {
        let big = 2f64.powi(62) + 2048.0;
        for u in [
            -1.5,
            -1.0,
            -0.5,
            -1e-300,
            -0.0,
            0.0,
            1e-300,
            0.5,
            1.0,
            2.999,
            1e15 + 0.5,
            -1e15 - 0.5,
            big,
            -big,
        ] {
            assert_eq!(floor(u), u.floor(), "floor({u})");
        }
        assert_eq!(floor(1e300), 2f64.powi(63));
        assert_eq!(floor(-1e300), -(2f64.powi(63)));
        assert_eq!(floor(f64::NAN), 0.0);
    }
}
