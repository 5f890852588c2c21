//! Volume rendering with a directional light (docs/EQUATIONS.md, V-tau .. V-I):
//! media as density fields, the terms along an eye ray with any
//! rule, closed forms in [`crate::exact`], the document's printed formulas in
//! [`audit`], and the stochastic estimators renderers use (tracking).
//!
//! ```
//! use std::sync::Arc;
//! use lightquad::domain::Vec3;
//! use lightquad::geometry::Ray;
//! use lightquad::quadrature::GaussLegendre;
//! use lightquad::volume::{ConstantSphere, DepthScheme, ShadowMethod, VolumeScene, evaluate};
//! use rand::SeedableRng;
//!
//! // Transmittance through the diameter of a unit sphere of density 0.5:
//! // tau = exp(-0.5 * 2).
//! let mut scene = VolumeScene::new(Ray::new(Vec3::new(-3.0, 0.0, 0.0), Vec3::x())?);
//! scene.medium = Some(Arc::new(ConstantSphere::new(Vec3::zeros(), 1.0, 0.5)?));
//! let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
//! let r = evaluate(&scene, &GaussLegendre::default(), 8, DepthScheme::Cumulative,
//!                  ShadowMethod::ClosedFormWhereAvailable, &mut rng)?;
//! assert!((r.transmittance - (-1.0f64).exp()).abs() < 1e-15);
//! # Ok::<(), lightquad::QuadError>(())
//! ```

pub mod audit;
pub mod constant_sphere;
pub mod experiment;
pub mod gaussian_blobs;
pub mod linear_gradient;
pub mod medium;
pub mod printed;
pub mod scene;
pub mod terms;
pub mod tracking;
pub mod voxel_grid;

pub use constant_sphere::ConstantSphere;
pub use gaussian_blobs::{GaussianBlob, GaussianBlobs};
pub use linear_gradient::LinearGradient;
pub use medium::Medium;
pub use scene::{DirectionalLight, EmissionMap, TransferTable, VolumeScene};
pub use terms::{DepthScheme, ShadowMethod, Term, VolumeResult, evaluate};
pub use voxel_grid::VoxelGrid;
