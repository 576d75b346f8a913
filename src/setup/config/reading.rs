//! Reading TOML text into configuration types, with errors in the user's terms: one line
//! naming the field (its dotted path), the value as written and what is allowed, and its line.

use std::borrow::Cow;
use std::ops::Range;

use toml::de::{DeTable, DeValue};

use super::compare::Model;
use super::error::ConfigError;
use super::material::KEY_ERROR;

/// The tables of a run config (`smithwalk run`), every top-level key but `paths` and `seed`; a
/// table config (`smithwalk lut`) has `[surface]` and `[material]` of them, and `[table]`.
pub const RUN_TABLES: [&str; 7] = ["surface", "material", "incident", "detector", "energy", "precision", "compare"];

/// Deserializes TOML text; an error is one line naming the field (its dotted path), the value
/// as written (shortened) and what is allowed, whatever the input's size.
pub fn parse_toml<T: serde::de::DeserializeOwned>(text: &str) -> Result<T, ConfigError> {
    parse_toml_with(text, true)
}

/// A key that a config leaves out because another of its tables supplies it: `table.key` is
/// set to `value` (TOML text) before the configuration types read the document. A `smithwalk
/// lut` config reads `[surface]` and `[material]` with the run's types, and its grid (`[table]`)
/// supplies the values it sweeps along an axis. `by` says what supplies the key, for the error
/// when the text gives it too.
pub struct Supplied<'a> {
    pub table: &'a str,
    pub key: &'a str,
    pub value: String,
    pub by: String,
}

/// [`parse_toml`] of the document with the `supplied` keys set: a supplied key that the text
/// gives too is refused, one line naming it, its value, its line and what supplies it.
pub fn parse_toml_supplied<T: serde::de::DeserializeOwned>(
    text: &str,
    supplied: &[Supplied],
) -> Result<T, ConfigError> {
    read_toml(text, true, supplied)
}

/// [`parse_toml`], with the errors' lines and columns only when `lines` (text made from a dict
/// has lines the user never saw).
pub(super) fn parse_toml_with<T: serde::de::DeserializeOwned>(text: &str, lines: bool) -> Result<T, ConfigError> {
    read_toml(text, lines, &[])
}

/// Sets the `supplied` keys in the parsed document `root` of `text` (the key's span is its
/// table's); an error names a supplied key that the text gives too.
fn supply<'i>(
    text: &str,
    root: &mut toml::Spanned<DeTable<'i>>,
    supplied: &'i [Supplied<'i>],
    at: impl Fn(std::ops::Range<usize>) -> String,
) -> Result<(), String> {
    let span = root.span();
    for s in supplied {
        let key = |k: &'i str| toml::Spanned::new(span.clone(), Cow::Borrowed(k));
        let table = root
            .get_mut()
            .entry(key(s.table))
            .or_insert_with(|| toml::Spanned::new(span.clone(), DeValue::Table(DeTable::default())));
        let table_span = table.span();
        let DeValue::Table(entries) = table.get_mut() else { continue };
        if let Some(given) = entries.get(&key(s.key)) {
            let value = text.get(given.span()).map_or("?".to_string(), |v| shorten(v, VALUE_CHARS));
            return Err(format!(
                "`{}.{}` = {value} is not allowed{}: {}; leave it out",
                s.table,
                s.key,
                at(given.span()),
                s.by
            ));
        }
        let value =
            DeValue::parse(&s.value).map_err(|e| format!("supplied `{}.{}`: {}", s.table, s.key, e.message()))?;
        entries.insert(key(s.key), toml::Spanned::new(table_span, value.into_inner()));
    }
    Ok(())
}

/// Reads `text` (with the `supplied` keys set) into `T`; errors as [`parse_toml_with`] says.
fn read_toml<T: serde::de::DeserializeOwned>(text: &str, lines: bool, supplied: &[Supplied]) -> Result<T, ConfigError> {
    let parse = |message: String| ConfigError::Parse { path: "<text>".into(), message };
    let mut root = DeTable::parse(text).map_err(|e| parse(not_toml(text, lines, &e)))?;
    supply(text, &mut root, supplied, |span| at(text, lines, Some(span.start))).map_err(parse)?;
    tables_are_tables(text, root.get_ref(), lines).map_err(parse)?;
    let document = root.get_ref().clone();
    let deserializer = toml::de::Deserializer::from(root);
    serde_path_to_error::deserialize(deserializer)
        .map_err(|e| parse(in_user_terms(text, lines, &document, e.path().to_string(), e.inner())))
}

