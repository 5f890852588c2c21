//! The messages between lightquad and an external estimator, version
//! [`VERSION`]: one JSON object per line each way. Once started and ready,
//! the program writes a [`Hello`] on its stdout (lightquad's clock for a
//! request starts after it, so start-up is not counted as work); then a
//! [`Request`] on its stdin gets its [`Response`] on its stdout, one
//! request at a time, until its stdin ends and it exits. What it
//! writes to stderr is kept (its last lines are quoted when a job fails) and
//! never read as an answer. `lightquad schema --protocol` prints the JSON
//! Schema of both messages.
//!
//! ```
//! use lightquad::experiment::external::protocol::{Response, answer};
//!
//! // A scalar estimate with its standard error, for request 3.
//! let line = r#"{"id": 3, "value": [0.25], "std_error": [0.01], "evaluations": 1024}"#;
//! let response: Response = serde_json::from_str(line)?;
//! let measured = answer(response, 3, 1, 1024).map_err(|e| e.to_string())?;
//! assert_eq!(measured.value, vec![0.25]);
//! assert_eq!(measured.error, vec![0.01]);
//! assert!(measured.flags.is_empty());
//! // A standard error the program doubts flags the row as lightquad's own
//! // doubted estimates are.
//! let doubted = serde_json::from_str(r#"{"id": 5, "value": [0.3], "std_error": [0.2], "doubted": true}"#)?;
//! let measured = answer(doubted, 5, 1, 64).map_err(|e| e.to_string())?;
//! assert_eq!(measured.flags, vec![lightquad::family::Flag::UnreliableEstimate]);
//! // The wrong number of channels is refused, naming both counts.
//! let rgb = serde_json::from_str(r#"{"id": 4, "value": [1, 2, 3]}"#)?;
//! let e = answer(rgb, 4, 1, 16).err().ok_or("accepted")?;
//! assert!(e.contains("3 value(s)") && e.contains("1 channel"), "{e}");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::family::Measured;

/// The protocol's version: requests carry it, and a response may not
/// claim another.
pub const VERSION: u32 = 1;

/// The name every request carries in `protocol`.
pub const NAME: &str = "lightquad-estimator";

/// The program's first line: ready, and the protocol it speaks.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Hello {
    /// `"lightquad-estimator"`.
    pub protocol: String,
    /// The version it speaks: [`VERSION`].
    pub version: u32,
}

impl Hello {
    /// Why a hello is not this protocol's, if it is not.
    pub fn mismatch(&self) -> Option<String> {
        (self.protocol != NAME || self.version != VERSION).then(|| {
            format!(
                "speaks {:?} version {}, where lightquad speaks {NAME:?} version {VERSION}",
                crate::error::excerpt(&self.protocol),
                self.version
            )
        })
    }
}

/// One estimate lightquad asks for.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Request {
    /// Always `"lightquad-estimator"`.
    pub protocol: String,
    /// The protocol version, [`VERSION`].
    pub version: u32,
    /// Numbers the requests to this process (from 1); the response repeats it.
    pub id: u64,
    /// The experiment's name.
    pub experiment: String,
    /// The equation family (`rendering`, `volume`, ...): it says how to read
    /// `scene` (`lightquad schema` gives every family's scene format).
    pub family: String,
    /// The scene as the experiment file states it, every default filled in.
    pub scene: serde_json::Value,
    /// The quantity to estimate (`E`, `tau`, `I_L`, ...).
    pub quantity: String,
    /// How many numbers the value has (1 for a scalar, 3 for RGB, the pixel
    /// channels of an image).
    pub channels: usize,
    /// The dimension of the integral lightquad's rules compute it by.
    pub dimension: usize,
    /// The budget: samples per pixel, walks, evaluations, as the program
    /// counts its work.
    pub budget: usize,
    /// The job's seed: the same request gets the same seed on every run.
    pub seed: u64,
    /// The repeat index (0, 1, ...): repeats of one budget have different seeds.
    pub repeat: usize,
}

