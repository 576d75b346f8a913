//! Reading TOML text into configuration types, with errors in the user's terms: one line
//! naming the field (its dotted path), the value as written and what is allowed, and its line.

use std::borrow::Cow;

use serde::Deserialize;
use toml::de::{DeTable, DeValue};

use super::compare::Model;
use super::error::ConfigError;
use super::material::MaterialConfig;

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

/// [`parse_toml`], with the errors' line numbers only when `lines` (text made from a dict has
/// lines the user never saw).
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
    let shown = |line: Option<usize>| line.filter(|_| lines);
    let line_at = |start: usize| text[..start.min(text.len())].matches('\n').count() + 1;
    let line_of = |e: &toml::de::Error| shown(e.span().map(|s| line_at(s.start)));
    let at = |e: &toml::de::Error| at_line(line_of(e));
    let mut root = DeTable::parse(text)
        .map_err(|e| parse(format!("not TOML{}: {}", at(&e), shorten(e.message(), MESSAGE_CHARS))))?;
    supply(text, &mut root, supplied, |span| at_line(shown(Some(line_at(span.start))))).map_err(parse)?;
    let deserializer = toml::de::Deserializer::from(root);
    serde_path_to_error::deserialize(deserializer).map_err(|e| {
        let field = e.path().to_string();
        let inner = e.inner();
        let value = inner.span().and_then(|s| text.get(s)).map_or("?".to_string(), |v| shorten(v, VALUE_CHARS));
        let allowed = shorten(&in_user_terms(&field, inner.message()), MESSAGE_CHARS);
        // Keys inside a material (a table tagged by `kind`) are not on serde's path.
        let key = |prefix: &str| inner.message().strip_prefix(prefix).and_then(|m| m.split('`').next());
        let line = at(inner);
        match (key("unknown field `"), key("missing field `")) {
            (Some(k), _) => {
                let field = if field.ends_with(k) { field } else { format!("{field}.{k}") };
                parse(format!("`{field}` is not a known key{line}: {allowed}"))
            }
            // At the top level the span is the whole text: no line says where the key belongs.
            (None, Some(k)) if field == "." => {
                // `[table]` is a `smithwalk lut` config's grid.
                let field = if RUN_TABLES.contains(&k) || k == "table" { format!("[{k}]") } else { k.to_string() };
                let allowed = required(k).unwrap_or(allowed);
                parse(ConfigError::Missing { field, place: String::new(), allowed }.to_string())
            }
            (None, Some(k)) => {
                // The span of a table of `[[material]]` is that of the first one.
                let line = match material_index(&field) {
                    Some(Some(i)) => shown(material_header(&text.lines().collect::<Vec<_>>(), Some(i)).map(|h| h + 1)),
                    _ => line_of(inner),
                };
                let place = line.map_or(String::new(), |n| format!(" from the table at line {n}"));
                let allowed = required(&format!("{}.{k}", without_indices(&field))).unwrap_or(allowed);
                parse(ConfigError::Missing { field: format!("{field}.{k}"), place, allowed }.to_string())
            }
            _ if field == "." => parse(format!("{allowed}{line}")),
            _ => match material_culprit(text, &field, inner.message()) {
                Some(Culprit { key, value, line }) => {
                    let line = at_line(shown(line));
                    parse(format!("`{field}.{key}` = {value} is not allowed{line}: {allowed}"))
                }
                None => parse(format!("`{field}` = {value} is not allowed{line}: {allowed}")),
            },
        }
    })
}

/// serde's `message` about `field` with Rust's type names said in user terms: `expected u64`
/// is an integer in the field's range, `expected f64` a number.
fn in_user_terms(field: &str, message: &str) -> String {
    let integer = match without_indices(field).as_str() {
        "paths" | "compare.paths" | "table.paths" => "an integer from 2 to 10^15, e.g. 1000000 or 1_000_000",
        "seed" => "an integer >= 0",
        "detector.cos_theta_bins" | "detector.phi_bins" => "an integer from 1 to 4096",
        _ => "an integer >= 1",
    };
    ["u64", "usize", "u32"]
        .into_iter()
        .fold(message.to_string(), |m, rust| m.replace(&format!("expected {rust}"), &format!("expected {integer}")))
        .replace("expected f64", "expected a number")
}