/// The error of text that is not TOML: a key or table given twice is named, as the user wrote
/// it; any other error is TOML's own, with its place.
fn not_toml(text: &str, lines: bool, e: &toml::de::Error) -> String {
    let line = at(text, lines, e.span().map(|s| s.start));
    match e.span().and_then(|s| text.get(s)) {
        Some(key) if e.message() == "duplicate key" => {
            let key = shorten(key, VALUE_CHARS);
            let sweep = if key == "material" {
                ": one [material] table, or several [[material]] tables (a sweep), not both"
            } else {
                ": each key and table once (a sweep is a list: `key = [a, b]`)"
            };
            format!("`{key}` is given twice{line}{sweep}")
        }
        _ => format!("not TOML{line}: {}", shorten(e.message(), MESSAGE_CHARS)),
    }
}

/// serde's error `e` at `path` (serde_path_to_error's, `.` for the top) in the user's terms:
/// one line naming the field, the value as written (shortened), its line and column, and what
/// is allowed. Type errors ("invalid type: map, expected f64") say what the field takes.
fn in_user_terms(text: &str, lines: bool, root: &DeTable, path: String, e: &toml::de::Error) -> String {
    let message = e.message();
    let key_in = |prefix: &str| message.strip_prefix(prefix).and_then(|m| m.split('`').next());
    // A key of a table read whole (a material) that serde's path does not reach.
    let with_key = |k: &str| match path.as_str() {
        "." => k.to_string(),
        p if p == k || p.ends_with(&format!(".{k}")) => p.to_string(),
        p => format!("{p}.{k}"),
    };
    if let Some(k) = key_in("unknown field `") {
        let field = with_key(k);
        let line = at(text, lines, find(root, &field).map(|(key, _)| key.start).or(e.span().map(|s| s.start)));
        let keys = message
            .split_once(", expected ")
            .map_or("none".to_string(), |(_, keys)| keys.trim_start_matches("one of ").to_string());
        return format!("`{field}` is not a known key{line}: the keys here are {keys}");
    }
    if let Some(k) = key_in("missing field `") {
        if path == "." {
            // At the top level no line says where the key belongs; `[table]` is a `smithwalk lut`
            // config's grid.
            let field = if RUN_TABLES.contains(&k) || k == "table" { format!("[{k}]") } else { k.to_string() };
            let allowed = allowed_value(k).unwrap_or_else(|| message.to_string());
            return ConfigError::Missing { field, place: String::new(), allowed }.to_string();
        }
        let field = with_key(k);
        let place = match find(root, &path).filter(|_| lines) {
            Some((_, table)) => format!(" from the table at {}", place(text, table.start)),
            None => String::new(),
        };
        let key = without_indices(&field);
        // Only a dielectric needs an `eta`, one number (a conductor's is per channel, and optional).
        let eta = (key == "material.eta").then(|| "the relative index n_inside / n_outside, > 0 and != 1".to_string());
        let allowed = allowed_value(&key).or(eta).unwrap_or_else(|| message.to_string());
        return ConfigError::Missing { field, place, allowed }.to_string();
    }
    let (field, allowed) = match key_in(KEY_ERROR) {
        Some(k) => (with_key(k), message.split_once("`: ").map_or(message, |(_, m)| m).to_string()),
        None if path == "." => return format!("{message}{}", at(text, lines, e.span().map(|s| s.start))),
        None => (path, message.to_string()),
    };
    let found = find(root, &field);
    let line = at(text, lines, found.as_ref().map(|(_, v)| v.start).or(e.span().map(|s| s.start)));
    let value = match find_value(root, &field) {
        Some(value) => written(text, value),
        None => e.span().and_then(|s| text.get(s)).unwrap_or("?").to_string(),
    };
    let value = shorten(&value, VALUE_CHARS);
    let is_type_error = ["invalid type: ", "invalid value: ", "invalid length "].iter().any(|p| allowed.starts_with(p))
        || allowed.ends_with("overflowed");
    let allowed = match allowed_value(&without_indices(&field)) {
        Some(described) if is_type_error => described,
        _ if is_type_error => rust_in_user_terms(allowed.split_once(", expected ").map_or("", |(_, e)| e)),
        _ => allowed,
    };
    format!("`{field}` = {value} is not allowed{line}: {}", shorten(&allowed, MESSAGE_CHARS))
}

/// What serde expected, for a field [`allowed_value`] does not describe, with Rust's type names
/// in user terms.
fn rust_in_user_terms(expected: &str) -> String {
    let expected = match expected {
        "u64" | "usize" | "u32" => "an integer >= 0",
        "i64" => "an integer",
        "f64" => "a number",
        "a sequence" => "a list",
        "a map" => "a table",
        "" => "a value of another type",
        e if e.starts_with("struct ") => "a table",
        e => e,
    };
    expected.replace("an array of length 2", "a list of two numbers")
}

/// `field` without its list indices: `material[1].eta` is `material.eta`.
fn without_indices(field: &str) -> String {
    field.split('[').map(|part| part.split_once(']').map_or(part, |(_, rest)| rest)).collect()
}

