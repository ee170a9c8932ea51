//! Where a TOML file is wrong: the field path and line of a parse error, and the key at
//! fault inside an entry of an array of tables (serde reports those against the whole entry).

use super::schema::*;
use crate::error::{Error, Result};
use std::path::Path;

/// The entry of an array of tables (`[[bodies]]`, `[[joints]]`, `[[loads]]`, `[[probes]]`)
/// that fails to parse, with the key at fault and its line: serde reports errors inside
/// internally tagged or untagged entries against the whole entry, so each entry is parsed
/// on its own, and the key at fault is the one whose removal changes the error (the
/// `type` tag last: removing it always does). `None` when every entry parses by itself.
pub(super) fn entry_error(text: &str, path: &Path) -> Option<Error> {
    fn first_error<T: serde::de::DeserializeOwned>(v: &toml::Value) -> Option<String> {
        v.clone().try_into::<T>().err().map(|e| e.message().to_string())
    }
    let doc: toml::Table = toml::from_str(text).ok()?;
    type FirstError = fn(&toml::Value) -> Option<String>;
    let kinds: [(&str, FirstError); 4] = [
        ("bodies", first_error::<BodySpec>),
        ("joints", first_error::<JointSpec>),
        ("loads", first_error::<LoadSpec>),
        ("probes", first_error::<ProbeSpec>),
    ];
    for (name, parse) in kinds {
        let Some(toml::Value::Array(items)) = doc.get(name) else { continue };
        for (i, item) in items.iter().enumerate() {
            let Some(message) = parse(item) else { continue };
            let key = item.as_table().and_then(|t| {
                let changes = |k: &String| {
                    let mut rest = t.clone();
                    rest.remove(k);
                    parse(&toml::Value::Table(rest)).as_deref() != Some(message.as_str())
                };
                t.keys()
                    .filter(|k| k.as_str() != "type")
                    .find(|k| changes(k))
                    .or_else(|| t.keys().find(|k| changes(k)))
                    .cloned()
            });
            let line =
                entry_line(text, name, i).map(|l| key.as_deref().and_then(|k| key_line(text, l, k)).unwrap_or(l));
            let field = match (&key, line) {
                (Some(k), Some(l)) => format!("{name}[{i}].{k} (line {l})"),
                (Some(k), None) => format!("{name}[{i}].{k}"),
                (None, Some(l)) => format!("{name}[{i}] (line {l})"),
                (None, None) => format!("{name}[{i}]"),
            };
            return Some(Error::input(path, field, message));
        }
    }
    None
}

/// The line (1-based) of the `[[name]]` header of entry `i`, if written that way.
pub(super) fn entry_line(text: &str, name: &str, i: usize) -> Option<usize> {
    let is_header =
        |l: &str| l.trim().strip_prefix("[[").and_then(|r| r.split("]]").next()).is_some_and(|n| n.trim() == name);
    text.lines().enumerate().filter(|(_, l)| is_header(l)).nth(i).map(|(k, _)| k + 1)
}

/// The line of `key = …` in the table whose header is on line `header`.
fn key_line(text: &str, header: usize, key: &str) -> Option<usize> {
    for (k, l) in text.lines().enumerate().skip(header) {
        let l = l.trim();
        if l.starts_with('[') {
            return None;
        }
        let lhs = l.split('=').next().unwrap_or("").trim().trim_matches('"');
        if l.contains('=') && (lhs == key || lhs.starts_with(&format!("{key}."))) {
            return Some(k + 1);
        }
    }
    None
}

/// The dotted key path (or line) at byte `pos` of a TOML text, for error messages.
/// Parses a TOML file into its schema; an error names the file, the field path (with its
/// line) and the problem. Shared by model and pipeline files.
pub(crate) fn parse_toml<T: serde::de::DeserializeOwned>(text: &str, path: &Path) -> Result<T> {
    toml::from_str(text).map_err(|e| {
        let field = e.span().map(|s| locate(text, s.start)).unwrap_or_else(|| "(file)".into());
        Error::input(path, field, e.message().to_string())
    })
}

fn locate(text: &str, pos: usize) -> String {
    // counted on bytes: a span that is not on a char boundary must not panic
    let line = text.as_bytes()[..pos.min(text.len())].iter().filter(|&&b| b == b'\n').count() + 1;
    let mut table = String::new();
    let mut counts: std::collections::HashMap<String, usize> = Default::default();
    for l in text.lines().take(line) {
        let l = l.trim();
        if let Some(name) = l.strip_prefix("[[").and_then(|r| r.strip_suffix("]]")) {
            let c = counts.entry(name.to_string()).or_insert(0);
            table = format!("{name}[{}]", *c);
            *c += 1;
        } else if let Some(name) = l.strip_prefix('[').and_then(|r| r.strip_suffix(']')) {
            table = name.to_string();
        }
    }
    let this = text.lines().nth(line - 1).unwrap_or("");
    let key = this.split('=').next().unwrap_or("").trim();
    let key = if this.contains('=') && !key.is_empty() { key } else { "" };
    match (table.is_empty(), key.is_empty()) {
        (true, true) => format!("line {line}"),
        (true, false) => format!("{key} (line {line})"),
        (false, true) => format!("{table} (line {line})"),
        (false, false) => format!("{table}.{key} (line {line})"),
    }
}
