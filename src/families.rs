//! The registry of equation families: the one place in the crate that names
//! them. An experiment file picks one with `"family": "<name>"`.
//!
//! ```
//! let registry = lightquad::families::builtin();
//! let names: Vec<&str> = registry.entries().iter().map(|f| f.name).collect();
//! assert_eq!(names, ["calibration", "volume", "rendering", "whitted", "furnace", "exchange", "integral"]);
//! assert!(registry.get("volume").expect("registered").quantities().contains(&"tau"));
//! ```

use crate::experiment::Registry;

/// Every family this crate ships, in listing order. Adding a family is its
/// module and one line here.
pub fn builtin() -> Registry {
    Registry::new()
        .with::<crate::calibration::Calibration>()
        .with::<crate::volume::experiment::Volume>()
        .with::<crate::rendering::experiment::Rendering>()
        .with::<crate::whitted::experiment::Whitted>()
        .with::<crate::rendering::closed::Furnace>()
        .with::<crate::rendering::exchange::Exchange>()
        .with::<crate::integral::Integral>()
}

#[cfg(test)]
mod tests {
    use crate::family::{Estimator, Family, Quantity};
    use crate::quadrature::AnyRule;

    /// A family's names agree with its serde forms (results and reports use
    /// `name()`, experiment files the serde form), and no estimator hides a rule.
    fn names_agree<F: Family>() -> Result<(), serde_json::Error> {
        for q in F::Quantity::all() {
            assert_eq!(serde_json::to_value(q)?, q.name(), "{} quantity", F::NAME);
        }
        let rules: Vec<&str> = AnyRule::listing().iter().map(|r| r.0).collect();
        for e in F::Estimator::all() {
            assert_eq!(serde_json::to_value(&e)?["rule"], e.name(), "{}", F::NAME);
            assert!(!rules.contains(&e.name()), "{} hides a rule", e.name());
        }
        Ok(())
    }

    #[test]
    fn every_builtin_familys_names_agree_with_its_serde_forms() -> Result<(), serde_json::Error> {
        names_agree::<crate::calibration::Calibration>()?;
        names_agree::<crate::volume::experiment::Volume>()?;
        names_agree::<crate::rendering::experiment::Rendering>()?;
        names_agree::<crate::whitted::experiment::Whitted>()?;
        names_agree::<crate::rendering::closed::Furnace>()?;
        names_agree::<crate::rendering::exchange::Exchange>()?;
        names_agree::<crate::integral::Integral>()?;
        // Every family listed above is the registry's.
        assert_eq!(
            super::builtin()
                .entries()
                .iter()
                .map(|e| e.name)
                .collect::<Vec<_>>(),
            [
                "calibration",
                "volume",
                "rendering",
                "whitted",
                "furnace",
                "exchange",
                "integral"
            ]
        );
        Ok(())
    }
}
