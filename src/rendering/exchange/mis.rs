//! Multiple importance sampling for the exchange family: per unit of
//! budget, a receiver point `x = map(u)` for a uniform `u`, and at `x` one
//! light sample and one cosine (white Lambertian BRDF) sample combined by
//! Veach's heuristic ([`crate::rendering::mis::mis_sample`]), whose score
//! is an unbiased estimate of the irradiance `E(x)`. With the map's
//! Jacobian, `E(x) |J(u)| / A_r` has mean `E_mean`; `Phi = A_r E_mean`, and
//! `F` is `E_mean / pi` of the scene with every light's radiance 1.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::domain::Domain;
use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::family;
use crate::quadrature::monte_carlo::Welford;
use crate::rendering::brdf::Lambert;
use crate::rendering::emitter::LightSampling;
use crate::rendering::forms::Reflected;
use crate::rendering::mis::{Heuristic, mis_sample};
use crate::rendering::receiver::Receiver;
use crate::rendering::scene::Scene;

use super::forms::ExchangeForm;
use super::{Built, ExchangeQuantity, Measure};

/// The family's estimators beside the rules.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "rule", rename_all = "kebab-case")]
pub enum ExchangeMis {
    /// Veach's balance heuristic.
    MisBalance,
    /// Veach's power heuristic (`beta = 2`).
    MisPower,
}

impl family::Estimator for ExchangeMis {
    fn name(&self) -> &'static str {
        match self {
            ExchangeMis::MisBalance => "mis-balance",
            ExchangeMis::MisPower => "mis-power",
        }
    }
    fn about(&self) -> &'static str {
        match self {
            ExchangeMis::MisBalance => {
                "multiple importance sampling, balance heuristic: per unit of budget a uniform \
                 receiver point, a light sample there (by area for the _area quantities, in its \
                 cone for the _cone ones) and a cosine sample; standard error"
            }
            ExchangeMis::MisPower => {
                "multiple importance sampling, power heuristic (beta = 2): per unit of budget a \
                 uniform receiver point, a light sample there (by area for the _area \
                 quantities, in its cone for the _cone ones) and a cosine sample; standard error"
            }
        }
    }
    /// Two samples: a standard error needs them.
    fn min_budget(&self) -> usize {
        2
    }
    fn is_random(&self) -> bool {
        true
    }
    fn all() -> Vec<Self> {
        vec![ExchangeMis::MisBalance, ExchangeMis::MisPower]
    }
}

impl ExchangeMis {
    fn heuristic(&self) -> Heuristic {
        match self {
            ExchangeMis::MisBalance => Heuristic::Balance,
            ExchangeMis::MisPower => Heuristic::Power,
        }
    }
}

/// `q` by `mis` with `n` receiver points (module documentation).
pub(super) fn by_mis(
    built: &Built,
    mis: ExchangeMis,
    n: usize,
    rng: &mut rand_pcg::Pcg64,
    q: ExchangeQuantity,
) -> Result<Estimate<f64>, QuadError> {
    use rand::RngExt;
    let sampling = match q.form() {
        ExchangeForm::Area => LightSampling::Area,
        ExchangeForm::Cone => LightSampling::Cone,
        ExchangeForm::Contour => {
            return Err(QuadError::invalid(
                "quantity",
                family::Quantity::name(&q),
                "an _area or _cone quantity for MIS (its light strategy is the form)",
            ));
        }
    };
    if n < 2 {
        return Err(QuadError::invalid("n", n, "at least 2 samples"));
    }
    let unit = q.measure() == Measure::FormFactor;
    let scene = if unit {
        unit_radiance(&built.scene)
    } else {
        built.scene.clone()
    };
    let (surface, area) = (&built.receiver, built.receiver.area());
    let white = Lambert::new(1.0)?;
    let mut acc = Welford::<f64>::default();
    let mut evaluations = 0;
    for _ in 0..n {
        let (x, jacobian) = surface.map([rng.random::<f64>(), rng.random::<f64>()]);
        let receiver = Receiver::new(x, surface.normal())?;
        let kernel = Reflected::new(&white, &receiver, surface.normal())?;
        let (score, spent) =
            mis_sample(&scene, &receiver, &kernel, sampling, mis.heuristic(), rng)?;
        evaluations += spent;
        acc.add(std::f64::consts::PI * score * jacobian / area);
    }
    let scale = match q.measure() {
        Measure::FormFactor => 1.0 / std::f64::consts::PI,
        Measure::Flux => area,
        Measure::MeanIrradiance => 1.0,
    };
    let estimate = Estimate::random(acc.mean(), acc.interval_error(), evaluations).scaled(scale);
    Ok(if acc.doubtful() {
        estimate.doubted()
    } else {
        estimate
    })
}

/// The scene with every light's radiance 1 (for the form factor).
fn unit_radiance(scene: &Scene<f64>) -> Scene<f64> {
    (0..scene.emitters().len()).fold(scene.clone(), |s, k| s.with_radiance(k, 1.0))
}
