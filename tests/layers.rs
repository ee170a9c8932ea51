//! The layering of the source tree (docs/design.md): reads every `src/**/*.rs`, collects each
//! file's references to other files of the crate (`use` trees and inline paths starting with
//! `crate::`, `super::`, `self::`, a child module's name in a `use`, or `flexrom::` in the
//! binary; imports and `pub use` re-exports are followed to the file that defines the item), and fails on
//!
//! * an import cycle between files (a strongly connected set of more than one file), and
//! * an import running upward, or sideways between two top-level modules of one layer, in the
//!   layer order, top to bottom:
//!
//!   `main` → `cli` → `report` → `training` → `workflows` → `cost` → `records` → `pipeline`
//!   → `rom` → `io` → `simulate` → `analysis` → `model` → `reduction` | `physics`
//!   → `solver` → `linalg` → `output` → `limits` | `interrupt` → `error`
//!
//!   (`cli` is the binary's command handlers, below `main.rs`'s parsing and dispatch;
//!   `reduction` and `physics` share a layer and must not see each other: the reduction
//!   knows the physics only through the traits of `solver::model`; the rooms from `report`
//!   to `pipeline` are the workflow's concerns: presentation, offline training, online
//!   workflows, the cost model, what runs record and their files, the pipeline file).
//!
//! Comments, string literals and `#[cfg(test)]` modules are left out (a unit test may reach
//! wherever it needs). The expected results are structural, not numbers: no cycle, no
//! upward edge. `KNOWN` lists the edges that still break the rule, each with its reason; an entry that no longer occurs fails the test too,
//! so the list only shrinks. A self-check at the end runs the checker on a small made-up tree
//! with one cycle and one upward import, so the test can fail.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

const LAYERS: &[&[&str]] = &[
    &["main"],
    &["cli"],
    &["report"],
    &["training"],
    &["workflows"],
    &["cost"],
    &["records"],
    &["pipeline"],
    &["rom"],
    &["io"],
    &["simulate"],
    &["analysis"],
    &["model"],
    &["reduction", "physics"],
    &["solver"],
    &["linalg"],
    &["output"],
    &["limits", "interrupt"],
    &["error"],
];

/// Edges (from file module, to file module) that still break the layering, in files that
/// other branches edit at the time of writing; the lead removes them after the merge.
const KNOWN: &[(&str, &str, &str)] = &[];

/// One source file: its module path (`a::b`, `main` for the binary, `` for the crate root).
struct File {
    module: String,
    text: String,
}

fn module_of(rel: &Path) -> String {
    let mut parts: Vec<String> = rel.iter().map(|s| s.to_string_lossy().into_owned()).collect();
    let last = parts.pop().expect("a file name");
    let stem = last.trim_end_matches(".rs");
    if !(stem == "mod" || (parts.is_empty() && stem == "lib")) {
        parts.push(stem.to_string());
    }
    parts.join("::")
}

fn read_tree(dir: &Path, root: &Path, out: &mut Vec<File>) {
    let mut entries: Vec<_> =
        std::fs::read_dir(dir).expect("readable src dir").map(|e| e.expect("entry").path()).collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            read_tree(&p, root, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            let text = std::fs::read_to_string(&p).expect("readable source");
            out.push(File { module: module_of(p.strip_prefix(root).expect("under src")), text: strip(&text) });
        }
    }
}

