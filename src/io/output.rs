//! The checks every command makes before it writes anything: an output never is (nor
//! resolves to, through symlinks, `..` or a hard link) one of the command's inputs, an
//! existing output file is one flexrom wrote, of the kind the command writes, and a report
//! folder is flexrom's own.
//!
//! Report folders carry a mark, [`MARKER`], a text file whose first line is [`MARKER_HEAD`]
//! and whose other lines name the files flexrom wrote into the folder. flexrom replaces an
//! existing report folder only when it is empty, or marked and holding nothing but the files
//! its mark lists (and flexrom's own temporary files); anything else is the user's and is
//! refused with an error naming the folder and the pipeline key `report`.

use super::atomic::{kind_of, names_an_entry, swap_in_dir_with, write_new, TempPath};
use super::attrs::{Kind, KIND_ATTR};
use crate::error::{Error, Result};
use std::os::unix::fs::MetadataExt;
use std::path::{Component, Path, PathBuf};

/// The mark of a report folder made by flexrom.
pub const MARKER: &str = ".flexrom-report";
/// First line of the mark.
pub const MARKER_HEAD: &str = "flexrom report folder: made by flexrom and replaced as a whole by `flexrom run`; files:";

/// Where an output path comes from, for messages: a command-line option or a pipeline key.
#[derive(Clone, Copy, Debug)]
pub enum Origin<'a> {
    /// `-o`, `--basis`, …
    Flag(&'a str),
    /// a key of a pipeline file (`basis`, `report`)
    Key { pipeline: &'a Path, key: &'a str },
}

impl Origin<'_> {
    fn error(&self, output: &Path, problem: impl std::fmt::Display) -> Error {
        match self {
            Origin::Flag(flag) => Error::input(output, *flag, problem.to_string()),
            Origin::Key { pipeline, key } => Error::input(pipeline, *key, format!("`{}` {problem}", output.display())),
        }
    }
}

/// `p` with `.` left out and `name/..` folded away, lexically, where `name` is not a
/// symbolic link (through a link, `..` is the parent of the link's target, which a lexical
/// fold would miss; such a `..` stays): `pipelines/../data/x.h5` reads `data/x.h5`. Nothing
/// is canonicalized: a link in the path stays a link. The paths a pipeline names are kept
/// this way, so that messages and report lines print them as a user would write them.
pub fn tidy(p: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    // the trailing plain names of `out` a `..` may fold away
    let mut foldable = 0usize;
    for c in p.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir if foldable > 0 && !is_link(&out) => {
                out.pop();
                foldable -= 1;
            }
            Component::Normal(name) => {
                out.push(name);
                foldable += 1;
            }
            other => {
                out.push(other.as_os_str());
                foldable = 0;
            }
        }
    }
    if out.as_os_str().is_empty() {
        PathBuf::from(".")
    } else {
        out
    }
}

fn is_link(p: &Path) -> bool {
    p.symlink_metadata().is_ok_and(|m| m.file_type().is_symlink())
}

/// `p` made absolute with its longest existing prefix canonicalized (symlinks and `..`
/// resolved by the file system) and the rest applied lexically.
pub fn resolve(p: &Path) -> PathBuf {
    let abs = if p.is_absolute() {
        p.to_path_buf()
    } else {
        std::env::current_dir().unwrap_or_else(|_| PathBuf::from("/")).join(p)
    };
    let comps: Vec<Component> = abs.components().collect();
    for k in (0..=comps.len()).rev() {
        let prefix: PathBuf = comps[..k].iter().collect();
        if let Ok(mut base) = std::fs::canonicalize(&prefix) {
            for c in &comps[k..] {
                match c {
                    Component::Normal(x) => base.push(x),
                    Component::ParentDir => {
                        base.pop();
                    }
                    _ => {}
                }
            }
            return base;
        }
    }
    abs
}

/// (device, inode) of the file `p` leads to (symlinks followed).
fn identity(p: &Path) -> Option<(u64, u64)> {
    std::fs::metadata(p).ok().map(|m| (m.dev(), m.ino()))
}

/// Refuses `output` when it is, or leads to, one of `inputs` (path and what it is, e.g.
/// `(model, "model file")`): compared by (device, inode) when it exists, which covers
/// symlinks, `..` and hard links, and by resolved path otherwise. Refuses an existing
/// output that is not a regular file (nor a symlink to one), an existing file that is not
/// flexrom's own of one of the `kinds` the command writes ([`check_own_file`]), a dangling
/// symlink, and a path whose nearest existing ancestor is not a folder. Missing folders are
/// created at write time ([`super::atomic::TempPath::file_for`]), for every command alike.
pub fn check_output(output: &Path, origin: Origin, inputs: &[(&Path, &str)], kinds: &[Kind]) -> Result<()> {
    check_output_with(output, origin, inputs, |o| check_own_file(o, origin, kinds))?;
    // after the checks that name an input or a file of the user's, which say more
    check_extension(output, origin, kinds)
}

