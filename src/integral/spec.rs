//! The `integral` family's scene as an experiment file writes it, and its
//! build into a [`Region`] and compiled expressions.

use schemars::JsonSchema;
use serde::de::Error;
use serde::{Deserialize, Serialize};
use serde_json::Value as Json;

use crate::domain::{
    Disk, Hemisphere, HemisphereMap, Pixel, Rectangle, Segment, SphericalCap, Triangle, Vec3,
};
use crate::error::{QuadError, SpecError};
use crate::experiment::tagged;

use super::expr::{Expr, ExprError};
use super::region::{Interval, MAX_BOX_DIM, Region};

/// The scene: `{"domain": {..}, "integrand": "..", "exact": ..}`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct IntegralSpec {
    /// Where the integral is taken, and in which measure.
    #[serde(deserialize_with = "tagged::object")]
    pub domain: DomainSpec,
    /// The integrand: an expression (`"x*exp(-x*y)"`), or a list of three
    /// (R, G, B).
    pub integrand: Formulas,
    /// The exact value, for `"reference": {"type": "closed-form"}`: a number
    /// or an expression without variables (`"(1 + exp(-2))/2"`), a list of
    /// three for an RGB integrand.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub exact: Option<Exact>,
}

/// A domain: `{"type": <name>, <its fields>}` ([`region`](super::region)).
#[derive(Debug, Clone, PartialEq, Serialize, JsonSchema)]
#[serde(tag = "type", rename_all = "kebab-case")]
pub enum DomainSpec {
    /// `[a, b]`, either end possibly `"-inf"` or `"inf"`.
    Interval(IntervalSpec),
    /// A finite segment `[a, b]` cut at `breaks`.
    Segment(SegmentSpec),
    /// The unit cube `[0, 1]^dimension`.
    Cube(CubeSpec),
    /// The box `[min_1, max_1] x ... x [min_D, max_D]`, D from 1 to 6.
    Box(BoxSpec),
    /// A parallelogram `origin + s edge_u + t edge_v`.
    Rectangle(RectangleSpec),
    /// A disk.
    Disk(DiskSpec),
    /// A triangle.
    Triangle(TriangleSpec),
    /// The cap `{p : |p - centre| = radius, (p - centre) . axis >= radius cos_max}`.
    Cap(CapSpec),
    /// A whole sphere.
    Sphere(SphereSpec),
    /// The hemisphere of unit directions about `normal`.
    Hemisphere(HemisphereSpec),
    /// A pixel `[x0, x0 + width] x [y0, y0 + height]` on the image plane.
    Pixel(PixelSpec),
}

/// `[a, b]`, either end possibly infinite.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct IntervalSpec {
    /// Lower end (a number or `"-inf"`).
    #[serde(
        serialize_with = "crate::family::json_f64::one::serialize",
        deserialize_with = "end"
    )]
    #[schemars(with = "serde_json::Value")]
    pub a: f64,
    /// Upper end (a number or `"inf"`).
    #[serde(
        serialize_with = "crate::family::json_f64::one::serialize",
        deserialize_with = "end"
    )]
    #[schemars(with = "serde_json::Value")]
    pub b: f64,
}

/// A finite segment cut at break points.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SegmentSpec {
    /// Start.
    pub a: f64,
    /// End (`>= a`).
    pub b: f64,
    /// Points inside `(a, b)` where the integrand is not smooth.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub breaks: Vec<f64>,
}

/// The unit cube.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CubeSpec {
    /// 1 to 6.
    #[serde(deserialize_with = "dimension")]
    pub dimension: usize,
}

/// A box.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BoxSpec {
    /// Lower corner, 1 to 6 numbers.
    pub min: Vec<f64>,
    /// Upper corner, as many numbers.
    pub max: Vec<f64>,
}

/// A parallelogram patch.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RectangleSpec {
    /// The corner at `s = t = 0`.
    #[serde(deserialize_with = "tagged::array")]
    pub origin: [f64; 3],
    /// First edge.
    #[serde(deserialize_with = "tagged::array")]
    pub edge_u: [f64; 3],
    /// Second edge.
    #[serde(deserialize_with = "tagged::array")]
    pub edge_v: [f64; 3],
}