/// The code without comments, string/char literals and `#[cfg(test)]` items (their text is
/// replaced by spaces so that words on either side stay apart).
fn strip(src: &str) -> String {
    let b: Vec<char> = src.chars().collect();
    let mut out = String::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        let next = b.get(i + 1).copied();
        if c == '/' && next == Some('/') {
            while i < b.len() && b[i] != '\n' {
                i += 1;
            }
        } else if c == '/' && next == Some('*') {
            let mut depth = 0;
            while i < b.len() {
                if b[i] == '/' && b.get(i + 1) == Some(&'*') {
                    depth += 1;
                    i += 2;
                } else if b[i] == '*' && b.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
            out.push(' ');
        } else if c == 'r'
            && (next == Some('"') || (next == Some('#') && !prev_is_ident(&b, i)))
            && !prev_is_ident(&b, i)
        {
            // raw string r"…" or r#"…"#
            let mut j = i + 1;
            let mut hashes = 0;
            while b.get(j) == Some(&'#') {
                hashes += 1;
                j += 1;
            }
            if b.get(j) != Some(&'"') {
                out.push(c);
                i += 1;
                continue;
            }
            j += 1;
            loop {
                if j >= b.len() {
                    break;
                }
                if b[j] == '"' && (0..hashes).all(|h| b.get(j + 1 + h) == Some(&'#')) {
                    j += 1 + hashes;
                    break;
                }
                j += 1;
            }
            i = j;
            out.push(' ');
        } else if c == '"' {
            i += 1;
            while i < b.len() && b[i] != '"' {
                if b[i] == '\\' {
                    i += 1;
                }
                i += 1;
            }
            i += 1;
            out.push(' ');
        } else if c == '\'' {
            // a char literal ('x', '\n', '\u{..}'); a lifetime ('a) is kept as it is
            let close = if next == Some('\\') {
                (i + 2..b.len().min(i + 12)).find(|&j| b[j] == '\'')
            } else if b.get(i + 2) == Some(&'\'') {
                Some(i + 2)
            } else {
                None
            };
            match close {
                Some(j) => {
                    i = j + 1;
                    out.push(' ');
                }
                None => {
                    out.push(c);
                    i += 1;
                }
            }
        } else {
            out.push(c);
            i += 1;
        }
    }
    drop_cfg_test(&out)
}

fn prev_is_ident(b: &[char], i: usize) -> bool {
    i > 0 && (b[i - 1].is_alphanumeric() || b[i - 1] == '_')
}

/// Removes each `#[cfg(test)]` item: up to the end of its `{ … }` block or its `;`.
fn drop_cfg_test(s: &str) -> String {
    let mut s = s.to_string();
    while let Some(at) = s.find("#[cfg(test)]") {
        let rest = &s[at..];
        let brace = rest.find('{');
        let semi = rest.find(';');
        let end = match (brace, semi) {
            (Some(b), Some(sc)) if sc < b => at + sc + 1,
            (Some(b), _) => {
                let mut depth = 0;
                let mut end = s.len();
                for (k, ch) in s[at + b..].char_indices() {
                    match ch {
                        '{' => depth += 1,
                        '}' => {
                            depth -= 1;
                            if depth == 0 {
                                end = at + b + k + 1;
                                break;
                            }
                        }
                        _ => {}
                    }
                }
                end
            }
            (None, Some(sc)) => at + sc + 1,
            (None, None) => s.len(),
        };
        s.replace_range(at..end, " ");
    }
    s
}

