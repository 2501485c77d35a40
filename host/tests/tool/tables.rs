//! The planner parameters are declared once, in `ohaca::Params` (its serde derive serves the
//! protocol and the JSON report), and the error codes once, in `ohaca::protocol::ErrorCode`. The
//! places that still spell them out by hand must follow: the tables of docs/PROTOCOL.md (parameter
//! names in wire order with their defaults; error codes and names) and the Python client
//! `scripts/ohaca_client.py` (field order and encoding, enum values in variant order, error
//! names).

use std::path::Path;

use ohaca::protocol::ErrorCode;
use ohaca::{Algorithm, DeadEnd, Params, SmoothingKind};
use serde_json::Value;

fn read(rel: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(rel);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The default parameters' fields as the derive writes them: names in declaration (= wire)
/// order, with their JSON values.
fn fields() -> Vec<(String, Value)> {
    let json = serde_json::to_string(&Params::default()).unwrap();
    // A flat object of numbers, booleans and names: no commas or colons inside a value.
    json.trim_start_matches('{')
        .trim_end_matches('}')
        .split(',')
        .map(|kv| {
            let (k, v) = kv.split_once(':').unwrap();
            (
                k.trim_matches('"').to_string(),
                serde_json::from_str(v).unwrap(),
            )
        })
        .collect()
}

fn names(fields: &[(String, Value)]) -> Vec<&str> {
    fields.iter().map(|(k, _)| k.as_str()).collect()
}

#[test]
fn the_protocol_doc_lists_every_parameter_in_wire_order_with_its_default() {
    let doc = read("docs/PROTOCOL.md");
    let table = doc
        .split("\n## Params\n")
        .nth(1)
        .expect("a `## Params` section");
    let rows: Vec<(String, String)> = table
        .lines()
        .skip_while(|l| !l.starts_with("| field"))
        .skip(2)
        .take_while(|l| l.starts_with('|'))
        .map(|l| {
            let cols: Vec<&str> = l.split('|').map(str::trim).collect();
            (cols[1].trim_matches('`').to_string(), cols[3].to_string())
        })
        .collect();
    let fields = fields();
    let documented: Vec<&str> = rows.iter().map(|(k, _)| k.as_str()).collect();
    assert_eq!(documented, names(&fields), "docs/PROTOCOL.md, ## Params");
    for ((name, value), (_, default)) in fields.iter().zip(&rows) {
        let same = match value {
            Value::Number(n) => {
                default.parse::<f64>().ok().map(|d| d as f32) == n.as_f64().map(|v| v as f32)
            }
            Value::String(s) => s == default,
            Value::Bool(b) => default.parse::<bool>() == Ok(*b),
            other => panic!("{name}: unexpected {other}"),
        };
        assert!(
            same,
            "{name}: documented default {default}, the core's {value}"
        );
    }
}

/// The quoted words of the Python list assigned to `name` (`NAME = [...]`), in order.
fn python_list(src: &str, name: &str) -> Vec<String> {
    let start = src.find(&format!("\n{name} = [")).expect(name);
    let body = &src[start..];
    let body = &body[..body.find(']').unwrap()];
    body.split('"')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

#[test]
fn the_python_client_encodes_every_parameter_in_wire_order() {
    let py = read("scripts/ohaca_client.py");
    let fields = fields();
    // PARAM_FIELDS is ("name", "kind") pairs: every other word is a name.
    let listed = python_list(&py, "PARAM_FIELDS");
    let py_names: Vec<&str> = listed.iter().step_by(2).map(String::as_str).collect();
    let kinds: Vec<&str> = listed
        .iter()
        .skip(1)
        .step_by(2)
        .map(String::as_str)
        .collect();
    assert_eq!(
        py_names,
        names(&fields),
        "scripts/ohaca_client.py PARAM_FIELDS"
    );
    for ((name, value), kind) in fields.iter().zip(kinds) {
        let want = match value {
            Value::String(_) => "enum",
            Value::Bool(_) => "bool",
            Value::Number(n) if n.is_f64() => "f",
            Value::Number(_) => "u",
            other => panic!("{name}: {other}"),
        };
        assert_eq!(kind, want, "{name}");
    }
    // Enum values go on the wire as their variant index: the lists must be in variant order.
    let variants = |mut v: Vec<(u8, &'static str)>| {
        v.sort();
        v.into_iter()
            .map(|(_, n)| n.to_string())
            .collect::<Vec<_>>()
    };
    let algorithms = variants(Algorithm::ALL.map(|a| (a as u8, a.name())).to_vec());
    let dead_ends = variants(DeadEnd::ALL.map(|d| (d as u8, d.name())).to_vec());
    let smoothing = variants(SmoothingKind::ALL.map(|k| (k as u8, k.name())).to_vec());
    assert_eq!(python_list(&py, "ALGORITHMS"), algorithms);
    assert_eq!(python_list(&py, "DEAD_ENDS"), dead_ends);
    assert_eq!(python_list(&py, "SMOOTHING"), smoothing);
}

/// Every error code with its name (`1 BadMap`, ...), in numeric order.
fn error_codes() -> Vec<(u8, String)> {
    ErrorCode::ALL
        .into_iter()
        .map(|c| (c.code(), format!("{c:?}")))
        .collect()
}

#[test]
fn the_protocol_doc_and_the_python_client_name_every_error_code() {
    let doc = read("docs/PROTOCOL.md");
    let table = doc
        .split("\n## Error codes\n")
        .nth(1)
        .expect("a `## Error codes` section");
    let documented: Vec<(u8, String)> = table
        .lines()
        .skip_while(|l| !l.starts_with("| code"))
        .skip(2)
        .take_while(|l| l.starts_with('|'))
        .map(|l| {
            let cols: Vec<&str> = l.split('|').map(str::trim).collect();
            (
                cols[1].parse().unwrap(),
                cols[2].trim_matches('`').to_string(),
            )
        })
        .collect();
    assert_eq!(
        documented,
        error_codes(),
        "docs/PROTOCOL.md, ## Error codes"
    );

    let py = read("scripts/ohaca_client.py");
    let start = py.find("\nERRORS = {").expect("ERRORS");
    let body = &py[start..];
    let body = &body[body.find('{').unwrap() + 1..body.find('}').unwrap()];
    let listed: Vec<(u8, String)> = body
        .split(',')
        .filter(|kv| !kv.trim().is_empty())
        .map(|kv| {
            let (k, v) = kv.split_once(':').unwrap();
            (
                k.trim().parse().unwrap(),
                v.trim().trim_matches('"').to_string(),
            )
        })
        .collect();
    assert_eq!(listed, error_codes(), "scripts/ohaca_client.py ERRORS");
}
