//! The receiving surface of the exchange family: a one-sided planar patch
//! (parallelogram, disk or triangle) that receives light on the side of its
//! normal, through the same maps of the unit square as the emitters'
//! surfaces ([`crate::domain`]).

use crate::domain::{Disk, Domain, Rectangle, Triangle, Vec3};
use crate::rendering::emitter::AnyEmitter;

/// A receiving patch: `edge_u x edge_v` is a parallelogram's normal,
/// `(b - a) x (c - a)` a triangle's, `normal` a disk's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Surface {
    /// A parallelogram, `|J| = |e_1 x e_2|`.
    Rectangle(Rectangle),
    /// A disk, polar map, `|J| = 2 pi R^2 u_1`.
    Disk(Disk),
    /// A triangle, Duffy map, `|J| = 2 A u_1`.
    Triangle(Triangle),
}

impl Surface {
    /// The surface of a rectangle, disk or triangle light (`None` for the
    /// other lights): its map, normal and corners.
    pub fn of_light(e: &AnyEmitter<f64>) -> Option<Surface> {
        Some(match e {
            AnyEmitter::Rectangle(r) => Surface::Rectangle(*r.shape()),
            AnyEmitter::Disk(d) => Surface::Disk(*d.shape()),
            AnyEmitter::Triangle(t) => Surface::Triangle(*t.shape()),
            _ => return None,
        })
    }

    /// The unit normal of the receiving side.
    pub fn normal(&self) -> Vec3 {
        match self {
            Surface::Rectangle(r) => r.normal(),
            Surface::Disk(d) => d.frame().n,
            Surface::Triangle(t) => t.normal(),
        }
    }

    /// The centroid.
    pub fn centre(&self) -> Vec3 {
        match self {
            Surface::Rectangle(r) => r.origin() + (r.edge_u() + r.edge_v()) * 0.5,
            Surface::Disk(d) => d.centre(),
            Surface::Triangle(t) => t.vertices().iter().sum::<Vec3>() / 3.0,
        }
    }

    /// The area.
    pub fn area(&self) -> f64 {
        self.measure()
    }

    /// The corners in order about the normal, for a polygon.
    pub fn corners(&self) -> Option<Vec<Vec3>> {
        match self {
            Surface::Rectangle(r) => {
                let (o, a, b) = (r.origin(), r.edge_u(), r.edge_v());
                Some(vec![o, o + a, o + a + b, o + b])
            }
            Surface::Triangle(t) => Some(t.vertices().to_vec()),
            Surface::Disk(_) => None,
        }
    }

    /// The largest and smallest signed distance of the surface's points
    /// from the plane through `p` with unit normal `n`.
    pub fn span_along(&self, p: Vec3, n: Vec3) -> (f64, f64) {
        match self.corners() {
            Some(cs) => cs
                .iter()
                .fold((f64::NEG_INFINITY, f64::INFINITY), |(hi, lo), c| {
                    let s = n.dot(&(c - p));
                    (hi.max(s), lo.min(s))
                }),
            None => {
                let Surface::Disk(d) = self else {
                    return (f64::NAN, f64::NAN);
                };
                let s = n.dot(&(d.centre() - p));
                let tilt = n.cross(&d.frame().n).norm() * d.radius();
                (s + tilt, s - tilt)
            }
        }
    }
}

impl Domain<2> for Surface {
    type Point = Vec3;

    fn map(&self, u: [f64; 2]) -> (Vec3, f64) {
        match self {
            Surface::Rectangle(d) => d.map(u),
            Surface::Disk(d) => d.map(u),
            Surface::Triangle(d) => d.map(u),
        }
    }

    fn invert(&self, p: &Vec3) -> Option<[f64; 2]> {
        match self {
            Surface::Rectangle(d) => d.invert(p),
            Surface::Disk(d) => d.invert(p),
            Surface::Triangle(d) => d.invert(p),
        }
    }

    fn measure(&self) -> f64 {
        match self {
            Surface::Rectangle(d) => d.measure(),
            Surface::Disk(d) => d.measure(),
            Surface::Triangle(d) => d.measure(),
        }
    }
}
