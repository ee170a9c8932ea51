//! Where a TOML file is wrong: the field path and line of a parse error, and the key at
//! fault inside an entry of an array of tables (serde reports those against the whole entry).

use super::schema::*;
use crate::error::{Error, Result};
use std::path::Path;

/// The entry of an array of tables (`[[bodies]]`, `[[joints]]`, `[[loads]]`, `[[probes]]`)
/// that fails to parse, with the key at fault and its line: serde reports errors inside
/// internally tagged or untagged entries against the whole entry, so each entry is parsed
/// on its own and the key at fault is searched for ([`fault_path`]), down through nested
/// tables such as a piecewise function's pieces. `None` when every entry parses by itself.
pub(super) fn entry_error(text: &str, path: &Path) -> Option<Error> {
    fn first_error<T: serde::de::DeserializeOwned>(v: &toml::Value) -> Option<String> {
        v.clone().try_into::<T>().err().map(|e| e.message().to_string())
    }
    let doc: toml::Table = toml::from_str(text).ok()?;
    type FirstError = fn(&toml::Value) -> Option<String>;
    let kinds: [(&str, FirstError); 5] = [
        ("bodies", first_error::<BodySpec>),
        ("joints", first_error::<JointSpec>),
        ("loads", first_error::<LoadSpec>),
        ("masses", first_error::<MassSpec>),
        ("probes", first_error::<ProbeSpec>),
    ];
    for (name, parse) in kinds {
        let Some(toml::Value::Array(items)) = doc.get(name) else { continue };
        for (i, item) in items.iter().enumerate() {
            let Some(message) = parse(item) else { continue };
            let mut fault = fault_path(item, |v| parse(v).as_deref() == Some(message.as_str()));
            // a missing key belongs to the table that lacks it (removing a sibling changes
            // the error too, to that sibling missing): named as that table's key, on the
            // line where the table opens, as the model's own checks name a missing key
            let missing = message.strip_prefix("missing field `").and_then(|m| m.strip_suffix('`'));
            if missing.is_some() && value_at(item, &fault).is_some_and(|v| !v.is_table()) {
                fault.pop();
            }
            let mut full = vec![Step::Key(name.to_string()), Step::Index(i)];
            full.extend(fault.iter().cloned());
            let line = step_line(text, &full).or_else(|| entry_line(text, name, i));
            if let Some(key) = missing {
                fault.push(Step::Key(key.to_string()));
            }
            let mut field = format!("{name}[{i}]");
            for step in &fault {
                match step {
                    Step::Key(k) => field += &format!(".{k}"),
                    Step::Index(j) => field += &format!("[{j}]"),
                }
            }
            if let Some(l) = line {
                field += &format!(" (line {l})");
            }
            return Some(Error::input(path, field, message));
        }
    }
    None
}

/// One step of a path into a TOML value: a key of a table or an index into an array.
#[derive(Clone, Debug, PartialEq)]
enum Step {
    Key(String),
    Index(usize),
}

/// The path below `entry` to the value at fault: the first key (the `type` tag last, as
/// removing it always changes the error) or array element whose removal makes the error
/// differ (`fails_alike` false), then the same inside it, as long as it is a table or an
/// array of tables. An error of a value's type or an unknown key is raised where serde
/// meets the key, before any missing key is noticed, so removing another key leaves it
/// alike; removing the key at fault changes it.
fn fault_path(entry: &toml::Value, fails_alike: impl Fn(&toml::Value) -> bool) -> Vec<Step> {
    let mut path = Vec::new();
    loop {
        let children: Vec<Step> = match value_at(entry, &path) {
            Some(toml::Value::Table(t)) => {
                let keys = t.keys().filter(|k| k.as_str() != "type").chain(t.keys().filter(|k| k.as_str() == "type"));
                keys.map(|k| Step::Key(k.clone())).collect()
            }
            Some(toml::Value::Array(a)) if a.iter().all(|v| v.is_table()) => (0..a.len()).map(Step::Index).collect(),
            _ => break,
        };
        let culprit = children.into_iter().find(|c| {
            let mut at = path.clone();
            at.push(c.clone());
            !fails_alike(&without(entry, &at))
        });
        match culprit {
            Some(c) => path.push(c),
            None => break,
        }
    }
    path
}

fn value_at<'a>(v: &'a toml::Value, path: &[Step]) -> Option<&'a toml::Value> {
    path.iter().try_fold(v, |v, step| match (step, v) {
        (Step::Key(k), toml::Value::Table(t)) => t.get(k),
        (Step::Index(i), toml::Value::Array(a)) => a.get(*i),
        _ => None,
    })
}

/// A copy of `v` without the key or element at `path` (non-empty).
fn without(v: &toml::Value, path: &[Step]) -> toml::Value {
    let mut copy = v.clone();
    let (last, parent) = path.split_last().expect("a path to remove");
    let mut at = &mut copy;
    for step in parent {
        at = match (step, at) {
            (Step::Key(k), toml::Value::Table(t)) => t.get_mut(k).expect("the path exists"),
            (Step::Index(i), toml::Value::Array(a)) => &mut a[*i],
            _ => unreachable!("the path exists"),
        };
    }
    match (last, at) {
        (Step::Key(k), toml::Value::Table(t)) => {
            t.remove(k);
        }
        (Step::Index(i), toml::Value::Array(a)) => {
            a.remove(*i);
        }
        _ => unreachable!("the path exists"),
    }
    copy
}