/// A disk.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DiskSpec {
    /// Centre.
    #[serde(deserialize_with = "tagged::array")]
    pub centre: [f64; 3],
    /// Normal.
    #[serde(deserialize_with = "tagged::array")]
    pub normal: [f64; 3],
    /// Radius (`> 0`).
    pub radius: f64,
}

/// A triangle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TriangleSpec {
    /// First vertex.
    #[serde(deserialize_with = "tagged::array")]
    pub a: [f64; 3],
    /// Second vertex.
    #[serde(deserialize_with = "tagged::array")]
    pub b: [f64; 3],
    /// Third vertex.
    #[serde(deserialize_with = "tagged::array")]
    pub c: [f64; 3],
}

/// A spherical cap.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CapSpec {
    /// Centre of the sphere.
    #[serde(deserialize_with = "tagged::array")]
    pub centre: [f64; 3],
    /// The cap's axis.
    #[serde(deserialize_with = "tagged::array")]
    pub axis: [f64; 3],
    /// Radius (`> 0`).
    pub radius: f64,
    /// Cosine of the cap's half angle, in `[-1, 1)`.
    pub cos_max: f64,
}

/// A whole sphere.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SphereSpec {
    /// Centre.
    #[serde(deserialize_with = "tagged::array")]
    pub centre: [f64; 3],
    /// Radius (`> 0`).
    pub radius: f64,
}

/// The hemisphere of directions.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct HemisphereSpec {
    /// The pole (default `[0, 0, 1]`).
    #[serde(default = "up", deserialize_with = "tagged::array")]
    pub normal: [f64; 3],
    /// `uniform` or `cosine` (solid angle), `projected` (projected solid angle).
    #[serde(default)]
    pub map: MapSpec,
}

/// A pixel on the image plane.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PixelSpec {
    /// Left edge.
    pub x0: f64,
    /// Bottom edge.
    pub y0: f64,
    /// Width (`> 0`).
    pub width: f64,
    /// Height (`> 0`).
    pub height: f64,
}

fn up() -> [f64; 3] {
    [0.0, 0.0, 1.0]
}

/// The hemisphere's map and measure.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum MapSpec {
    /// `cos theta = u_1`: solid angle.
    #[default]
    Uniform,
    /// Malley's map, in solid angle (`|J| = pi / cos theta`).
    Cosine,
    /// Malley's map, in projected solid angle (`|J| = pi`).
    Projected,
}

/// The names of the domains, in [`DomainSpec`]'s order.
const DOMAINS: [&str; 11] = [
    "interval",
    "segment",
    "cube",
    "box",
    "rectangle",
    "disk",
    "triangle",
    "cap",
    "sphere",
    "hemisphere",
    "pixel",
];

/// Reads the tag, then the variant's fields, so a fault inside names its
/// own path (`scene.domain.radius`).
impl<'de> Deserialize<'de> for DomainSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use tagged::variant;
        let (tag, f) = tagged::split_tag(Json::deserialize(d)?, "type", &DOMAINS)?;
        match tag.as_str() {
            "interval" => variant(f).map(DomainSpec::Interval),
            "segment" => variant(f).map(DomainSpec::Segment),
            "cube" => variant(f).map(DomainSpec::Cube),
            "box" => variant(f).map(DomainSpec::Box),
            "rectangle" => variant(f).map(DomainSpec::Rectangle),
            "disk" => variant(f).map(DomainSpec::Disk),
            "triangle" => variant(f).map(DomainSpec::Triangle),
            "cap" => variant(f).map(DomainSpec::Cap),
            "sphere" => variant(f).map(DomainSpec::Sphere),
            "hemisphere" => variant(f).map(DomainSpec::Hemisphere),
            _ => variant(f).map(DomainSpec::Pixel),
        }
    }
}

