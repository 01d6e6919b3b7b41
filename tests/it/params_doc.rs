//! `docs/parameters.md`, the reference of every recognition parameter — its key in a parameters
//! file, unit, default and what it does — generated from the parameters' own definition: the
//! keys and defaults from `RecognitionParams::default()` as JSON (exactly what a parameters file
//! holds), the descriptions from the doc comments of the structs' fields in `src/`. The test
//! fails when the committed file is not what the definition says.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use serde_json::Value;

/// The committed reference, relative to the project root.
const PARAMS_REFERENCE: &str = "docs/parameters.md";

fn project_root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A field of a parameters struct as its source declares it.
#[derive(Debug, Clone)]
struct FieldDoc {
    /// Its doc comment, lines joined.
    doc: String,
    /// Its type as written (`BallParams`, `[f64; 2]`, `TestWeight`).
    ty: String,
}

/// A struct's or enum's declaration: fields by name (structs) or variants (enums, as a
/// parameters file writes them).
#[derive(Debug, Clone, Default)]
struct TypeDoc {
    fields: HashMap<String, FieldDoc>,
    variants: Vec<String>,
}

/// Every `.rs` file under `dir`.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut paths: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
    paths.sort();
    for p in paths {
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// `CamelCase` → `camel_case` (serde's `rename_all = "snake_case"`).
fn snake_case(name: &str) -> String {
    let mut out = String::new();
    for (i, c) in name.chars().enumerate() {
        if c.is_uppercase() && i > 0 {
            out.push('_');
        }
        out.extend(c.to_lowercase());
    }
    out
}

/// The public structs and enums of one source file with their fields' docs and types.
fn parse_types(text: &str, types: &mut HashMap<String, TypeDoc>) {
    let lines: Vec<&str> = text.lines().collect();
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i].trim_start();
        let head = line
            .strip_prefix("pub struct ")
            .map(|r| (r, false))
            .or_else(|| line.strip_prefix("pub enum ").map(|r| (r, true)));
        let Some((rest, is_enum)) = head.filter(|(r, _)| r.trim_end().ends_with('{')) else {
            i += 1;
            continue;
        };
        let name: String = rest
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        // The attributes just above: serde's renaming of enum variants.
        let snake = lines[..i]
            .iter()
            .rev()
            .take_while(|l| l.trim_start().starts_with("#[") || l.trim_start().starts_with("///"))
            .any(|l| l.contains("rename_all = \"snake_case\""));
        let indent = lines[i].len() - line.len();
        let mut t = TypeDoc::default();
        let mut doc: Vec<String> = Vec::new();
        i += 1;
        while i < lines.len() {
            let raw = lines[i];
            let l = raw.trim();
            if raw.len() - raw.trim_start().len() == indent && l.starts_with('}') {
                break;
            }
            if let Some(d) = l.strip_prefix("///") {
                doc.push(d.trim().to_owned());
            } else if l.starts_with("#[") {
                // Attributes between a doc comment and its field.
            } else if !is_enum && let Some(f) = l.strip_prefix("pub ") {
                if let Some((field, ty)) = f.split_once(':') {
                    // The type's own name (`patterns::PatternParams` → `PatternParams`).
                    let ty = ty.trim().trim_end_matches(',');
                    let ty = ty.rsplit("::").next().unwrap_or(ty).to_owned();
                    t.fields.insert(
                        field.trim().to_owned(),
                        FieldDoc {
                            doc: doc.join(" "),
                            ty,
                        },
                    );
                }
                doc.clear();
            } else if is_enum && !l.is_empty() && !l.starts_with("//") {
                let v: String = l
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                if !v.is_empty() {
                    t.variants.push(if snake { snake_case(&v) } else { v });
                }
                doc.clear();
            } else {
                doc.clear();
            }
            i += 1;
        }
        types.entry(name).or_insert(t);
        i += 1;
    }
}

/// The unit of a parameter, from its key's suffix (the project names units in field names)
/// or, failing that, from the first unit its description names.
fn unit_of(key: &str, doc: &str) -> &'static str {
    let last = key.rsplit('.').next().unwrap_or(key);
    for (suffix, unit) in [
        ("_cm", "cm"),
        ("_px", "px"),
        ("_deg", "°"),
        ("_rad", "rad"),
        ("_ms", "ms"),
        ("_s", "s"),
    ] {
        if last.ends_with(suffix) {
            return unit;
        }
    }
    // A unit the description names after a comma, as the project writes it ("…, pixels.",
    // "…, centimetres (2005 rules: 30)"); a share or a count of pixels has none.
    let d = doc.to_lowercase();
    for (word, unit) in [
        ("centimetres", "cm"),
        ("pixels", "px"),
        ("radians", "rad"),
        ("degrees", "°"),
        ("seconds", "s"),
    ] {
        if [".", " (", ":", ";", ","]
            .iter()
            .any(|end| d.contains(&format!(", {word}{end}")))
            || d.ends_with(&format!(", {word}"))
        {
            return unit;
        }
    }
    if last.ends_with("_pixels") {
        return "px";
    }
    ""
}

/// The value as a table cell.
fn cell(v: &Value) -> String {
    match v {
        Value::String(s) => format!("`\"{s}\"`"),
        other => format!("`{other}`"),
    }
}

/// Makes a description fit one table cell.
fn one_cell(text: &str) -> String {
    text.replace('|', "\\|")
}