/// The line (1-based) where the last step of `path` (from the document's root) is written:
/// the key's own line, or an array element's first line, from the parser's spans. The key's
/// line holds for every way of writing it (`[a.b]` headers, inline tables, dotted keys).
fn step_line(text: &str, path: &[Step]) -> Option<usize> {
    use toml::de::DeValue;
    let root = DeValue::Table(toml::de::DeTable::parse(text).ok()?.into_inner());
    let (mut value, mut start) = (&root, None);
    for step in path {
        let (at, v) = match (step, value) {
            (Step::Key(k), DeValue::Table(t)) => t.get_key_value(k.as_str()).map(|(key, v)| (key.span().start, v))?,
            (Step::Index(i), DeValue::Array(a)) => a.get(*i).map(|v| (v.span().start, v))?,
            _ => return None,
        };
        (value, start) = (v.get_ref(), Some(at));
    }
    Some(text.as_bytes()[..start?.min(text.len())].iter().filter(|&&b| b == b'\n').count() + 1)
}

/// A checked field's name (`time.dt`, `bodies[2].elements`, `joints[0].b.body`) with the
/// line it is written on, as parse errors name theirs: `bodies[2].elements (line 14)`. A
/// field not written (a missing key, a default) takes the line of the nearest enclosing
/// entry or table that is; a name that is no path of the text stays as it is.
pub(super) fn field_with_line(text: &str, field: &str) -> String {
    let mut path = Vec::new();
    for part in field.split('.') {
        let (key, rest) = part.split_once('[').unwrap_or((part, ""));
        if key.is_empty() {
            return field.to_string();
        }
        path.push(Step::Key(key.to_string()));
        for index in rest.split('[') {
            match index.strip_suffix(']').and_then(|i| i.parse().ok()) {
                Some(i) => path.push(Step::Index(i)),
                None if index.is_empty() => {}
                None => return field.to_string(),
            }
        }
    }
    match (1..=path.len()).rev().find_map(|n| step_line(text, &path[..n])) {
        Some(line) => format!("{field} (line {line})"),
        None => field.to_string(),
    }
}

/// An input error about the TOML file `file` whose `text` is given, with the line of its
/// field added where the field is a path of that text and names no line yet
/// (`train.load_scales (line 7)`); any other error as it is.
pub(crate) fn with_field_line(e: Error, file: &Path, text: &str) -> Error {
    match e {
        Error::Input { file: f, field, problem } if f == file.display().to_string() && !field.contains("(line ") => {
            Error::Input { field: field_with_line(text, &field), file: f, problem }
        }
        other => other,
    }
}

/// `with_field_line` for an error found after the file was loaded (a check a stage makes
/// while it runs, e.g. `train --snapshots-only` on a greedy pipeline): the field of an input
/// error about a TOML file gets its line from the file as it is now; any other error, or a
/// file that can no longer be read, as it is.
pub fn with_field_line_from_file(e: Error) -> Error {
    let Error::Input { file, field, .. } = &e else { return e };
    if !file.ends_with(".toml") || field.contains("(line ") {
        return e;
    }
    let file = std::path::PathBuf::from(file);
    match std::fs::read_to_string(&file) {
        Ok(text) => with_field_line(e, &file, &text),
        Err(_) => e,
    }
}

/// The line (1-based) of the `[[name]]` header of entry `i`, if written that way.
pub(super) fn entry_line(text: &str, name: &str, i: usize) -> Option<usize> {
    let is_header =
        |l: &str| l.trim().strip_prefix("[[").and_then(|r| r.split("]]").next()).is_some_and(|n| n.trim() == name);
    text.lines().enumerate().filter(|(_, l)| is_header(l)).nth(i).map(|(k, _)| k + 1)
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
    // the keys down to `pos` through the inline tables of the line (`greedy = { …, measure =
    // "x" }`: greedy.measure), else the line's first key
    let line_start = text.as_bytes()[..pos.min(text.len())].iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
    let inline = text.get(line_start..pos.min(text.len())).map(inline_key_path).unwrap_or_default();
    let first = this.split('=').next().unwrap_or("").trim();
    let key = if !inline.is_empty() {
        inline.join(".")
    } else if this.contains('=') && !first.is_empty() {
        first.to_string()
    } else {
        String::new()
    };
    match (table.is_empty(), key.is_empty()) {
        (true, true) => format!("line {line}"),
        (true, false) => format!("{key} (line {line})"),
        (false, true) => format!("{table} (line {line})"),
        (false, false) => format!("{table}.{key} (line {line})"),
    }
}