fn is_ident(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// The paths of one `use` tree (the text between `use` and `;`), each with the name it binds.
fn use_paths(tree: &str) -> Vec<(Vec<String>, String)> {
    fn go(s: &[char], i: &mut usize, prefix: &[String], out: &mut Vec<(Vec<String>, String)>) {
        let mut path = prefix.to_vec();
        loop {
            while *i < s.len() && s[*i].is_whitespace() {
                *i += 1;
            }
            if *i >= s.len() {
                break;
            }
            if s[*i] == '{' {
                *i += 1;
                loop {
                    go(s, i, &path, out);
                    while *i < s.len() && s[*i].is_whitespace() {
                        *i += 1;
                    }
                    if *i < s.len() && s[*i] == ',' {
                        *i += 1;
                        continue;
                    }
                    if *i < s.len() && s[*i] == '}' {
                        *i += 1;
                    }
                    break;
                }
                return;
            }
            if s[*i] == '*' {
                *i += 1;
                out.push((path, "*".into()));
                return;
            }
            let start = *i;
            while *i < s.len() && is_ident(s[*i]) {
                *i += 1;
            }
            if start == *i {
                // `}` or `,` of an empty group
                return;
            }
            let word: String = s[start..*i].iter().collect();
            path.push(word);
            if s[*i..].starts_with(&[':', ':']) {
                *i += 2;
                continue;
            }
            // end of this path: `as name`?
            let mut j = *i;
            while j < s.len() && s[j].is_whitespace() {
                j += 1;
            }
            let mut name = path.last().cloned().unwrap_or_default();
            if s[j..].starts_with(&['a', 's']) && s.get(j + 2).is_some_and(|c| c.is_whitespace()) {
                j += 2;
                while j < s.len() && s[j].is_whitespace() {
                    j += 1;
                }
                let st = j;
                while j < s.len() && is_ident(s[j]) {
                    j += 1;
                }
                name = s[st..j].iter().collect();
                *i = j;
            }
            if name == "self" {
                path.pop();
                name = path.last().cloned().unwrap_or_default();
            }
            out.push((path, name));
            return;
        }
    }
    let s: Vec<char> = tree.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    go(&s, &mut i, &[], &mut out);
    out
}

/// Paths of the file, relative or absolute as written: (path, from a `use`, bound name).
fn references(text: &str) -> Vec<(Vec<String>, bool, String)> {
    let chars: Vec<char> = text.chars().collect();
    let mut refs = Vec::new();
    // `use` statements
    let mut i = 0;
    while i + 3 < chars.len() {
        let boundary = i == 0 || !is_ident(chars[i - 1]);
        if boundary && chars[i..].starts_with(&['u', 's', 'e']) && chars[i + 3].is_whitespace() {
            let end = (i..chars.len()).find(|&j| chars[j] == ';').unwrap_or(chars.len());
            let tree: String = chars[i + 4..end].iter().collect();
            for (p, name) in use_paths(&tree) {
                refs.push((p, true, name));
            }
            i = end;
        }
        i += 1;
    }
    // inline paths
    for head in ["crate::", "super::", "self::", "flexrom::"] {
        let hc: Vec<char> = head.chars().collect();
        let mut i = 0;
        while i + hc.len() <= chars.len() {
            if chars[i..].starts_with(&hc) && (i == 0 || !(is_ident(chars[i - 1]) || chars[i - 1] == ':')) {
                let mut j = i;
                let mut path = Vec::new();
                loop {
                    let st = j;
                    while j < chars.len() && is_ident(chars[j]) {
                        j += 1;
                    }
                    if st == j {
                        break;
                    }
                    path.push(chars[st..j].iter().collect::<String>());
                    if chars[j..].starts_with(&[':', ':']) {
                        j += 2;
                    } else {
                        break;
                    }
                }
                refs.push((path, false, String::new()));
                i = j.max(i + 1);
            } else {
                i += 1;
            }
        }
    }
    refs
}

struct Tree {
    modules: BTreeSet<String>,
    /// module → (bound name → absolute path) of its `use` items
    reexports: BTreeMap<String, BTreeMap<String, Vec<String>>>,
    raw: BTreeMap<String, Vec<Vec<String>>>,
}

fn join(p: &[String]) -> String {
    p.join("::")
}

/// The absolute path (from the crate root) of a path written in `module`.
fn absolute(module: &str, path: &[String], modules: &BTreeSet<String>) -> Option<Vec<String>> {
    let mut base: Vec<String> =
        if module.is_empty() || module == "main" { Vec::new() } else { module.split("::").map(String::from).collect() };
    // a file `a/b.rs` is module a::b; `super` inside it is `a`
    let first = path.first()?;
    match first.as_str() {
        "crate" | "flexrom" => return Some(path[1..].to_vec()),
        "self" => return Some([base, path[1..].to_vec()].concat()),
        "super" => {
            let mut k = 0;
            while path.get(k).is_some_and(|s| s == "super") {
                base.pop();
                k += 1;
            }
            return Some([base, path[k..].to_vec()].concat());
        }
        _ => {}
    }
    // 2018 paths: a child module of this one
    let child = [base.clone(), vec![first.clone()]].concat();
    if modules.contains(&join(&child)) {
        return Some([base, path.to_vec()].concat());
    }
    None
}

impl Tree {
    fn new(files: &[File]) -> Tree {
        let modules: BTreeSet<String> = files.iter().map(|f| f.module.clone()).collect();
        let mut reexports = BTreeMap::new();
        let mut raw = BTreeMap::new();
        for f in files {
            let mut re = BTreeMap::new();
            let mut paths = Vec::new();
            for (p, is_use, name) in references(&f.text) {
                let Some(abs) = absolute(&f.module, &p, &modules) else { continue };
                // private imports too: a child module may name its parent's imports
                if is_use && !name.is_empty() && name != "*" {
                    re.insert(name, abs.clone());
                }
                paths.push(abs);
            }
            reexports.insert(f.module.clone(), re);
            raw.insert(f.module.clone(), paths);
        }
        Tree { modules, reexports, raw }
    }

    /// The file that defines what `path` (absolute) names: the deepest module on it, with
    /// re-exports followed.
    fn target(&self, path: &[String], depth: usize) -> String {
        let mut cur: Vec<String> = Vec::new();
        for (k, seg) in path.iter().enumerate() {
            let next = [cur.clone(), vec![seg.clone()]].concat();
            if self.modules.contains(&join(&next)) {
                cur = next;
                continue;
            }
            if depth < 8 {
                if let Some(to) = self.reexports.get(&join(&cur)).and_then(|r| r.get(seg)) {
                    let rest = [to.clone(), path[k + 1..].to_vec()].concat();
                    return self.target(&rest, depth + 1);
                }
            }
            break;
        }
        join(&cur)
    }

    fn edges(&self) -> BTreeSet<(String, String)> {
        let mut e = BTreeSet::new();
        for (m, paths) in &self.raw {
            for p in paths {
                let t = self.target(p, 0);
                // the crate root only declares modules
                if &t != m && !t.is_empty() && !m.is_empty() {
                    e.insert((m.clone(), t));
                }
            }
        }
        e
    }
}

fn layer(module: &str) -> Option<(usize, &str)> {
    let top = module.split("::").next().unwrap_or("");
    LAYERS.iter().position(|l| l.contains(&top)).map(|i| (i, top))
}

/// Strongly connected sets of more than one module (Tarjan).
fn cycles(edges: &BTreeSet<(String, String)>) -> Vec<Vec<String>> {
    let nodes: BTreeSet<&String> = edges.iter().flat_map(|(a, b)| [a, b]).collect();
    let nodes: Vec<&String> = nodes.into_iter().collect();
    let idx: BTreeMap<&String, usize> = nodes.iter().enumerate().map(|(i, n)| (*n, i)).collect();
    let mut adj = vec![Vec::new(); nodes.len()];
    for (a, b) in edges {
        adj[idx[a]].push(idx[b]);
    }
    struct St {
        index: Vec<Option<usize>>,
        low: Vec<usize>,
        on: Vec<bool>,
        stack: Vec<usize>,
        next: usize,
        out: Vec<Vec<usize>>,
    }
    fn visit(v: usize, adj: &[Vec<usize>], s: &mut St) {
        s.index[v] = Some(s.next);
        s.low[v] = s.next;
        s.next += 1;
        s.stack.push(v);
        s.on[v] = true;
        for &w in &adj[v] {
            match s.index[w] {
                None => {
                    visit(w, adj, s);
                    s.low[v] = s.low[v].min(s.low[w]);
                }
                Some(iw) if s.on[w] => s.low[v] = s.low[v].min(iw),
                _ => {}
            }
        }
        if Some(s.low[v]) == s.index[v] {
            let mut comp = Vec::new();
            loop {
                let w = s.stack.pop().expect("on the stack");
                s.on[w] = false;
                comp.push(w);
                if w == v {
                    break;
                }
            }
            if comp.len() > 1 {
                s.out.push(comp);
            }
        }
    }
    let n = nodes.len();
    let mut s =
        St { index: vec![None; n], low: vec![0; n], on: vec![false; n], stack: Vec::new(), next: 0, out: Vec::new() };
    for v in 0..n {
        if s.index[v].is_none() {
            visit(v, &adj, &mut s);
        }
    }
    s.out
        .into_iter()
        .map(|c| {
            let mut c: Vec<String> = c.into_iter().map(|i| nodes[i].clone()).collect();
            c.sort();
            c
        })
        .collect()
}

/// The problems of a tree: cycles, upward or sideways edges, unknown top-level modules, and
/// known exceptions that no longer occur.
fn problems(files: &[File], known: &[(&str, &str, &str)]) -> Vec<String> {
    let tree = Tree::new(files);
    let all = tree.edges();
    let mut out = Vec::new();
    for (a, b, _) in known {
        if !all.contains(&(a.to_string(), b.to_string())) {
            out.push(format!("known exception {a} -> {b} no longer occurs: remove it from KNOWN"));
        }
    }
    let edges: BTreeSet<(String, String)> =
        all.into_iter().filter(|(a, b)| !known.iter().any(|(ka, kb, _)| ka == a && kb == b)).collect();
    for c in cycles(&edges) {
        let inside: Vec<String> =
            edges.iter().filter(|(a, b)| c.contains(a) && c.contains(b)).map(|(a, b)| format!("{a} -> {b}")).collect();
        out.push(format!("import cycle among {{{}}}: {}", c.join(", "), inside.join("; ")));
    }
    for m in &tree.modules {
        if !m.is_empty() && layer(m).is_none() {
            out.push(format!("module {m} has no layer: add its top-level module to LAYERS"));
        }
    }
    for (a, b) in &edges {
        let (Some((la, ta)), Some((lb, tb))) = (layer(a), layer(b)) else { continue };
        if lb < la {
            out.push(format!("upward import {a} -> {b} (layer {la} uses layer {lb})"));
        } else if lb == la && ta != tb {
            out.push(format!("sideways import {a} -> {b} ({ta} and {tb} share a layer and must not see each other)"));
        }
    }
    out
}

#[test]
fn no_cycles_and_no_upward_imports() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    read_tree(&root, &root, &mut files);
    assert!(files.len() > 20, "read {} files under {}", files.len(), root.display());
    let p = problems(&files, KNOWN);
    assert!(p.is_empty(), "layering problems:\n  {}", p.join("\n  "));
}

