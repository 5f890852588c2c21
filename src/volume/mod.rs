//! Volume rendering with a directional light (docs/EQUATIONS.md, V-tau .. V-I):
//! media as density fields, the terms along an eye ray with any
//! rule, closed forms in [`crate::exact`], the document's printed formulas in
//! [`audit`], and the stochastic estimators renderers use (tracking).

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