/// [`check_output`] with the check of an existing file's owner given: `own` refuses an
/// existing file flexrom must not replace (an animation's GIF is no HDF5 file).
pub fn check_output_with(
    output: &Path,
    origin: Origin,
    inputs: &[(&Path, &str)],
    own: impl FnOnce(&Path) -> Result<()>,
) -> Result<()> {
    if !names_an_entry(output) {
        return Err(origin.error(output, "does not name a file"));
    }
    if output.as_os_str().to_string_lossy().ends_with('/') {
        return Err(origin.error(output, "ends in `/`, which names a folder, not a file"));
    }
    match std::fs::symlink_metadata(output) {
        Ok(m) if m.file_type().is_symlink() => match std::fs::metadata(output) {
            Ok(t) if !t.is_file() => {
                return Err(origin.error(
                    output,
                    format!(
                        "is a symbolic link to {}, not to a regular file; flexrom only replaces regular files",
                        kind_of(&t)
                    ),
                ))
            }
            Ok(_) => {}
            Err(_) => {
                return Err(origin.error(
                    output,
                    "is a symbolic link to nothing (dangling); flexrom does not create files through it",
                ))
            }
        },
        Ok(m) if !m.is_file() => {
            return Err(origin.error(
                output,
                format!("exists and is {}, not a regular file; flexrom only replaces regular files", kind_of(&m)),
            ))
        }
        Ok(_) => {}
        Err(_) => creatable(output, origin)?,
    }
    let out_id = identity(output);
    let out_path = resolve(output);
    for (input, what) in inputs {
        let same = match (out_id, identity(input)) {
            (Some(a), Some(b)) => a == b,
            _ => out_path == resolve(input),
        };
        if same {
            return Err(origin.error(
                output,
                format!(
                    "is the {what} `{}` (the same file); flexrom never writes over a command's input",
                    input.display()
                ),
            ));
        }
    }
    if std::fs::metadata(output).is_ok() {
        own(output)?;
    }
    Ok(())
}

/// The extensions of an HDF5 file, which every kind of [`Kind`] is.
const HDF5_EXTENSIONS: [&str; 4] = ["h5", "hdf5", "hdf", "he5"];

/// Refuses an output whose extension names another format (`out.csv`, `out.vtu`): the file
/// would be HDF5 whatever its name says. No extension is allowed (`-o run1`).
fn check_extension(output: &Path, origin: Origin, kinds: &[Kind]) -> Result<()> {
    let Some(ext) = output.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()) else { return Ok(()) };
    if HDF5_EXTENSIONS.contains(&ext.as_str()) {
        return Ok(());
    }
    let kind = kinds.first().map_or("an", |k| k.name());
    let csv = if ext == "csv" { "; for CSV, the command's `--csv` prints it to stdout" } else { "" };
    Err(origin.error(output, format!("ends in `.{ext}`, but flexrom writes {kind} files in HDF5 only (`.h5`){csv}")))
}

/// Refuses an existing file at `output` that flexrom did not write as one of `kinds`: only an
/// HDF5 file whose root attribute `flexrom_file` names one of them is replaced (a result by
/// a result, a basis by a basis, …), so a path mistyped in a pipeline or on the command line
/// never destroys a user's own file, nor a trained basis by a result. A file of a flexrom
/// older than that attribute is recognised by its root `program_version`.
pub fn check_own_file(output: &Path, origin: Origin, kinds: &[Kind]) -> Result<()> {
    let names = kinds.iter().map(|k| k.name()).collect::<Vec<_>>().join(" or ");
    let refuse = |what: String| {
        Err(origin.error(
            output,
            format!("exists and {what}; flexrom replaces only its own {names} files: remove it or choose another path"),
        ))
    };
    let f = match crate::io::h5_open::open(output) {
        Ok(f) => f,
        // flexrom's own file, perhaps, held open by another handle: say so, not "foreign"
        Err(e) if super::h5_open::is_locked(&e) => {
            return Err(origin.error(output, format!("exists and {}", super::h5_open::unreadable(&e))))
        }
        Err(_) => return refuse("is not an HDF5 file flexrom wrote".into()),
    };
    match super::h5::read_attr_str(&f, KIND_ATTR) {
        Ok(kind) if kinds.iter().any(|k| k.name() == kind) => Ok(()),
        Ok(kind) => refuse(format!("is a {kind} file flexrom wrote")),
        Err(_) if f.attr("program_version").is_ok() => Ok(()),
        Err(_) => refuse("is an HDF5 file flexrom did not write (no `flexrom_file` attribute)".into()),
    }
}

