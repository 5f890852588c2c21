//! Fuzzing the experiment parser and validator with proptest: random byte
//! edits of the bundled files, structure-aware mutations of their JSON trees
//! (numbers replaced by extremes, keys dropped, types swapped) and arbitrary
//! strings. The law: never a panic, and every rejection names a JSON path and
//! says what is wrong. (4,096 + 4,096 + 2,048 cases per run.)

use lightquad::experiment::validate::parse_json;
use proptest::prelude::*;
use serde_json::Value;

fn bundled() -> Vec<String> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments");
    let mut files: Vec<String> = std::fs::read_dir(dir)
        .map(|d| {
            d.filter_map(Result::ok)
                .filter(|f| f.path().extension().is_some_and(|x| x == "json"))
                .filter_map(|f| std::fs::read_to_string(f.path()).ok())
                .collect()
        })
        .unwrap_or_default();
    files.sort();
    files
}

/// Parse and validate; an error must carry a path and a message.
fn check(text: &str) -> Result<(), TestCaseError> {
    let registry = lightquad::families::builtin();
    match parse_json(text).and_then(|json| registry.load(json, "h").map(|_| ())) {
        Ok(_) => Ok(()),
        Err(e) => {
            prop_assert!(!e.path.is_empty(), "no path in {e}");
            prop_assert!(e.message.len() > 5, "no message in {e}");
            Ok(())
        }
    }
}

/// Replaces the `k`-th leaf of a JSON tree (depth first) with `new`.
fn mutate(v: &mut Value, k: &mut usize, new: &Value, drop: bool) -> bool {
    match v {
        Value::Object(map) => {
            let keys: Vec<String> = map.keys().cloned().collect();
            for key in keys {
                if *k == 0 {
                    if drop {
                        map.remove(&key);
                    } else if let Some(slot) = map.get_mut(&key) {
                        *slot = new.clone();
                    }
                    return true;
                }
                *k -= 1;
                if let Some(child) = map.get_mut(&key)
                    && mutate(child, k, new, drop)
                {
                    return true;
                }
            }
            false
        }
        Value::Array(items) => {
            for item in items.iter_mut() {
                if *k == 0 {
                    *item = new.clone();
                    return true;
                }
                *k -= 1;
                if mutate(item, k, new, drop) {
                    return true;
                }
            }
            false
        }
        _ => false,
    }
}

fn extreme() -> impl Strategy<Value = Value> {
    prop_oneof![
        Just(Value::from(-1)),
        Just(Value::from(0)),
        Just(Value::from(0.0)),
        Just(Value::from(1e308)),
        Just(Value::from(-1e-308)),
        Just(Value::from(u64::MAX)),
        Just(Value::from(i64::MIN)),
        Just(Value::from("x")),
        Just(Value::Null),
        Just(Value::Bool(true)),
        Just(Value::Array(vec![])),
        Just(serde_json::json!({})),
        Just(serde_json::json!([1e300, -1e300, 0.0])),
        any::<f64>()
            .prop_filter("finite", |x| x.is_finite())
            .prop_map(Value::from),
        any::<i64>().prop_map(Value::from),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 4096, ..ProptestConfig::default() })]

    #[test]
    fn byte_edits_of_bundled_files_never_panic(
        file in 0usize..64, pos in any::<usize>(), edit in 0u8..3, byte in 0x20u8..0x7f,
    ) {
        let files = bundled();
        let mut text = files[file % files.len()].clone().into_bytes();
        let i = pos % text.len();
        match edit {
            0 => { text.remove(i); }
            1 => text.insert(i, byte),
            _ => text[i] = byte,
        }
        check(&String::from_utf8_lossy(&text))?;
    }

    #[test]
    fn tree_mutations_of_bundled_files_never_panic(
        file in 0usize..64, leaf in 0usize..400, new in extreme(), drop in any::<bool>(),
    ) {
        let files = bundled();
        let mut tree: Value = serde_json::from_str(&files[file % files.len()]).expect("bundled JSON");
        let mut k = leaf;
        mutate(&mut tree, &mut k, &new, drop);
        check(&tree.to_string())?;
    }
}

/// A tag: a known name, a near miss, or anything.
fn tag() -> impl Strategy<Value = Value> {
    prop_oneof![
        Just(Value::from("volume")),
        Just(Value::from("product")),
        Just(Value::from("ratio-tracking")),
        Just(Value::from("gauss-legendre")),
        "[a-z-]{0,16}".prop_map(Value::from),
        extreme(),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2048, ..ProptestConfig::default() })]

    /// The family tag and the rule tags replaced by known names, near misses,
    /// other types, or dropped; and products nested in any slot.
    #[test]
    fn family_and_rule_tags_never_panic(
        file in 0usize..64, family in tag(), rule in tag(), slot in 0usize..8, drop in any::<bool>(),
        nest in any::<bool>(),
    ) {
        let files = bundled();
        let mut tree: Value = serde_json::from_str(&files[file % files.len()]).expect("bundled JSON");
        if drop {
            tree.as_object_mut().map(|m| m.remove("family"));
        } else {
            tree["family"] = family;
        }
        if let Some(rules) = tree["rules"].as_array_mut() {
            let n = rules.len();
            let r = &mut rules[slot % n];
            if nest {
                *r = serde_json::json!({"rule": "product", "outer": r.clone(), "inner": {"rule": rule}});
            } else {
                r["rule"] = rule;
            }
        }
        check(&tree.to_string())?;
    }

    #[test]
    fn arbitrary_strings_never_panic(text in ".{0,300}") {
        check(&text)?;
    }
}