/// ` (line n)`, or nothing without a line.
fn at_line(line: Option<usize>) -> String {
    line.map_or(String::new(), |n| format!(" (line {n})"))
}

/// `field` without its list indices: `material[1].eta` is `material.eta`.
fn without_indices(field: &str) -> String {
    field.split('[').map(|part| part.split_once(']').map_or(part, |(_, rest)| rest)).collect()
}

/// What a required table or key (its dotted path without list indices) should be, for the
/// error that says it is missing.
pub(super) fn required(key: &str) -> Option<String> {
    let kinds = "\"conductor\", \"dielectric\", \"diffuse\" or \"hammon\"";
    Some(match key {
        "paths" => "photons per case, from 2 to 10^15".into(),
        "table" => "a table with the grid of a `smithwalk lut` config, at least `paths` (configs/lut-*.toml)".into(),
        "table.paths" => "photons per cell, from 2 to 10^15".into(),
        "surface" => "a table with `alpha`, the roughness".into(),
        "material" => format!("a table with `kind` = {kinds}, or several `[[material]]` tables"),
        "incident" => "a table with `theta_deg` or `theta_rad`, the incident polar angles".into(),
        "surface.alpha" => "a roughness > 0 and at most 1e4, a list of them (a sweep) or [[alpha_x, alpha_y]]".into(),
        "material.kind" => kinds.into(),
        "material.eta" => "the relative index n_inside / n_outside, > 0 and != 1".into(),
        "incident.theta_deg" => {
            "a polar angle in [0, 90) or a list of them (or `theta_rad`, in radians, in [0, pi/2))".into()
        }
        "compare.models" => {
            let names: Vec<&str> = Model::ALL.iter().map(|m| m.name()).collect();
            format!("a list of models from {}", names.join(", "))
        }
        _ => return None,
    })
}

/// The key of a material table whose value is wrong, its value and its line.
struct Culprit {
    key: String,
    value: String,
    line: Option<usize>,
}

/// Which key of the material at `field` (`material` or `material[i]`) causes the error
/// `message`. Serde reports errors of values inside a material at the whole table, since the
/// table is tagged by `kind` and read as a whole before its keys are; the culprit is the key
/// whose removal makes the error go away or change. Its line is that of the key after the
/// table's header (none for an inline table).
fn material_culprit(text: &str, field: &str, message: &str) -> Option<Culprit> {
    let document: toml::Table = toml::from_str(text).ok()?;
    let index = material_index(field)?;
    let table = match (document.get("material")?, index) {
        (toml::Value::Table(t), None) => t,
        (toml::Value::Array(a), Some(i)) => a.get(i)?.as_table()?,
        _ => return None,
    };
    let key = table.keys().filter(|k| *k != "kind").find(|k| {
        let mut without = table.clone();
        without.remove(k.as_str());
        MaterialConfig::deserialize(toml::Value::Table(without)).map_or_else(|e| e.message() != message, |_| true)
    })?;
    let value = shorten(&table[key].to_string(), VALUE_CHARS);
    // The key's line: the first `key =` after the header of the material's table.
    let lines: Vec<&str> = text.lines().collect();
    let line = material_header(&lines, index).and_then(|h| {
        lines[h + 1..]
            .iter()
            .take_while(|l| !l.trim_start().starts_with('['))
            .position(|l| l.split('=').next().is_some_and(|k| k.trim() == key))
            .map(|n| h + 1 + n + 1)
    });
    Some(Culprit { key: key.clone(), value, line })
}

/// Which material `field` names: `Some(None)` for `material` (one table), `Some(Some(i))` for
/// `material[i]`, `None` for any other field.
fn material_index(field: &str) -> Option<Option<usize>> {
    match field.strip_prefix("material")? {
        "" => Some(None),
        rest => Some(Some(rest.strip_prefix('[')?.strip_suffix(']')?.parse::<usize>().ok()?)),
    }
}

/// The index (from 0) of the line of the header of material `index` (`[material]`, or the
/// `index`-th `[[material]]`); none for inline tables.
fn material_header(lines: &[&str], index: Option<usize>) -> Option<usize> {
    let is_header = |l: &str| {
        let l: String = l.chars().filter(|c| !c.is_whitespace()).collect();
        l == "[material]" || l == "[[material]]"
    };
    lines.iter().enumerate().filter(|(_, l)| is_header(l)).nth(index.unwrap_or(0)).map(|(n, _)| n)
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