/// The keys that lead to the end of `prefix` (the start of a line up to an error's
/// position) through inline tables: `greedy = { range = [0.5, 1.5], measure = ` gives
/// `["greedy", "measure"]`. Empty when the prefix ends on no `key =` (a header, a key
/// already closed by a `,`). Strings are skipped, so a `=`, `{` or `,` inside one counts
/// for nothing, and so is everything inside arrays but their nested inline tables.
fn inline_key_path(prefix: &str) -> Vec<String> {
    let (mut open, mut current, mut token) = (Vec::<String>::new(), None::<String>, String::new());
    let mut arrays = 0_usize;
    let mut chars = prefix.chars();
    while let Some(c) = chars.next() {
        match c {
            '"' | '\'' => {
                // to the closing quote (a basic string's \" does not close it)
                let mut escaped = false;
                for d in chars.by_ref() {
                    if d == c && !(escaped && c == '"') {
                        break;
                    }
                    escaped = d == '\\' && !escaped;
                }
            }
            '=' => current = Some(token.trim().to_string()).filter(|k| !k.is_empty()),
            '{' => open.extend(current.take()),
            '}' => {
                open.pop();
                current = None;
            }
            '[' => arrays += 1,
            ']' => arrays = arrays.saturating_sub(1),
            ',' if arrays == 0 => current = None,
            _ => {}
        }
        if matches!(c, '=' | '{' | '}' | ',' | '[' | ']' | '"' | '\'') {
            token.clear();
        } else {
            token.push(c);
        }
    }
    match current {
        Some(k) => {
            open.push(k);
            open
        }
        None => Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::{field_with_line, inline_key_path, locate, with_field_line_from_file};
    use crate::error::Error;

    /// A stage's input error about a TOML file gets its field's line from the file; one
    /// that has a line, one about another kind of file, and one whose file is gone stay.
    #[test]
    fn a_stage_error_takes_its_line_from_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let toml = dir.path().join("p.toml");
        std::fs::write(&toml, "[train]\n# comment\ngreedy = { range = [0.5, 1.5] }\n").unwrap();
        let shown = |e: Error| with_field_line_from_file(e).to_string();
        assert!(shown(Error::input(&toml, "train.greedy", "no")).ends_with("train.greedy (line 3): no"));
        assert!(shown(Error::input(&toml, "train.greedy (line 9)", "no")).ends_with("train.greedy (line 9): no"));
        let h5 = dir.path().join("b.h5");
        std::fs::write(&h5, "[train]\ngreedy = 1\n").unwrap();
        assert!(shown(Error::input(&h5, "train.greedy", "no")).ends_with("train.greedy: no"));
        let gone = dir.path().join("gone.toml");
        assert!(shown(Error::input(&gone, "train.greedy", "no")).ends_with("train.greedy: no"));
        assert_eq!(shown(Error::usage("x")), "x");
    }

    /// A checked field's line: a key of a table, a key of an array-of-tables entry, a key
    /// inside an inline table, a missing key (its entry's line), and names that are no path
    /// of the text (unchanged).
    #[test]
    fn a_checked_field_takes_the_line_it_is_written_on() {
        let text = "[time]\ndt = 0.1\n\n[[bodies]]\nname = \"a\"\n\n[[bodies]]\nname = \"b\"\n\
                    youngs_modulus = { value = 1e9, parameter = \"E\" }\n";
        assert_eq!(field_with_line(text, "time.dt"), "time.dt (line 2)");
        assert_eq!(field_with_line(text, "bodies[1].name"), "bodies[1].name (line 8)");
        assert_eq!(
            field_with_line(text, "bodies[1].youngs_modulus.parameter"),
            "bodies[1].youngs_modulus.parameter (line 9)"
        );
        assert_eq!(field_with_line(text, "bodies[0].angle"), "bodies[0].angle (line 4)");
        assert_eq!(field_with_line(text, "time.t_end"), "time.t_end (line 1)");
        // an entry past the last: the array's first line
        assert_eq!(field_with_line(text, "bodies[3].name"), "bodies[3].name (line 4)");
        for field in ["joints", "joints[0].body", "joints[1] (line 25)", "(file)", ""] {
            assert_eq!(field_with_line(text, field), field);
        }
    }

    /// The key path through inline tables to an error's position: nested tables, arrays and
    /// strings holding `=`, `,` or `{` passed over; none after a closed entry.
    #[test]
    fn inline_keys_lead_to_the_position() {
        assert_eq!(inline_key_path("greedy = { range = [0.5, 1.5], measure = "), ["greedy", "measure"]);
        assert_eq!(inline_key_path("a = { b = { c = "), ["a", "b", "c"]);
        assert_eq!(inline_key_path("a = { s = \"x = {, y\", t = "), ["a", "t"]);
        assert_eq!(inline_key_path("a = { b = 1, "), Vec::<String>::new());
        assert_eq!(inline_key_path("range = [0.5, "), ["range"]);
        assert_eq!(inline_key_path(""), Vec::<String>::new());
        let text = "[train]\ngreedy = { range = [0.5, 1.5], measure = \"x\" }\n";
        assert_eq!(locate(text, text.find("\"x\"").unwrap()), "train.greedy.measure (line 2)");
        assert_eq!(locate(text, 0), "train (line 1)");
    }
}