/// What a key (its dotted path without list indices) takes, for the errors that say a value is
/// of the wrong type or that a required key is missing. Keys it does not describe are described
/// by their type's own error (`Channels`, the names of an enum).
pub(super) fn allowed_value(key: &str) -> Option<String> {
    let kinds = "\"conductor\", \"dielectric\", \"diffuse\" or \"hammon\"";
    let integer = |range: &str| format!("an integer {range}, e.g. 1000000 or 1_000_000");
    Some(match key {
        "paths" => format!("photons per case, {}", integer("from 2 to 10^15")),
        "seed" => "an integer from 0 to 2^64 - 1".into(),
        "table" => "a table with the grid of a `smithwalk lut` config, at least `paths` (configs/lut-*.toml)".into(),
        "table.paths" => format!("photons per cell, {}", integer("from 2 to 10^15")),
        "table.mu" | "table.alpha" | "table.eta" => "a node count, an integer from 1 to 1024".into(),
        "table.alpha_range" | "table.eta_range" => "a range [lo, hi] of two numbers".into(),
        "table.max_order" => "an order, an integer from 1 to 64".into(),
        "table.avg_nodes" => "a node count, an integer from 2 to 256".into(),
        "table.target_stderr" | "precision.target_rel_stderr" | "precision.target_stderr" => {
            "a standard error, a number > 0".into()
        }
        "table.seed" => "an integer from 0 to 2^64 - 1".into(),
        "surface" => "a table with `alpha`, the roughness".into(),
        "material" => format!("a table with `kind` = {kinds}, or several `[[material]]` tables"),
        "incident" => "a table with `theta_deg` or `theta_rad`, the incident polar angles".into(),
        "detector" | "energy" | "precision" | "compare" => format!("a table, [{key}] and its keys (README.md)"),
        "surface.alpha" => "a roughness > 0 and at most 1e4, a list of them (a sweep) or [[alpha_x, alpha_y]]".into(),
        "surface.gamma" => "the Student-T shape (ndf = \"student-t\" only), a number > 1.5 or a list of them".into(),
        "material.kind" => kinds.into(),
        "material.name" => "a label, a string of at most 100 characters".into(),
        "incident.theta_deg" => {
            "a polar angle in [0, 90) or a list of them (or `theta_rad`, in radians, in [0, pi/2))".into()
        }
        "incident.theta_rad" => "a polar angle in [0, pi/2) or a list of them".into(),
        "incident.phi_deg" => "an azimuth in degrees in [-360, 360] or a list of them".into(),
        "detector.cos_theta_bins" | "detector.phi_bins" => "a bin count, an integer from 1 to 4096".into(),
        "detector.max_order" => "an order, an integer >= 1".into(),
        "energy.split" => "true or false".into(),
        "energy.threshold" => "a weight, a number in [0, 1]".into(),
        "precision.orders" => "an order slot, an integer >= 0".into(),
        "compare.models" => {
            let names: Vec<&str> = Model::ALL.iter().map(|m| m.name()).collect();
            format!("a list of models from {}", names.join(", "))
        }
        "compare.paths" => format!("photons per case, {}", integer("from 2 to 10^15")),
        _ => return None,
    })
}

/// Where a config error is, in the user's text: `line N, column M` (both from 1, the column in
/// characters), from a byte offset of the text.
pub fn place(text: &str, offset: usize) -> String {
    let before = text.get(..offset.min(text.len())).unwrap_or(text);
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    format!("line {line}, column {column}")
}

/// ` (line N, column M)` at `offset` of `text`, or nothing without an offset or when the text
/// has no lines the user wrote (`lines` is false: a dict).
fn at(text: &str, lines: bool, offset: Option<usize>) -> String {
    offset.filter(|_| lines).map_or(String::new(), |o| format!(" ({})", place(text, o)))
}

/// The spans of the key and of the value at `field` (a dotted path with list indices, as errors
/// name it: `material[1].eta`, `surface.alpha[0]`) in the parsed document, or of the deepest
/// part of it that is there; none when not even its first key is.
fn find(root: &DeTable, field: &str) -> Option<(Range<usize>, Range<usize>)> {
    let mut table = root;
    let mut found = None;
    for segment in field.split('.') {
        let (name, indices) = segment.split_once('[').map_or((segment, ""), |(n, i)| (n, i));
        let Some((key, mut value)) = table.iter().find(|(k, _)| k.get_ref() == name) else { break };
        let mut key_span = key.span();
        for index in indices.split('[').filter_map(|i| i.trim_end_matches(']').parse::<usize>().ok()) {
            match value.get_ref() {
                DeValue::Array(items) if index < items.len() => {
                    value = &items[index];
                    key_span = value.span();
                }
                _ => break,
            }
        }
        found = Some((key_span, value.span()));
        match value.get_ref() {
            DeValue::Table(inner) => table = inner,
            _ => break,
        }
    }
    found
}