/// The rows for the value `v` at `key`, declared as `field` of its parent struct.
fn rows(
    key: &str,
    v: &Value,
    field: Option<&FieldDoc>,
    types: &HashMap<String, TypeDoc>,
    out: &mut Vec<String>,
) {
    let doc = field.map_or("", |f| f.doc.as_str());
    let ty = field.map(|f| f.ty.as_str());
    if let Value::Object(m) = v {
        let own = ty.and_then(|t| types.get(t));
        for (k, x) in m {
            let sub = join(key, k);
            match own.and_then(|t| t.fields.get(k)) {
                Some(f) => rows(&sub, x, Some(f), types, out),
                // A field of a type whose source was not found: the parent's description.
                None => rows(
                    &sub,
                    x,
                    Some(&FieldDoc {
                        doc: format!("{doc} ({k})"),
                        ty: String::new(),
                    }),
                    types,
                    out,
                ),
            }
        }
        return;
    }
    let mut what = one_cell(doc);
    if let Some(variants) = ty
        .and_then(|t| types.get(t))
        .filter(|t| !t.variants.is_empty())
        .map(|t| &t.variants)
    {
        let list: Vec<String> = variants.iter().map(|v| format!("`{v}`")).collect();
        what = format!("{what} One of {}.", list.join(", "));
    }
    out.push(format!(
        "| `{key}` | {} | {} | {what} |",
        unit_of(key, doc),
        cell(v)
    ));
}

fn join(prefix: &str, key: &str) -> String {
    if prefix.is_empty() {
        key.to_owned()
    } else {
        format!("{prefix}.{key}")
    }
}

/// `docs/parameters.md` as the definition makes it.
fn generated_params_reference() -> String {
    let mut files = Vec::new();
    for dir in ["src/recognition", "src/geometry"] {
        rust_files(&project_root().join(dir), &mut files);
    }
    let mut types = HashMap::new();
    for f in files {
        parse_types(&std::fs::read_to_string(&f).unwrap(), &mut types);
    }
    let defaults = serde_json::to_value(eotn::recognition::RecognitionParams::default()).unwrap();
    let root = types
        .get("RecognitionParams")
        .expect("RecognitionParams in src/recognition")
        .clone();
    let mut out = String::from(
        "<!-- Generated from the recognition parameters' definition (`RecognitionParams` and its\n     \
         parts in src/recognition/ and src/geometry/: keys and defaults as a parameters file\n     \
         holds them, descriptions from the fields' doc comments) by tests/it/params_doc.rs; do\n     \
         not edit. Regenerate with\n     \
         UPDATE_PARAMS_REFERENCE=1 cargo test --test it params_reference -->\n\n\
         # Recognition parameters\n\n\
         Every key a recognition parameters file (`--params P.json`, `params/*.json`, the app's\n\
         Parameters window) can set, with its unit, its default and what it does. A file holds any\n\
         subset, nested as the dots say (`ball.min_pixels` is `{\"ball\": {\"min_pixels\": 5}}`);\n\
         unknown keys and values out of range are refused naming the key. `[low, high]` is an\n\
         accepted range; a `*_weight` is what the test adds to a candidate's confidence when the\n\
         value is in range (`reward`) and takes off when it is not (`penalty`). Advice on tuning\n\
         (small balls, other leagues' markers) is in [recognition.md](recognition.md#tuning-the-parameters).\n",
    );
    let Value::Object(sections) = &defaults else {
        panic!("the parameters are a JSON object");
    };
    // Top-level numbers first, in one table; then one table per section.
    let mut top = Vec::new();
    for (k, v) in sections {
        if !v.is_object() {
            rows(k, v, root.fields.get(k), &types, &mut top);
        }
    }
    let header = "| key | unit | default | what it does |\n|---|---|---|---|\n";
    out.push_str(&format!("\n## General\n\n{header}{}\n", top.join("\n")));
    for (k, v) in sections {
        if v.is_object() {
            let f = root.fields.get(k);
            let mut r = Vec::new();
            rows(k, v, f, &types, &mut r);
            let title = f.map_or(String::new(), |f| format!("{}\n\n", one_cell(&f.doc)));
            out.push_str(&format!("\n## `{k}`\n\n{title}{header}{}\n", r.join("\n")));
        }
    }
    out
}

#[test]
fn params_reference_is_current() {
    let path = project_root().join(PARAMS_REFERENCE);
    let want = generated_params_reference();
    if std::env::var_os("UPDATE_PARAMS_REFERENCE").is_some() {
        std::fs::write(&path, &want).unwrap();
        eprintln!("wrote {}", path.display());
        return;
    }
    let have = std::fs::read_to_string(&path).unwrap_or_default();
    if have != want {
        let line = have
            .lines()
            .zip(want.lines())
            .position(|(a, b)| a != b)
            .unwrap_or_else(|| have.lines().count().min(want.lines().count()));
        panic!(
            "{PARAMS_REFERENCE} is not what the parameters' definition says (first difference at line {}).\n\
             Regenerate it and commit the result:\n    \
             UPDATE_PARAMS_REFERENCE=1 cargo test --test it params_reference",
            line + 1
        );
    }
}

#[test]
fn every_parameter_has_a_description() {
    let text = generated_params_reference();
    let rows: Vec<&str> = text.lines().filter(|l| l.starts_with("| `")).collect();
    assert!(rows.len() > 100, "{} rows", rows.len());
    for key in [
        "ball.min_pixels",
        "ball.unclassified_around",
        "overhead.team_dot_diameter_cm",
    ] {
        assert!(
            rows.iter().any(|r| r.starts_with(&format!("| `{key}`"))),
            "{key} missing"
        );
    }
    let empty: Vec<&&str> = rows.iter().filter(|r| r.ends_with("|  |")).collect();
    assert!(empty.is_empty(), "rows without a description: {empty:?}");
    // Units come from the names: every `_cm` key says cm.
    assert!(
        rows.iter()
            .filter(|r| r.split('`').nth(1).is_some_and(|k| k.ends_with("_cm")))
            .all(|r| r.contains("| cm |"))
    );
}