/// An interval's end: a number, or `"inf"`, `"+inf"`, `"-inf"`.
fn end<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    match Json::deserialize(d)? {
        Json::Number(n) => n
            .as_f64()
            .ok_or_else(|| D::Error::custom(format!("{n} is not a number f64 holds"))),
        Json::String(s) if s == "inf" || s == "+inf" => Ok(f64::INFINITY),
        Json::String(s) if s == "-inf" => Ok(f64::NEG_INFINITY),
        other => Err(D::Error::custom(format!(
            "{}: expected a number, \"-inf\" or \"inf\"",
            tagged::kind(&other)
        ))),
    }
}

/// A cube's dimension, 1 to [`MAX_BOX_DIM`].
fn dimension<'de, D: serde::Deserializer<'de>>(d: D) -> Result<usize, D::Error> {
    let n: usize = tagged::whole(d, 1, MAX_BOX_DIM as i128, "")?;
    if !(1..=MAX_BOX_DIM).contains(&n) {
        return Err(D::Error::custom(format!(
            "{n}: expected a dimension from 1 to {MAX_BOX_DIM}"
        )));
    }
    Ok(n)
}

/// One expression or a list of them (R, G, B).
#[derive(Debug, Clone, PartialEq)]
pub struct Formulas(pub Vec<String>);

impl Serialize for Formulas {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self.0.as_slice() {
            [one] => one.serialize(s),
            many => many.serialize(s),
        }
    }
}

impl<'de> Deserialize<'de> for Formulas {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let value = Json::deserialize(d)?;
        if value.is_number() {
            return Err(D::Error::custom(format!(
                "{}: expected an expression in quotes (\"x*y\"), or a list of 3 (R, G, B)",
                tagged::kind(&value)
            )));
        }
        let terms = terms(value, "an expression in quotes (\"x*y\")")?;
        terms
            .into_iter()
            .enumerate()
            .map(|(i, t)| match t {
                Json::String(s) => Ok(s),
                other => Err(tagged::below(
                    &format!("[{i}]"),
                    &format!("{}: expected an expression in quotes", tagged::kind(&other)),
                )),
            })
            .collect::<Result<Vec<_>, D::Error>>()
            .map(Formulas)
    }
}

impl JsonSchema for Formulas {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        "Formulas".into()
    }
    fn json_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
        schemars::json_schema!({
            "anyOf": [
                {"type": "string"},
                {"type": "array", "items": {"type": "string"}, "minItems": 3, "maxItems": 3}
            ]
        })
    }
}

/// One exact value or a list of three: numbers or expressions without variables.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Exact(pub Vec<Json>);

impl<'de> Deserialize<'de> for Exact {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let terms = terms(Json::deserialize(d)?, "a number or an expression in quotes")?;
        for (i, t) in terms.iter().enumerate() {
            if !(t.is_number() || t.is_string()) {
                return Err(tagged::below(
                    &format!("[{i}]"),
                    &format!(
                        "{}: expected a number or an expression in quotes",
                        tagged::kind(t)
                    ),
                ));
            }
        }
        Ok(Exact(terms))
    }
}

impl JsonSchema for Exact {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        "Exact".into()
    }
    fn json_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
        schemars::json_schema!({
            "anyOf": [
                {"type": ["number", "string"]},
                {"type": "array", "items": {"type": ["number", "string"]}, "minItems": 3, "maxItems": 3}
            ]
        })
    }
}

/// A single value as a list of one; a list of 1 or 3 as it is.
fn terms<E: Error>(value: Json, one: &str) -> Result<Vec<Json>, E> {
    match value {
        Json::Array(items) if items.len() == 1 || items.len() == 3 => Ok(items),
        Json::Array(items) => Err(E::custom(format!(
            "a list of {}: expected {one}, or a list of 3 (R, G, B)",
            items.len()
        ))),
        other @ (Json::String(_) | Json::Number(_)) => Ok(vec![other]),
        other => Err(E::custom(format!(
            "{}: expected {one}, or a list of 3 (R, G, B)",
            tagged::kind(&other)
        ))),
    }
}

