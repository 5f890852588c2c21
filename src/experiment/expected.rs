//! What a field of an experiment file accepts, in words, read from the
//! family's JSON Schema: a missing required field is reported with it
//! (serde's message names only the field: "missing field `radius`").
//!
//! ```
//! use lightquad::experiment::expected::describe;
//! use serde_json::json;
//!
//! let schema = json!({"properties": {"r": {"type": "number", "description": "Radius."}}});
//! assert_eq!(describe(&schema, &json!({}), "r").as_deref(), Some("a number (radius)"));
//! ```

use serde_json::Value;

/// One step of a JSON path: a field or an index.
enum Step<'a> {
    Field(&'a str),
    Index(usize),
}

/// The steps of `scene.medium.blobs[1].width`.
fn steps(path: &str) -> Vec<Step<'_>> {
    let mut out = Vec::new();
    for part in path.split('.').filter(|p| !p.is_empty()) {
        let (name, rest) = part.split_at(part.find('[').unwrap_or(part.len()));
        if !name.is_empty() {
            out.push(Step::Field(name));
        }
        for index in rest.split('[').filter(|i| !i.is_empty()) {
            if let Ok(i) = index.trim_end_matches(']').parse() {
                out.push(Step::Index(i));
            }
        }
    }
    out
}

/// `node` with a `$ref` into the root's `$defs` followed.
fn resolve<'s>(root: &'s Value, node: &'s Value) -> &'s Value {
    let mut node = node;
    for _ in 0..16 {
        let Some(name) = node["$ref"]
            .as_str()
            .and_then(|r| r.strip_prefix("#/$defs/"))
        else {
            break;
        };
        match root["$defs"].get(name) {
            Some(def) => node = def,
            None => break,
        }
    }
    node
}

/// The branches of a `oneOf` or `anyOf` (resolved), or the node alone.
fn branches<'s>(root: &'s Value, node: &'s Value) -> Vec<&'s Value> {
    let node = resolve(root, node);
    let list = node["oneOf"].as_array().or(node["anyOf"].as_array());
    match list {
        Some(list) => list
            .iter()
            .flat_map(|b| branches(root, b))
            .filter(|b| b["type"] != "null")
            .collect(),
        None => vec![node],
    }
}

/// Whether every constant property of `branch` (a tag) matches `instance`.
fn matches(branch: &Value, instance: Option<&Value>) -> bool {
    let Some(props) = branch["properties"].as_object() else {
        return true;
    };
    props.iter().all(|(k, p)| match (&p["const"], instance) {
        (Value::Null, _) => true,
        (c, Some(i)) => i.get(k) == Some(c),
        (_, None) => false,
    })
}

/// The schema of the field at `path` in a file whose JSON is `instance`,
/// described in words (its kind, range and documentation), or `None` where
/// the schema does not say.
pub fn describe(schema: &Value, instance: &Value, path: &str) -> Option<String> {
    let steps = steps(path);
    let mut node = schema;
    let mut inst = Some(instance);
    for (k, step) in steps.iter().enumerate() {
        let options = branches(schema, node);
        match step {
            Step::Field(name) => {
                let has = |b: &&Value| b["properties"].get(*name).is_some();
                let with: Vec<&Value> = options.iter().copied().filter(has).collect();
                // A tag left out: the names of every variant.
                let tags: Vec<String> = with
                    .iter()
                    .filter_map(|b| b["properties"][*name]["const"].as_str())
                    .map(|c| format!("`{c}`"))
                    .collect();
                if k + 1 == steps.len() && with.len() > 1 && tags.len() == with.len() {
                    return Some(format!("one of {}", tags.join(", ")));
                }
                let chosen = with.iter().find(|b| matches(b, inst)).or(with.first())?;
                node = &chosen["properties"][*name];
                inst = inst.and_then(|i| i.get(*name));
            }
            Step::Index(i) => {
                let chosen = options.iter().find(|b| b.get("items").is_some())?;
                node = &chosen["items"];
                inst = inst.and_then(|v| v.get(*i));
            }
        }
    }
    let words = kind(schema, node, 0)?;
    let about = resolve(schema, node)["description"]
        .as_str()
        .or(node["description"].as_str())
        .map(first_sentence)
        .filter(|s| !s.is_empty());
    Some(match about {
        Some(about) => format!("{words} ({about})"),
        None => words,
    })
}

