//! The rendering-equation family (`R-*` in docs/EQUATIONS.md): BRDFs,
//! emitters and occluders, and the hemispherical (R-H) and area (R-A)
//! forms of reflected radiance and irradiance at a point.
//!
//! | module | what |
//! |---|---|
//! | [`brdf`] | `f_r` with sampling, pdf and inverse (Lambert, Phong, normalised Phong, GGX) |
//! | [`emitter`] | Lambertian rectangle, disk, triangle and sphere lights, a uniform environment, a cap light; ray hits, surface maps, light sampling |
//! | [`occluder`] | opaque spheres, disks, rectangles, triangles and their ray intersection |
//! | [`order`] | which of two shapes every ray from a point meets first, where that holds for all rays |
//! | [`receiver`] | the point `x` with its normal where `E` and `L_r` are evaluated |
//! | [`scene`] | incident radiance `L_i(x, w)` and visibility `V(x, y)` |
//! | [`forms`] | R-H and R-A integrands for any rule, over the hemisphere, a BRDF-sampled map, emitter cones and emitter surfaces |
//! | [`mis`] | multiple importance sampling of light and BRDF samples (balance, power heuristics) |
//! | [`arcs`] | the exact arcs of a great half-circle of directions that a shape, a cone or a half-space covers (pieces on which visibility is constant) |
//! | [`cap`] | spherical caps and cones of directions given by `1 - cos theta_max` |
//! | [`exchange`] | light between two surfaces: form factor, flux and mean irradiance of a receiving patch (R-3P, R-A over both surfaces) |
//! | [`furnace`] | the full equation in a closed scene (an integrating sphere, the white furnace): Neumann series bounce by bounce and path tracing with Russian roulette |
//! | [`experiment`] | the family of the experiment layer (`"family": "rendering"`): scene format, quantities by form, MIS estimators, closed forms, converged reference |
//!
//! Closed forms live in [`crate::exact::rendering`].

pub mod arcs;
pub mod audit;
pub mod blocked;
pub mod brdf;
pub mod cap;
pub mod clipped;
pub mod closed;
pub mod emitter;
pub mod exchange;
pub mod experiment;
pub mod forms;
pub mod furnace;
pub mod mis;
pub mod occluder;
pub mod order;
pub mod receiver;
pub mod scene;
