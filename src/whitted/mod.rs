//! Whitted ray tracing (`W-*` in docs/EQUATIONS.md): the illumination model
//! W-6.1 with the Phong term (W-Phong), recursive reflection and refraction,
//! and the pixel as an integral over its square, estimated by supersampling
//! (W-SS), by Whitted's shared corner rays (W-Corner) and by any rule of the
//! core; 8-bit images by W-Grey.
//!
//! | module | what |
//! |---|---|
//! | [`scene`] | spheres, planes, triangles with materials (`k_a`, `k_d`, `k_s`, `k_t`, Phong `n`, index of refraction, colour); point and directional lights; ambient; a pinhole camera |
//! | [`intersect`] | ray–object intersection robust at grazing incidence, spawn offsets from floating-point error bounds (as pbrt-v4) |
//! | [`shade`] | W-6.1 and W-Phong with shadow rays, reflection, refraction (Snell, total internal reflection) to a maximum depth; rays counted by kind |
//! | [`pixel`] | the pixel value by the centre ray, W-SS's grid, any core rule (jittered, scrambled Sobol'), W-Corner, adaptive subdivision |
//! | [`coverage`] | the exact fraction of a pixel inside a half-plane or convex polygon, by clipping |
//! | [`pieces`] | a pixel cut along the scene's outlines on the film, each piece integrated by a rule (the converged reference) |
//! | [`image`] | PNG (W-Grey, 8 bits) and PFM output, error heat maps |
//! | [`render`] | images and pixels of a scene by a scheme, with the rays they traced |
//! | [`experiment`] | the family of the experiment layer (`"family": "whitted"`) |

pub mod coverage;
pub mod experiment;
pub mod image;
pub mod intersect;
pub mod pieces;
pub mod pixel;
pub mod render;
pub mod scene;
pub mod shade;