/// The first sentence of a doc comment, lower-cased at its start, on one
/// line, without its full stop.
fn first_sentence(text: &str) -> String {
    let text = text.split("\n\n").next().unwrap_or("").replace('\n', " ");
    let end = text.find(". ").map_or(text.len(), |i| i + 1);
    let s = text[..end].trim().trim_end_matches('.');
    let mut chars = s.chars();
    match chars.next() {
        Some(c) if chars.clone().next().is_some_and(char::is_lowercase) => {
            c.to_lowercase().chain(chars).collect()
        }
        _ => s.to_string(),
    }
}

/// The kind of value `node` accepts, in words.
fn kind(root: &Value, node: &Value, depth: usize) -> Option<String> {
    if depth > 4 {
        return None;
    }
    let node = resolve(root, node);
    if let Some(c) = node["const"].as_str() {
        return Some(format!("`{c}`"));
    }
    if let Some(names) = node["enum"].as_array() {
        let names: Vec<String> = names
            .iter()
            .map(|n| format!("`{}`", n.as_str().unwrap_or("?")))
            .collect();
        return Some(format!("one of {}", names.join(", ")));
    }
    let options = branches(root, node);
    // A unit enum: names.
    if options.len() > 1 && options.iter().all(|b| b["const"].is_string()) {
        let names: Vec<String> = options
            .iter()
            .map(|b| format!("`{}`", b["const"].as_str().unwrap_or("?")))
            .collect();
        return Some(format!("one of {}", names.join(", ")));
    }
    if options.len() > 1 || !std::ptr::eq(options[0], node) {
        // Variants told apart by a tag: the tag's names.
        let tag = options.first().and_then(|b| {
            b["properties"]
                .as_object()?
                .iter()
                .find(|(_, p)| p["const"].is_string())
                .map(|(k, _)| k.clone())
        });
        if let Some(tag) = tag
            && options
                .iter()
                .all(|b| b["properties"][&tag]["const"].is_string())
        {
            let names: Vec<String> = options
                .iter()
                .map(|b| {
                    format!(
                        "`{}`",
                        b["properties"][&tag]["const"].as_str().unwrap_or("?")
                    )
                })
                .collect();
            return Some(format!(
                "an object {{\"{tag}\": <name>, ...}} with the name one of {}",
                names.join(", ")
            ));
        }
        let words: Vec<String> = options
            .iter()
            .filter_map(|b| kind(root, b, depth + 1))
            .collect();
        return (!words.is_empty()).then(|| words.join(", or "));
    }
    let ty = match &node["type"] {
        Value::Array(types) => types.iter().find(|t| *t != "null")?.as_str()?,
        t => t.as_str()?,
    };
    Some(match ty {
        "number" => "a number".into(),
        "integer" => match (node["minimum"].as_i64(), node["maximum"].as_i64()) {
            (Some(lo), Some(hi)) => format!("a whole number in {lo}..={hi}"),
            (Some(lo), None) => format!("a whole number >= {lo}"),
            _ => "a whole number".into(),
        },
        "string" => "a string".into(),
        "boolean" => "true or false".into(),
        "array" => {
            let items = kind(root, &node["items"], depth + 1).unwrap_or("a value".into());
            match (node["minItems"].as_u64(), node["maxItems"].as_u64()) {
                (Some(a), Some(b)) if a == b && items == "a number" => {
                    format!("a list of {a} numbers")
                }
                (Some(a), Some(b)) if a == b => format!("a list of {a}, each {items}"),
                _ => format!("a list, each {items}"),
            }
        }
        "object" => match node["required"].as_array() {
            Some(fields) if !fields.is_empty() => {
                let fields: Vec<String> = fields
                    .iter()
                    .filter_map(Value::as_str)
                    .map(|f| format!("`{f}`"))
                    .collect();
                format!("an object with {}", fields.join(", "))
            }
            _ => "an object".into(),
        },
        _ => return None,
    })
}