/// The checker itself on a made-up tree: the one cycle, the one upward import, the one
/// stale exception, the child `use` and the followed re-export are all found.
#[test]
fn checker_finds_cycles_and_upward_imports() {
    let f = |module: &str, text: &str| File { module: module.into(), text: strip(text) };
    let files = vec![
        f("", "pub mod linalg; pub mod solver; pub mod model;"),
        f("linalg", "pub mod a; pub mod b;"),
        // a ↔ b through a `use super::` and an inline `crate::` path
        f("linalg::a", "use super::b::X; // crate::model::Ignored in a comment\nconst S: &str = \"crate::model\";"),
        f("linalg::b", "fn g() { crate::linalg::a::f() }"),
        // solver re-exports linalg::a under its own name: model -> solver::kkt resolves to linalg::a
        f("solver", "pub use crate::linalg::a as kkt; pub mod inner; use inner::Y;"),
        f("solver::inner", "use crate::model::Model; pub struct Y;"),
        f("model", "use crate::solver::kkt::Thing; #[cfg(test)] mod tests { use crate::pipeline::X; }"),
    ];
    let tree = Tree::new(&files);
    let e = tree.edges();
    let has = |a: &str, b: &str| e.contains(&(a.to_string(), b.to_string()));
    assert!(has("model", "linalg::a"), "re-export followed: {e:?}");
    assert!(has("solver", "solver::inner"), "child use found: {e:?}");
    assert!(!has("linalg::a", "model"), "comments and strings ignored: {e:?}");
    assert!(!e.iter().any(|(_, b)| b.starts_with("pipeline")), "cfg(test) ignored: {e:?}");
    let p = problems(&files, &[("model", "io", "stale")]);
    assert!(p.iter().any(|s| s.contains("cycle among {linalg::a, linalg::b}")), "{p:?}");
    assert!(p.iter().any(|s| s.contains("upward import solver::inner -> model")), "{p:?}");
    assert!(p.iter().any(|s| s.contains("known exception model -> io no longer occurs")), "{p:?}");
    assert_eq!(p.len(), 3, "{p:?}");
}

