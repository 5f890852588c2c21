//! [`AnyRule`]: any rule selected at run time, by name or by its serde
//! form, products included, and [`BaseRule::by_name`], which it builds on.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::value::Value;

use super::{AnyRuleSpec, BaseRule, Dimensions, Product, Rule, RuleVisitor};

/// Any rule selected at run time, products included. Its serde form is a
/// single rule's, or `{"rule": "product", "outer": {..}, "inner": {..}}`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(from = "AnyRuleSpec", into = "AnyRuleSpec")]
pub enum AnyRule {
    /// One rule.
    Base(BaseRule),
    /// The [`Product`] of two rules (kept apart from [`BaseRule`] so a product
    /// of products, which the type system could not bound, cannot be named).
    Product(Box<Product<BaseRule, BaseRule>>),
}

impl JsonSchema for AnyRule {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        AnyRuleSpec::schema_name()
    }
    fn json_schema(generator: &mut schemars::SchemaGenerator) -> schemars::Schema {
        AnyRuleSpec::json_schema(generator)
    }
}

impl BaseRule {
    /// The rule named `name` with its default parameters.
    pub fn by_name(name: &str) -> Result<BaseRule, QuadError> {
        serde_json::from_value(serde_json::json!({ "rule": name.trim() })).map_err(|_| {
            QuadError::UnknownRule {
                name: name.trim().to_string(),
                known: BaseRule::defaults()
                    .iter()
                    .map(Rule::name)
                    .collect::<Vec<_>>()
                    .join(", "),
            }
        })
    }
}

impl AnyRule {
    /// Runs `visitor` with the concrete rule (see [`RuleVisitor`]); a product
    /// is visited as itself, its two rules taking the integrand as a trait
    /// object.
    pub fn visit<V: RuleVisitor>(&self, visitor: V) -> V::Output {
        match self {
            AnyRule::Base(r) => r.visit(visitor),
            AnyRule::Product(p) => visitor.visit(p.as_ref()),
        }
    }

    /// The rule named `name` with its default parameters; `product(A,B)` names
    /// the iterated product of two named rules.
    pub fn by_name(name: &str) -> Result<AnyRule, QuadError> {
        let name = name.trim();
        if let Some(args) = name
            .strip_prefix("product(")
            .and_then(|rest| rest.strip_suffix(')'))
        {
            let Some((outer, inner)) = split_top_level_comma(args) else {
                return Err(QuadError::invalid(
                    "rule",
                    name,
                    "product(A,B) with two rule names, e.g. product(gauss-legendre,trapezoid)",
                ));
            };
            return Ok(AnyRule::Product(Box::new(Product {
                outer: BaseRule::by_name(outer)?,
                inner: BaseRule::by_name(inner)?,
            })));
        }
        BaseRule::by_name(name).map(AnyRule::Base)
    }

    /// The rule's name, with its factors for a product:
    /// `product(gauss-legendre,trapezoid)`.
    pub fn label(&self) -> String {
        match self {
            AnyRule::Base(r) => r.name().to_string(),
            AnyRule::Product(p) => format!("product({},{})", p.outer.name(), p.inner.name()),
        }
    }

    /// Every rule's name and one line about it, products last (for `lightquad rules`).
    pub fn listing() -> Vec<(&'static str, &'static str)> {
        let mut lines: Vec<(&'static str, &'static str)> = BaseRule::defaults()
            .iter()
            .map(|r| (r.name(), r.about()))
            .collect();
        lines.push((
            "product",
            "2-D iterated rule of two 1-D rules: {\"rule\": \"product\", \"outer\": {..}, \"inner\": {..}}",
        ));
        lines
    }
}

impl From<BaseRule> for AnyRule {
    fn from(rule: BaseRule) -> Self {
        AnyRule::Base(rule)
    }
}

impl Rule for AnyRule {
    fn name(&self) -> &'static str {
        match self {
            AnyRule::Base(r) => r.name(),
            AnyRule::Product(r) => r.name(),
        }
    }
    fn about(&self) -> &'static str {
        match self {
            AnyRule::Base(r) => r.about(),
            AnyRule::Product(r) => r.about(),
        }
    }
    fn min_budget(&self, dim: usize) -> usize {
        match self {
            AnyRule::Base(r) => r.min_budget(dim),
            AnyRule::Product(r) => r.min_budget(dim),
        }
    }
    fn is_random(&self) -> bool {
        match self {
            AnyRule::Base(r) => r.is_random(),
            AnyRule::Product(r) => r.is_random(),
        }
    }
    fn guarded(&self, dim: usize) -> bool {
        match self {
            AnyRule::Base(r) => r.guarded(dim),
            AnyRule::Product(r) => r.guarded(dim),
        }
    }
    fn dimensions(&self) -> Dimensions {
        match self {
            AnyRule::Base(r) => r.dimensions(),
            AnyRule::Product(r) => r.dimensions(),
        }
    }
    fn check(&self) -> Result<(), QuadError> {
        match self {
            AnyRule::Base(r) => r.check(),
            AnyRule::Product(r) => r.check(),
        }
    }
    fn resolution(&self, n: usize, dim: usize) -> f64 {
        match self {
            AnyRule::Base(r) => r.resolution(n, dim),
            AnyRule::Product(r) => r.resolution(n, dim),
        }
    }
    fn memory(&self, n: usize, dim: usize) -> f64 {
        match self {
            AnyRule::Base(r) => r.memory(n, dim),
            AnyRule::Product(r) => r.memory(n, dim),
        }
    }
    fn evaluations(&self, n: usize, dim: usize) -> f64 {
        match self {
            AnyRule::Base(r) => r.evaluations(n, dim),
            AnyRule::Product(r) => r.evaluations(n, dim),
        }
    }
    fn integrate_unguarded<
        const D: usize,
        V: Value,
        R: rand::Rng + ?Sized,
        F: FnMut([f64; D]) -> Result<V, QuadError>,
    >(
        &self,
        n: usize,
        rng: &mut R,
        f: F,
    ) -> Result<Estimate<V>, QuadError> {
        match self {
            AnyRule::Base(r) => r.integrate_unguarded(n, rng, f),
            AnyRule::Product(r) => r.integrate_unguarded(n, rng, f),
        }
    }
}

/// Splits `A,B` at the comma that is not inside parentheses.
fn split_top_level_comma(s: &str) -> Option<(&str, &str)> {
    let mut depth = 0i32;
    for (i, ch) in s.char_indices() {
        match ch {
            '(' => depth += 1,
            ')' => depth -= 1,
            ',' if depth == 0 => return Some((s[..i].trim(), s[i + 1..].trim())),
            _ => {}
        }
    }
    None
}