/// The value at `field` in the parsed document, if it is there.
fn find_value<'a, 'i>(root: &'a DeTable<'i>, field: &str) -> Option<&'a toml::Spanned<DeValue<'i>>> {
    let mut table = Some(root);
    let mut value = None;
    for segment in field.split('.') {
        let (name, indices) = segment.split_once('[').map_or((segment, ""), |(n, i)| (n, i));
        let mut v = table?.iter().find(|(k, _)| k.get_ref() == name)?.1;
        for index in indices.split('[').filter(|i| !i.is_empty()) {
            v = v.get_ref().as_array()?.get(index.trim_end_matches(']').parse::<usize>().ok()?)?;
        }
        table = match v.get_ref() {
            DeValue::Table(inner) => Some(inner),
            _ => None,
        };
        value = Some(v);
    }
    value
}

/// A value as written in `text`; a table given by its header (`[surface.ndf]`, or in the text
/// made from a dict) inline, `{ key = value }`, since its span is only the header.
fn written(text: &str, value: &toml::Spanned<DeValue>) -> String {
    let own = text.get(value.span()).unwrap_or("?");
    match value.get_ref() {
        DeValue::Table(table) if own.starts_with('[') => {
            let entries: Vec<String> =
                table.iter().map(|(k, v)| format!("{} = {}", k.get_ref(), written(text, v))).collect();
            if entries.is_empty() { "{}".to_string() } else { format!("{{ {} }}", entries.join(", ")) }
        }
        _ => own.to_string(),
    }
}

/// A configuration error found after `text` was read (by validation) with the place in the
/// text of the field it names: a value's line and column, or the line and column of the table a
/// missing key belongs in (none when `lines` is false, for a dict).
pub fn locate(e: ConfigError, text: &str, lines: bool) -> ConfigError {
    let Ok(root) = DeTable::parse(text) else { return e };
    let root = root.get_ref();
    let parse = |message: String| ConfigError::Parse { path: "<text>".into(), message };
    match e {
        ConfigError::Invalid { field, value, allowed } => {
            let line = at(text, lines, find(root, &field).map(|(_, v)| v.start));
            parse(format!("`{field}` = {value} is not allowed{line}: {allowed}"))
        }
        ConfigError::Missing { field, place, allowed } if place.is_empty() => {
            let table = field.rsplit_once('.').map_or("", |(t, _)| t);
            let place = match find(root, table).filter(|_| !table.is_empty() && lines) {
                Some((_, span)) => format!(" from the table at {}", self::place(text, span.start)),
                None => place,
            };
            parse(ConfigError::Missing { field, place, allowed }.to_string())
        }
        ConfigError::Exclusive { first, second } => {
            let line = at(text, lines, find(root, &second).map(|(k, _)| k.start));
            parse(format!("`{first}` and `{second}` are both given{line}: give one of them"))
        }
        e => e,
    }
}

/// Refuses a run config's table (`[detector]`, ...) given as something else: serde would read an
/// array as the table's fields in order (`detector = []` took every default).
fn tables_are_tables(text: &str, root: &DeTable, lines: bool) -> Result<(), String> {
    for (key, value) in root.iter() {
        let name = key.get_ref().as_ref();
        let is_table = match value.get_ref() {
            DeValue::Table(_) => true,
            // Several materials are a sweep; an array of anything else is refused by the
            // material's own reading, which names the item.
            DeValue::Array(_) => name == "material",
            _ => false,
        };
        if (RUN_TABLES.contains(&name) || name == "table") && !is_table {
            let line = at(text, lines, Some(value.span().start));
            let value = text.get(value.span()).map_or("?".to_string(), |v| shorten(v, VALUE_CHARS));
            let allowed = allowed_value(name).unwrap_or_else(|| format!("a table, [{name}] and its keys"));
            return Err(format!("`{name}` = {value} is not allowed{line}: {allowed}"));
        }
    }
    Ok(())
}
/// Longest quoted value and message in a config error.
pub(super) const VALUE_CHARS: usize = 60;
const MESSAGE_CHARS: usize = 300;

/// `text` on one line (runs of whitespace as one space), cut in the middle to at most `max`
/// characters: long inputs are quoted shortened, never echoed whole.
pub fn shorten(text: &str, max: usize) -> String {
    let one_line = |s: &str| s.split_whitespace().collect::<Vec<_>>().join(" ");
    if text.chars().nth(max).is_none() {
        return one_line(text);
    }
    let head: String = text.chars().take(max / 2).collect();
    let tail: String = text.chars().rev().take(max / 2).collect::<Vec<_>>().into_iter().rev().collect();
    format!("{} … {} ({} bytes)", one_line(&head), one_line(&tail), text.len())
}