/// Every LAPACK call passes through `linalg::lapack`, whose traits keep OpenBLAS on one
/// thread before the first call (concurrent callers crash a multi-threaded OpenBLAS): no
/// other file under src/ (test modules included) names `ndarray_linalg`, nor do the
/// integration tests, benches, examples or the Python bindings, which link the same OpenBLAS.
#[test]
fn lapack_is_reached_through_linalg_lapack_only() {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut offenders = Vec::new();
    for dir in ["src", "tests", "benches", "examples", "python/src"] {
        for path in rust_files(&manifest.join(dir)) {
            let text = std::fs::read_to_string(&path).expect("readable source");
            let code_names_it =
                text.lines().any(|l| !l.trim_start().starts_with("//") && l.contains(concat!("ndarray", "_linalg")));
            if code_names_it && !path.ends_with("src/linalg/lapack.rs") {
                offenders.push(path.strip_prefix(manifest).unwrap_or(&path).display().to_string());
            }
        }
    }
    assert!(offenders.is_empty(), "LAPACK reached around src/linalg/lapack.rs in: {offenders:?}");
}

fn rust_files(dir: &Path) -> Vec<std::path::PathBuf> {
    let mut out = Vec::new();
    for p in std::fs::read_dir(dir).into_iter().flatten().map(|e| e.expect("entry").path()) {
        if p.is_dir() {
            out.extend(rust_files(&p));
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
    out
}