/// A program's answer to one [`Request`]: a value, or an error.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Response {
    /// The request's `id`.
    pub id: u64,
    /// The estimate, one number per channel.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub value: Option<Vec<f64>>,
    /// Its standard error per channel, if the program estimates one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub std_error: Option<Vec<f64>>,
    /// The work it did, as the program counts it (default: the budget).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub evaluations: Option<u64>,
    /// The program's own wall time for this request, seconds, start-up
    /// excluded (lightquad times the request too and reports both).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seconds: Option<f64>,
    /// True where the program doubts its own standard error (a sample
    /// variance carried by a few samples, every sample alike): the row is
    /// flagged as lightquad's own rules' rows are, and the verdicts weigh
    /// its coverage instead of calling it consistent (default false).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub doubted: Option<bool>,
    /// Why the program could not answer (a scene it cannot express): the job
    /// fails with this message and the program stays running.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

/// The three messages, for `lightquad schema --protocol`.
#[derive(JsonSchema)]
#[schemars(rename = "LightquadEstimatorProtocol")]
#[allow(dead_code)]
pub struct Messages {
    /// The program's first line on its stdout, when it is ready.
    pub hello: Hello,
    /// A request, one line on the program's stdin.
    pub request: Request,
    /// A response, one line on the program's stdout.
    pub response: Response,
}

/// The JSON Schema of the protocol's messages: a line is one of a
/// [`Hello`], a [`Request`] or a [`Response`] (each also under `$defs`).
pub fn schema() -> serde_json::Value {
    let mut root = serde_json::to_value(schemars::schema_for!(Messages)).unwrap_or_default();
    if let Some(map) = root.as_object_mut() {
        for key in ["properties", "required", "type", "additionalProperties"] {
            map.remove(key);
        }
        map.insert(
            "description".into(),
            "One line of lightquad's external estimator protocol (lightquad-estimator, version 1): \
             the program's hello, a request from lightquad, or the program's response."
                .into(),
        );
        map.insert(
            "oneOf".into(),
            serde_json::json!([
                {"$ref": "#/$defs/Hello"},
                {"$ref": "#/$defs/Request"},
                {"$ref": "#/$defs/Response"}
            ]),
        );
    }
    root
}

/// `response` to request `id` as a measured value of `channels` channels at
/// `budget`, or why it is not one: another id, an error the program
/// reported, a value missing, of the wrong length or not finite, a standard
/// error negative or of the wrong length, a negative or non-finite time.
pub fn answer(
    response: Response,
    id: u64,
    channels: usize,
    budget: usize,
) -> Result<Measured, String> {
    if response.id != id {
        return Err(format!(
            "answered request {} where request {id} was asked",
            response.id
        ));
    }
    if let Some(e) = response.error {
        return Err(format!(
            "the program could not estimate it: {}",
            crate::error::excerpt(&super::server::one_line(&e))
        ));
    }
    let Some(value) = response.value else {
        return Err("a response with neither `value` nor `error`".into());
    };
    channel_count("value", value.len(), channels)?;
    finite("value", &value, f64::NEG_INFINITY)?;
    let error = match response.std_error {
        Some(se) => {
            channel_count("std_error", se.len(), channels)?;
            finite("std_error", &se, 0.0)?;
            se
        }
        None => vec![f64::INFINITY; channels],
    };
    if response.evaluations == Some(0) {
        return Err("`evaluations` is 0: expected the work done, at least 1".into());
    }
    if let Some(s) = response.seconds
        && !(s.is_finite() && s >= 0.0)
    {
        return Err(format!("`seconds` is {s}: expected a time >= 0"));
    }
    let mut m = Measured::scalar(0.0, 0.0, response.evaluations.unwrap_or(budget as u64));
    m.value = value;
    m.error = error;
    m.program_seconds = response.seconds;
    if response.doubted == Some(true) {
        m.flags.push(crate::family::Flag::UnreliableEstimate);
    }
    Ok(m)
}

fn channel_count(field: &str, got: usize, want: usize) -> Result<(), String> {
    if got == want {
        Ok(())
    } else {
        Err(format!(
            "`{field}` has {got} value(s) where the quantity has {want} channel(s)"
        ))
    }
}

/// Every number of `field` finite and at least `lo`.
fn finite(field: &str, xs: &[f64], lo: f64) -> Result<(), String> {
    match xs.iter().position(|x| !(x.is_finite() && *x >= lo)) {
        None => Ok(()),
        Some(k) => Err(format!(
            "`{field}[{k}]` is {}: expected a finite number{}",
            xs[k],
            if lo == 0.0 { " >= 0" } else { "" }
        )),
    }
}