/// The built scene: the region, the compiled integrand (one expression a
/// channel) and the exact value if given.
#[derive(Debug, Clone)]
pub struct Built {
    /// Where the integral is taken.
    pub region: Region,
    /// One expression per channel.
    pub integrand: Vec<Expr>,
    /// The variables' names, in the order of their values.
    pub variables: Vec<&'static str>,
    /// Whether any expression uses `theta` or `phi`.
    pub angles: bool,
    /// The exact value per channel, if given.
    pub exact: Option<Vec<f64>>,
}

/// Checks every field of `spec` and builds it; errors at `scene.<field>`.
pub fn build(spec: &IntegralSpec) -> Result<Built, SpecError> {
    let region = region(&spec.domain).map_err(|e| SpecError::from_quad("scene.domain", e))?;
    let size = region.size();
    if !(size.is_normal() || size == f64::INFINITY && matches!(region, Region::Interval(_))) {
        return Err(SpecError::at(
            "scene.domain",
            format!(
                "its {} is {size:e}: expected a finite size above 2.2e-308 in f64 (the \
                 integrand is multiplied by it; rescale the domain's coordinates)",
                region.measure()
            ),
        ));
    }
    let variables = region.variables();
    let integrand = spec
        .integrand
        .0
        .iter()
        .enumerate()
        .map(|(i, text)| {
            Expr::compile(text, &variables)
                .map_err(|e| expr_error(&indexed("scene.integrand", i, spec.integrand.0.len()), e))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let angles = integrand.iter().any(|e| e.uses("theta") || e.uses("phi"));
    let exact = spec
        .exact
        .as_ref()
        .map(|x| exact_values(x, integrand.len()))
        .transpose()?;
    Ok(Built {
        region,
        integrand,
        variables,
        angles,
        exact,
    })
}

/// `path` or `path[i]` where the field is a list.
fn indexed(path: &str, i: usize, len: usize) -> String {
    if len > 1 {
        format!("{path}[{i}]")
    } else {
        path.to_string()
    }
}

/// An expression's fault at `path`, with its column.
fn expr_error(path: &str, e: ExprError) -> SpecError {
    SpecError::at(path, format!("{e}"))
}

/// The exact values, one per channel: each finite.
fn exact_values(exact: &Exact, channels: usize) -> Result<Vec<f64>, SpecError> {
    if exact.0.len() != channels {
        return Err(SpecError::at(
            "scene.exact",
            format!(
                "{} value(s) for an integrand of {channels} channel(s): expected {channels}",
                exact.0.len()
            ),
        ));
    }
    exact
        .0
        .iter()
        .enumerate()
        .map(|(i, term)| {
            let path = indexed("scene.exact", i, channels);
            let value = match term {
                Json::String(text) => Expr::compile(text, &[])
                    .map_err(|e| expr_error(&path, e))?
                    .eval(&[]),
                other => other.as_f64().unwrap_or(f64::NAN),
            };
            if value.is_finite() {
                Ok(value)
            } else {
                Err(SpecError::at(
                    path,
                    format!("{term} is {value}: expected a finite value"),
                ))
            }
        })
        .collect()
}

fn vec3(v: [f64; 3]) -> Vec3 {
    Vec3::from(v)
}

/// The [`Region`] of a domain; an error names the field.
fn region(spec: &DomainSpec) -> Result<Region, QuadError> {
    Ok(match spec {
        DomainSpec::Interval(s) => Region::Interval(interval(s.a, s.b)?),
        DomainSpec::Segment(s) => {
            Region::Segment(Segment::with_breaks(s.a, s.b, s.breaks.clone())?)
        }
        DomainSpec::Cube(s) => unit_cube(s.dimension)?,
        DomainSpec::Box(s) => boxed(&s.min, &s.max)?,
        DomainSpec::Rectangle(s) => Region::Rectangle(Rectangle::new(
            vec3(s.origin),
            vec3(s.edge_u),
            vec3(s.edge_v),
        )?),
        DomainSpec::Disk(s) => Region::Disk(Disk::new(vec3(s.centre), vec3(s.normal), s.radius)?),
        DomainSpec::Triangle(s) => {
            Region::Triangle(Triangle::new(vec3(s.a), vec3(s.b), vec3(s.c))?)
        }
        DomainSpec::Cap(s) => Region::Cap(SphericalCap::new(
            vec3(s.centre),
            vec3(s.axis),
            s.radius,
            s.cos_max,
        )?),
        DomainSpec::Sphere(s) => Region::Cap(SphericalCap::sphere(vec3(s.centre), s.radius)?),
        DomainSpec::Hemisphere(s) => Region::Hemisphere(hemisphere(s.normal, s.map)?),
        DomainSpec::Pixel(s) => Region::Pixel(Pixel::new(s.x0, s.y0, s.width, s.height)?),
    })
}

/// The pieces of `[a, b]`, `a < b`, infinite ends cut off as
/// [`Interval`] says.
fn interval(a: f64, b: f64) -> Result<Vec<Interval>, QuadError> {
    if a.is_nan() || a == f64::INFINITY {
        return Err(QuadError::invalid("a", a, "a number or \"-inf\""));
    }
    if b.is_nan() || b == f64::NEG_INFINITY {
        return Err(QuadError::invalid("b", b, "a number or \"inf\""));
    }
    if b <= a {
        return Err(QuadError::invalid("b", b, format!("b > a = {a}")));
    }
    Ok(match (a.is_finite(), b.is_finite()) {
        (true, true) if (b - a).is_finite() => vec![Interval::Finite(a, b)],
        (true, true) => {
            return Err(QuadError::invalid(
                "b",
                b,
                format!("an end whose distance b - a from a = {a} is finite in f64"),
            ));
        }
        (true, false) => vec![Interval::Finite(a, a + 1.0), Interval::Above(a + 1.0)],
        (false, true) => vec![Interval::Below(b - 1.0), Interval::Finite(b, b - 1.0)],
        (false, false) => vec![
            Interval::Below(-1.0),
            Interval::Finite(-1.0, 1.0),
            Interval::Above(1.0),
        ],
    })
}

/// The unit cube in `dim` dimensions.
fn unit_cube(dim: usize) -> Result<Region, QuadError> {
    boxed(&vec![0.0; dim], &vec![1.0; dim])
}

/// The box between `min` and `max`: 1 to 6 finite numbers each, `min < max`
/// with a finite width.
fn boxed(min: &[f64], max: &[f64]) -> Result<Region, QuadError> {
    let dim = min.len();
    if !(1..=MAX_BOX_DIM).contains(&dim) {
        return Err(QuadError::invalid(
            "min",
            format!("a list of {dim}"),
            format!("1 to {MAX_BOX_DIM} numbers"),
        ));
    }
    if max.len() != dim {
        return Err(QuadError::invalid(
            "max",
            format!("a list of {}", max.len()),
            format!("{dim} numbers, as many as `min`"),
        ));
    }
    let (mut lo, mut hi) = ([0.0; MAX_BOX_DIM], [0.0; MAX_BOX_DIM]);
    for k in 0..dim {
        let (a, b) = (min[k], max[k]);
        crate::error::require_finite(&format!("min[{k}]"), a)?;
        crate::error::require_finite(&format!("max[{k}]"), b)?;
        if !(a < b && (b - a).is_finite()) {
            return Err(QuadError::invalid(
                format!("max[{k}]"),
                b,
                format!("a number above min[{k}] = {a}, at a finite distance"),
            ));
        }
        (lo[k], hi[k]) = (a, b);
    }
    Ok(Region::Box { lo, hi, dim })
}

/// The hemisphere about `normal` with `map`.
fn hemisphere(normal: [f64; 3], map: MapSpec) -> Result<Hemisphere, QuadError> {
    let frame = crate::domain::Frame::from_normal(vec3(normal)).map_err(|_| {
        QuadError::invalid("normal", format!("{normal:?}"), "a finite, non-zero vector")
    })?;
    let map = match map {
        MapSpec::Uniform => HemisphereMap::Uniform,
        MapSpec::Cosine => HemisphereMap::Cosine,
        MapSpec::Projected => HemisphereMap::Projected,
    };
    Ok(Hemisphere { frame, map })
}