/// The nearest existing ancestor of a missing `path` must be a folder for the missing
/// ones to be made.
fn creatable(path: &Path, origin: Origin) -> Result<()> {
    let mut a = resolve(path);
    while a.pop() {
        match std::fs::metadata(&a) {
            Ok(m) if m.is_dir() => return Ok(()),
            Ok(m) => {
                return Err(origin
                    .error(path, format!("cannot be created: `{}` is {}, not a folder", a.display(), kind_of(&m))))
            }
            Err(_) => {}
        }
    }
    Ok(())
}

/// True when `a` is `b` or one of its ancestors (both resolved).
fn contains(a: &Path, b: &Path) -> bool {
    b.starts_with(a)
}

/// Refuses a report folder that flexrom must not replace: one named `.` or `..`, the root,
/// a top-level folder, the home folder, the current folder, the pipeline's own folder, or a folder holding any
/// of `inputs` (the pipeline file, the model file, the basis file); a symlink; an existing
/// non-folder; a non-empty folder without flexrom's mark; a marked folder holding a file
/// its mark does not list.
pub fn check_report_dir(report: &Path, pipeline: &Path, inputs: &[(&Path, &str)]) -> Result<()> {
    let origin = Origin::Key { pipeline, key: "report" };
    if !names_an_entry(report) {
        return Err(origin.error(
            report,
            "names `.`, `..` or `/`, not a folder of its own; flexrom replaces the report folder as a whole",
        ));
    }
    let r = resolve(report);
    let mut forbidden: Vec<(PathBuf, String)> = vec![(PathBuf::from("/"), "the root folder".into())];
    if let Some(h) = std::env::var_os("HOME").filter(|h| !h.is_empty()) {
        forbidden.push((resolve(Path::new(&h)), "the home folder".into()));
    }
    if let Ok(c) = std::env::current_dir() {
        forbidden.push((resolve(&c), "the current folder".into()));
    }
    let pdir = resolve(pipeline).parent().map(Path::to_path_buf).unwrap_or_else(|| PathBuf::from("/"));
    forbidden.push((pdir, "the pipeline's own folder".into()));
    for (input, what) in inputs {
        forbidden.push((resolve(input), format!("the {what} `{}`", input.display())));
    }
    for (f, what) in &forbidden {
        if contains(&r, f) {
            let rel = if &r == f { "is" } else { "holds" };
            return Err(origin.error(
                report,
                format!(
                    "{rel} {what}; flexrom replaces the report folder as a whole, so it must be a folder of its own"
                ),
            ));
        }
    }
    if r.components().filter(|c| matches!(c, Component::Normal(_))).count() < 2 {
        return Err(origin.error(
            report,
            format!("is the top-level folder `{}`; a report folder must be a folder of its own", r.display()),
        ));
    }
    match std::fs::symlink_metadata(report) {
        Err(_) => creatable(report, origin),
        Ok(m) if m.file_type().is_symlink() => {
            Err(origin.error(report, "is a symbolic link; flexrom only replaces report folders it made itself"))
        }
        Ok(m) if !m.is_dir() => Err(origin.error(report, format!("exists and is {}, not a folder", kind_of(&m)))),
        Ok(_) => check_marked(report, origin),
    }
}

/// The names a report folder's mark lists, or `None` when it has no (valid) mark.
fn marked_names(dir: &Path) -> Option<Vec<String>> {
    let m = dir.join(MARKER);
    if !std::fs::symlink_metadata(&m).ok()?.is_file() {
        return None;
    }
    let text = std::fs::read_to_string(&m).ok()?;
    let mut lines = text.lines();
    (lines.next()? == MARKER_HEAD).then(|| lines.map(str::to_string).collect())
}

/// An existing folder flexrom may replace: empty, or marked with every entry listed.
fn check_marked(dir: &Path, origin: Origin) -> Result<()> {
    let entries: Vec<String> = std::fs::read_dir(dir)
        .map_err(|e| Error::io(dir, e))?
        .map(|e| e.map(|e| e.file_name().to_string_lossy().into_owned()))
        .collect::<std::io::Result<_>>()
        .map_err(|e| Error::io(dir, e))?;
    if entries.is_empty() {
        return Ok(());
    }
    let Some(listed) = marked_names(dir) else {
        return Err(origin.error(
            dir,
            format!("is a non-empty folder without flexrom's mark `{MARKER}`: flexrom did not make it and will not replace it (move it away or choose another `report`)"),
        ));
    };
    let ours =
        |n: &str| n == MARKER || listed.iter().any(|l| l == n) || (n.starts_with('.') && n.contains(".flexrom-tmp-"));
    if let Some(foreign) = entries.iter().find(|n| !ours(n)) {
        return Err(origin.error(
            dir,
            format!("holds `{foreign}`, which flexrom did not write there; flexrom replaces the report folder as a whole and will not delete it (move it away first)"),
        ));
    }
    Ok(())
}

