//! The registry of equation families: the one place in the crate that names
//! them. An experiment file picks one with `"family": "<name>"`.

use crate::experiment::Registry;

/// Every family this crate ships, in listing order. Adding a family is its
/// module and one line here.
pub fn builtin() -> Registry {
    Registry::new()
        .with::<crate::calibration::Calibration>()
        .with::<crate::volume::experiment::Volume>()
}