/// The text of a mark listing `names`.
fn marker_text(names: &[String]) -> String {
    let mut s = format!("{MARKER_HEAD}\n");
    for n in names.iter().filter(|n| n.as_str() != MARKER) {
        s.push_str(n);
        s.push('\n');
    }
    s
}

/// Writes the mark into a new report folder being built (`dir`, a temporary folder),
/// listing every file now in it.
pub fn mark_new_report(dir: &Path) -> Result<()> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .map_err(|e| Error::io(dir, e))?
        .filter_map(|e| e.ok().map(|e| e.file_name().to_string_lossy().into_owned()))
        .collect();
    names.sort();
    write_new(&dir.join(MARKER), marker_text(&names).as_bytes())
}

/// Replaces the report folder `target` by the finished temporary folder `tmp`, and the
/// files `with` (`run`'s basis) in the same step: re-checks that the existing folder (if any)
/// is still flexrom's, then swaps (see [`super::atomic::swap_in_dir_with`]).
pub fn swap_in_report(tmp: TempPath, with: Vec<TempPath>, pipeline: &Path) -> Result<()> {
    swap_in_dir_with(tmp, with, |d| check_marked(d, Origin::Key { pipeline, key: "report" }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tidy_folds_dot_dot_lexically_but_not_through_a_link() {
        assert_eq!(tidy(Path::new("pipelines/../data/models/p.toml")), PathBuf::from("data/models/p.toml"));
        assert_eq!(tidy(Path::new("./a/./b/../c")), PathBuf::from("a/c"));
        assert_eq!(tidy(Path::new("../a/..")), PathBuf::from(".."));
        assert_eq!(tidy(Path::new("a/..")), PathBuf::from("."));
        assert_eq!(tidy(Path::new("/x/../y")), PathBuf::from("/y"));
        // through a link, `..` is the target's parent: the lexical fold would name another file
        let d = tempfile::tempdir().unwrap();
        let base = std::fs::canonicalize(d.path()).unwrap();
        std::fs::create_dir_all(base.join("far/inner")).unwrap();
        std::os::unix::fs::symlink(base.join("far/inner"), base.join("link")).unwrap();
        assert_eq!(tidy(&base.join("link/../m.toml")), base.join("link/../m.toml"));
        assert_eq!(tidy(&base.join("far/inner/../m.toml")), base.join("far/m.toml"));
    }

    #[test]
    fn resolve_follows_dot_dot_and_keeps_missing_tails() {
        let d = tempfile::tempdir().unwrap();
        let base = std::fs::canonicalize(d.path()).unwrap();
        std::fs::create_dir(base.join("a")).unwrap();
        assert_eq!(resolve(&base.join("a/../b/c")), base.join("b/c"));
        assert_eq!(resolve(&base.join("a/x/../y")), base.join("a/y"));
        assert_eq!(resolve(&base.join("a/..")), base);
    }

    #[test]
    fn marked_folders_with_foreign_files_are_refused() {
        let d = tempfile::tempdir().unwrap();
        let pipe = d.path().join("p/pipe.toml");
        std::fs::create_dir(d.path().join("p")).unwrap();
        std::fs::write(&pipe, "x").unwrap();
        let rep = d.path().join("rep");
        let inputs = [(pipe.as_path(), "pipeline file")];
        check_report_dir(&rep, &pipe, &inputs).unwrap();
        std::fs::create_dir(&rep).unwrap();
        std::fs::write(rep.join("sweep.h5"), "s").unwrap();
        mark_new_report(&rep).unwrap();
        check_report_dir(&rep, &pipe, &inputs).unwrap();
        std::fs::write(rep.join("notes.txt"), "mine").unwrap();
        let e = check_report_dir(&rep, &pipe, &inputs).unwrap_err().to_string();
        assert!(e.contains("notes.txt") && e.contains("report"), "{e}");
        let e = check_report_dir(&d.path().join("p"), &pipe, &inputs).unwrap_err().to_string();
        assert!(e.contains("pipeline's own folder"), "{e}");
        let e = check_report_dir(d.path(), &pipe, &inputs).unwrap_err().to_string();
        assert!(e.contains("holds"), "{e}");
    }
}
