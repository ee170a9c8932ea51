//! Damaged sweep, part and basis files: each is refused with one line naming the file and the
//! dataset, a non-zero exit that is neither a panic (101) nor an abort or a signal, and the
//! file a command would have written left as it was.
//!
//! Where the cases come from: a mutation campaign against the release binary (files edited
//! with h5py and byte by byte) found each of them; here they are crafted with the hdf5 crate
//! from files the program wrote:
//! - a sweep or part file whose `/factorizations` (or `/newton_iterations`) is one entry
//!   short of its load list: `sweep --resume` and `merge` indexed past its end;
//! - a dataset whose declared shape is 2³¹ entries (what one flipped bit in a dataspace
//!   gives): `/load_scales` of a sweep under `--resume`, `/shard/all_load_scales` and
//!   `/load_scales` of a part, `/reduced_q` of a part: reading it needs 16 GiB, so each is
//!   refused before reading. The children run under a 4 GiB address-space limit (`ulimit -v`),
//!   so an unbounded read aborts ("memory allocation failed", exit 134) instead of taking the
//!   machine's memory.

use ndarray::Array1;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The tests of this file run one at a time: a child forked while another test has an HDF5
/// file open inherits its descriptor and HDF5's lock on it.
static SERIAL: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// `flexrom args…` under a 4 GiB address-space limit and `--max-memory 2G` (the default
/// bound, half the machine's memory, may be above the address-space limit); asserts it
/// exited by itself, without a panic or an abort.
fn flexrom(args: &[&str]) -> (Output, String) {
    let o = Command::new("sh")
        .args(["-c", "ulimit -v 4194304; exec \"$0\" \"$@\"", env!("CARGO_BIN_EXE_flexrom")])
        .args(args)
        .args(["--max-memory", "2G"])
        .env("HDF5_USE_FILE_LOCKING", "FALSE")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(o.status.code().is_some(), "{args:?}: killed by a signal: {err}");
    assert!(![101, 134].contains(&o.status.code().unwrap()), "{args:?}: panic or abort: {err}");
    (o, err)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A coarse pendulum pipeline in `dir` (8 elements, 0.1 s), trained at [0.9, 1.1] with 4
/// modes into `basis.h5`.
fn setup(dir: &Path) -> PathBuf {
    let model = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("data/models/pendulum.toml"))
        .unwrap()
        .replace("elements = 50", "elements = 8")
        .replace("t_end = 1.1", "t_end = 0.1");
    std::fs::write(dir.join("model.toml"), model).unwrap();
    let p = dir.join("pipe.toml");
    std::fs::write(
        &p,
        "model = \"model.toml\"\nbasis = \"basis.h5\"\nreport = \"report\"\n[train]\nload_scales = [0.9, 1.1]\n[reduction]\nvariant = \"galerkin\"\nmodes = { count = 4 }\n",
    )
    .unwrap();
    let (o, err) = flexrom(&["train", "-q", s(&p)]);
    assert!(o.status.success(), "{err}");
    p
}

/// A copy of `good` named `name`, edited by `edit` through the hdf5 crate.
fn craft(good: &Path, name: &str, edit: impl FnOnce(&hdf5::File)) -> PathBuf {
    let bad = good.with_file_name(name);
    std::fs::copy(good, &bad).unwrap();
    let f = flexrom::io::h5_open::open_rw(&bad).unwrap();
    edit(&f);
    f.close().unwrap();
    bad
}

/// Dataset `name` one entry shorter (u64 entries).
fn one_short(f: &hdf5::File, name: &str) {
    let a = f.dataset(name).unwrap().read_1d::<u64>().unwrap();
    f.unlink(name).unwrap();
    let short = Array1::from_iter(a.iter().skip(1).copied());
    f.new_dataset_builder().with_data(&short).create(name).unwrap();
}

/// Dataset `name` replaced by (or created as) one that declares 2³¹ entries (f64, chunked,
/// never written), in the rank it had (2: 2³¹ rows of 4).
fn huge(f: &hdf5::File, name: &str) {
    let rank = f.dataset(name).map_or(1, |d| d.ndim());
    if f.link_exists(name) {
        f.unlink(name).unwrap();
    }
    let b = f.new_dataset::<f64>();
    match rank {
        1 => b.chunk(1024).shape(1usize << 31).create(name),
        2 => b.chunk((1024, 4)).shape((1usize << 31, 4)).create(name),
        _ => b.chunk((1, 1024, 4)).shape((1usize << 20, 1usize << 11, 4)).create(name),
    }
    .unwrap();
}

/// The command fails with one line naming `file` and every one of `needles`, and `out` keeps
/// its bytes (`None`: no file there).
fn refused(args: &[&str], file: &Path, needles: &[&str], out: &Path, before: Option<&[u8]>) {
    let (o, err) = flexrom(args);
    assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
    assert!(err.contains(s(file)), "{args:?}: not naming {}: {err}", file.display());
    for n in needles {
        assert!(err.contains(n), "{args:?}: not naming {n}: {err}");
    }
    assert_eq!(std::fs::read(out).ok().as_deref(), before, "{args:?}: {} changed", out.display());
}

#[test]
fn damaged_sweep_and_part_files_are_refused_naming_the_dataset() {
    let _one = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let p = setup(d);
    let list = "0.9:1.1:3";
    let sweep = d.join("sweep.h5");
    let (o, err) = flexrom(&["sweep", "-q", s(&p), "--load-scales", list, "-o", s(&sweep)]);
    assert!(o.status.success(), "{err}");
    let parts: Vec<PathBuf> = (1..=2).map(|k| d.join(format!("part{k}.h5"))).collect();
    for (k, part) in parts.iter().enumerate() {
        let shard = format!("{}/2", k + 1);
        let (o, err) = flexrom(&["sweep", "-q", s(&p), "--load-scales", list, "--shard", &shard, "-o", s(part)]);
        assert!(o.status.success(), "{err}");
    }
    // control: the files as written resume and merge
    let merged = d.join("merged.h5");
    let (o, err) = flexrom(&["merge", "-q", s(&parts[0]), s(&parts[1]), "-o", s(&merged)]);
    assert!(o.status.success(), "{err}");

    for (name, edit) in [
        ("factorizations", one_short as fn(&hdf5::File, &str)),
        ("newton_iterations", one_short),
        ("load_scales", huge),
        ("reduced_q", huge),
    ] {
        // --resume rewrites the file it reads: a copy of it, whose bytes must stay
        let bad = craft(&sweep, &format!("sweep_{name}.h5"), |f| edit(f, name));
        let bytes = std::fs::read(&bad).unwrap();
        let args = ["sweep", "-q", s(&p), "--load-scales", list, "--resume", "-o", s(&bad)];
        refused(&args, &bad, &[name], &bad, Some(&bytes));

        let bad = craft(&parts[1], &format!("part_{name}.h5"), |f| edit(f, name));
        let out = d.join("out.h5");
        refused(&["merge", "-q", s(&parts[0]), s(&bad), "-o", s(&out)], &bad, &[name], &out, None);
    }
    let bad = craft(&parts[1], "part_all.h5", |f| huge(f, "shard/all_load_scales"));
    let out = d.join("out.h5");
    refused(&["merge", "-q", s(&parts[0]), s(&bad), "-o", s(&out)], &bad, &["shard/all_load_scales"], &out, None);

    // the paths a part records: a basis moved away names the part that points there, an
    // empty one is named as the part's attribute; a value with a newline stays on one line
    let moved = d.join("moved.h5");
    let reset = |loc: &hdf5::Location, name: &str, value: &str| {
        loc.delete_attr(name).unwrap();
        let v: hdf5::types::VarLenUnicode = value.parse().unwrap();
        loc.new_attr::<hdf5::types::VarLenUnicode>().create(name).unwrap().write_scalar(&v).unwrap();
    };
    let parts_with = |name: &str, edit: &dyn Fn(&hdf5::File)| -> Vec<PathBuf> {
        (0..2).map(|k| craft(&parts[k], &format!("{name}{k}.h5"), |f| edit(f))).collect()
    };
    for (name, edit, needles) in [
        (
            "moved",
            Box::new(|f: &hdf5::File| reset(&f.group("shard").unwrap(), "basis", s(&moved)))
                as Box<dyn Fn(&hdf5::File)>,
            vec![s(&moved), "shard/basis"],
        ),
        (
            "empty",
            Box::new(|f: &hdf5::File| reset(&f.group("shard").unwrap(), "basis", "")),
            vec!["shard/basis", "not a path"],
        ),
        ("newline", Box::new(|f: &hdf5::File| reset(f, "fallback", "no\nne")), vec!["fallback", "\"no\\nne\""]),
    ] {
        let mut edited = parts_with(name, &*edit);
        if name == "newline" {
            // differing from the other part's: compared, and the edited one named
            edited[0] = parts[0].clone();
        }
        // the part read first names the paths; the second is the one compared with it
        let named = if name == "newline" { &edited[1] } else { &edited[0] };
        refused(&["merge", "-q", s(&edited[0]), s(&edited[1]), "-o", s(&out)], named, &needles, &out, None);
    }
}

/// `train --from-snapshots` with an altered snapshot file names that file and dataset (the
/// check of the basis built from it named the basis's temporary name); the basis at
/// `--basis` keeps its bytes. The alterations: a NaN, and a run's first column (the model's
/// initial state x₀ in every run) shifted by 1e-3 m, over the 1e-9 relative tolerance the
/// basis check holds a basis's reference to.
#[test]
fn altered_snapshot_files_are_named() {
    let _one = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let p = setup(d);
    let snaps = d.join("snaps.h5");
    let (o, err) = flexrom(&["train", "-q", s(&p), "--snapshots-only", "--shard", "1/1", "-o", s(&snaps)]);
    assert!(o.status.success(), "{err}");
    let basis = d.join("basis.h5");
    let before = std::fs::read(&basis).unwrap();
    let edit = |at: (usize, usize), v: f64| {
        move |f: &hdf5::File| {
            let mut x = f.dataset("x").unwrap().read_2d::<f64>().unwrap();
            x[at] = if v.is_nan() { v } else { x[at] + v };
            f.unlink("x").unwrap();
            f.new_dataset_builder().with_data(&x).create("x").unwrap();
        }
    };
    for (name, at, v, needle) in
        [("nan.h5", (3, 5), f64::NAN, "entry (3, 5) is NaN"), ("shifted.h5", (0, 0), 1e-3, "column 0")]
    {
        let bad = craft(&snaps, name, edit(at, v));
        refused(&["train", "-q", s(&p), "--from-snapshots", s(&bad)], &bad, &["x", needle], &basis, Some(&before));
    }
}

/// A basis whose datasets the model does not size (the estimator's calibration, the training
/// record, the snapshot loads) or does (the estimator's modes) declaring 2³¹ entries: `online`
/// refuses it naming the dataset, before reading it.
#[test]
fn basis_datasets_declaring_huge_shapes_are_refused_unread() {
    let _one = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let p = setup(d);
    let good = d.join("basis.h5");
    let out = d.join("out.h5");
    let (o, err) = flexrom(&["online", "-q", s(&p), "--load-scale", "1", "-o", s(&out)]);
    assert!(o.status.success(), "{err}");
    std::fs::remove_file(&out).unwrap();
    for name in [
        "estimator/modes",
        "estimator/calibration/load_scale",
        "estimator/multiplier_modes",
        "training/range",
        "snapshot_load_scale",
    ] {
        let bad = craft(&good, &format!("{}.h5", name.replace('/', "_")), |f| {
            if let Some((group, _)) = name.rsplit_once('/') {
                if f.group(group).is_err() {
                    f.create_group(group).unwrap();
                }
            }
            huge(f, name)
        });
        let args = ["online", "-q", s(&p), "--load-scale", "1", "-o", s(&out), "--basis", s(&bad)];
        refused(&args, &bad, &[name], &out, None);
    }
}

/// Cases the campaign (scripts/fuzz/campaign.py) found, kept in tests/fuzz_cases/<name>/ with
/// the files it mutated, each run as it ran then (in a copy, as `online` writes beside its
/// basis): `heap_object_size`, bits flipped in a basis's global heap (`--seed 3 --bytes`,
/// case 122) so that an object claims 206 933 470 768 bytes of a 4 096-byte collection:
/// `online` died by SIGSEGV inside libhdf5 (`H5HG_read`) reading the attribute `variant`.
#[test]
fn cases_the_campaign_found_are_refused() {
    let _one = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let cases = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz_cases");
    for (name, args, needles) in [(
        "heap_object_size",
        &["online", "-q", "pipe.toml", "--load-scale", "1", "-o", "out.h5"],
        &["basis.h5", "global heap", "damaged"],
    )] {
        let tmp = tempfile::tempdir().unwrap();
        for f in std::fs::read_dir(cases.join(name)).unwrap() {
            let f = f.unwrap().path();
            std::fs::copy(&f, tmp.path().join(f.file_name().unwrap())).unwrap();
        }
        let o = Command::new(env!("CARGO_BIN_EXE_flexrom"))
            .args(args)
            .current_dir(tmp.path())
            .env("HDF5_USE_FILE_LOCKING", "FALSE")
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{name}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{name}: {err}");
        for n in needles {
            assert!(err.contains(n), "{name}: not naming {n}: {err}");
        }
        assert!(!tmp.path().join("out.h5").exists(), "{name}");
    }
}

/// A case the campaign found (`--seed 5 --bytes`, case 20): bits flipped outside the global
/// heaps, whose collections hold together, so that an attribute's heap reference (`timing`'s
/// `estimate_method`, read by `online`'s speed notice; its object index has its top bit set)
/// names an object libhdf5 then read past (SIGSEGV in `H5HG_read`). The model fingerprint
/// has changed since the case was kept, so `online` now stops at the fingerprint check
/// before it reaches `timing`: [`the_damaged_reference_of_the_campaign_case_is_refused`]
/// reads that attribute itself.
#[test]
fn an_attribute_with_a_damaged_heap_reference_is_refused() {
    let _one = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let case = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz_cases/heap_id_unguarded");
    let tmp = tempfile::tempdir().unwrap();
    for f in std::fs::read_dir(&case).unwrap() {
        let f = f.unwrap().path();
        std::fs::copy(&f, tmp.path().join(f.file_name().unwrap())).unwrap();
    }
    let o = Command::new(env!("CARGO_BIN_EXE_flexrom"))
        .args(["online", "-q", "pipe.toml", "--load-scale", "1", "-o", "out.h5"])
        .current_dir(tmp.path())
        .env("HDF5_USE_FILE_LOCKING", "FALSE")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("basis.h5") && !tmp.path().join("out.h5").exists(), "{err}");
}

/// The damaged reference of `tests/fuzz_cases/heap_id_unguarded` (object index
/// 0x80000007 in a collection of 7 objects) is refused by the text reader with an error
/// naming the attribute, before libhdf5 follows it (it crashed the process); the file's
/// sound texts still read.
#[test]
fn the_damaged_reference_of_the_campaign_case_is_refused() {
    let _one = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz_cases/heap_id_unguarded/basis.h5");
    let f = flexrom::io::h5_open::open(&path).unwrap();
    assert_eq!(flexrom::io::h5::read_attr_str(&f, "variant").unwrap(), "galerkin");
    let e = flexrom::io::h5::read_attr_str(&f.group("timing").unwrap(), "estimate_method").unwrap_err().to_string();
    assert!(e.contains("estimate_method") && e.contains("damaged"), "{e}");
}

/// Every kind of damage to a text attribute's stored heap reference is refused before
/// libhdf5 follows it: another object index, another collection address, a length that
/// is not the object's (shorter overran libhdf5's buffer). The reference is found in the
/// file as its 16 stored bytes (length, collection address, index) and changed in place.
#[test]
fn damaged_heap_references_of_text_attributes_are_refused() {
    let _one = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let tmp = tempfile::tempdir().unwrap();
    let (good, text) = (tmp.path().join("good.h5"), HEAP_TEXT);
    let bytes = file_with_heap_text(&good);
    let heap = global_heap_at(&bytes) as u64;
    let mut stored = (text.len() as u32).to_le_bytes().to_vec();
    stored.extend(heap.to_le_bytes());
    stored.extend(1u32.to_le_bytes());
    let at = bytes.windows(16).position(|w| w == stored.as_slice()).expect("the stored reference");
    // the sound file reads (the check passes what libhdf5 writes)
    let f = flexrom::io::h5_open::open(&good).unwrap();
    assert_eq!(flexrom::io::h5::read_attr_str(&f, "note").unwrap(), text);
    drop(f);
    let damages: [(&str, usize, Vec<u8>); 5] = [
        ("index", at + 12, 2u32.to_le_bytes().to_vec()),
        ("index, top bit", at + 12, 0x8000_0001u32.to_le_bytes().to_vec()),
        ("address", at + 4, (heap + 8).to_le_bytes().to_vec()),
        ("address past the end", at + 4, u64::MAX.to_le_bytes().to_vec()),
        ("length", at, 3u32.to_le_bytes().to_vec()),
    ];
    for (i, (what, off, with)) in damages.iter().enumerate() {
        let mut b = bytes.clone();
        b[*off..*off + with.len()].copy_from_slice(with);
        let p = tmp.path().join(format!("damaged{i}.h5"));
        std::fs::write(&p, &b).unwrap();
        let f = flexrom::io::h5_open::open(&p).unwrap();
        let e = flexrom::io::h5::read_attr_str(&f, "note").unwrap_err().to_string();
        assert!(e.contains("note") && e.contains("damaged"), "{what}: {e}");
    }
}

/// A case of scripts/fuzz/heaps.py (`--seed 2`, case 6), kept in
/// tests/fuzz_cases/heap_free_space/: the free-space object of a sweep file's global heap
/// made to claim 15 bytes, so that libhdf5's walk of the collection
/// (`H5HG__cache_heap_deserialize`) went on past it into zeros, an object 0 of 0 bytes it
/// stepped over by 0 bytes, for ever: `sweep --resume` never returned. Refused now, with
/// the file left as it was; the basis is trained afresh (the sweep names the model, not
/// the basis bytes).
#[test]
fn a_heap_libhdf5_would_loop_on_is_refused() {
    let _one = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let case = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz_cases/heap_free_space");
    let tmp = tempfile::tempdir().unwrap();
    for f in std::fs::read_dir(&case).unwrap() {
        let f = f.unwrap().path();
        std::fs::copy(&f, tmp.path().join(f.file_name().unwrap())).unwrap();
    }
    let run = |args: &[&str]| {
        // a time limit: the loop, if it came back, must fail the test rather than hang it
        Command::new("timeout")
            .arg("60")
            .arg(env!("CARGO_BIN_EXE_flexrom"))
            .args(args)
            .current_dir(tmp.path())
            .env("HDF5_USE_FILE_LOCKING", "FALSE")
            .output()
            .unwrap()
    };
    let o = run(&["train", "-q", "pipe.toml"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let before = std::fs::read(tmp.path().join("sweep.h5")).unwrap();
    let o = run(&["sweep", "-q", "pipe.toml", "--load-scales", "0.9:1.1:3", "--resume", "-o", "sweep.h5"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("sweep.h5") && err.contains("global heap") && err.contains("damaged"), "{err}");
    assert_eq!(std::fs::read(tmp.path().join("sweep.h5")).unwrap(), before);
}

/// Two more cases of scripts/fuzz/heaps.py (`--seed 3`), kept beside the sweep file in
/// tests/fuzz_cases/heap_free_space/: a snapshot file whose free space claims 8 bytes
/// (case 14, `train --from-snapshots` never returned) and a part file whose free space
/// claims 0 (case 192, `merge` never returned). `train` refuses the snapshot file on one
/// line; the check of global heaps that every text read goes through refuses the part file.
#[test]
fn snapshot_and_part_files_libhdf5_would_loop_on_are_refused() {
    let _one = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let case = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz_cases/heap_free_space");
    let e = flexrom::io::h5::check_global_heaps(&case.join("part2.h5")).unwrap_err().to_string();
    assert!(e.contains("global heap") && e.contains("damaged"), "{e}");
    let tmp = tempfile::tempdir().unwrap();
    for f in ["model.toml", "pipe.toml", "snaps.h5"] {
        std::fs::copy(case.join(f), tmp.path().join(f)).unwrap();
    }
    let o = Command::new("timeout")
        .arg("60")
        .arg(env!("CARGO_BIN_EXE_flexrom"))
        .args(["train", "-q", "pipe.toml", "--from-snapshots", "snaps.h5", "--basis", "new.h5"])
        .current_dir(tmp.path())
        .env("HDF5_USE_FILE_LOCKING", "FALSE")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    // its walk ends now that it goes as libhdf5's does; what it reads then is not a snapshot file
    assert!(err.contains("snaps.h5") && err.trim_end().lines().count() == 1, "{err}");
    assert!(!tmp.path().join("new.h5").exists());
}

/// A global heap whose walk would not end in libhdf5 is refused by the check before any
/// text of the file is read: the free-space object (index 0) claiming 0 bytes (a step of
/// nothing), at the collection's end or after a free space made shorter than the rest of
/// the collection; an object whose size, rounded up to 8 and plus its 16-byte header,
/// wraps to 0. The sound file reads.
#[test]
fn global_heaps_libhdf5_would_walk_for_ever_are_refused() {
    let _one = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let tmp = tempfile::tempdir().unwrap();
    let (good, text) = (tmp.path().join("good.h5"), HEAP_TEXT);
    let bytes = file_with_heap_text(&good);
    let heap = global_heap_at(&bytes);
    // object 1 at heap + 16 (16-byte header, the text padded to 8), then the free space
    let free = heap + 16 + 16 + text.len().div_ceil(8) * 8;
    assert_eq!(&bytes[free..free + 2], &[0, 0], "object 0, the free space, follows the text");
    assert!(flexrom::io::h5::check_global_heaps(&good).is_ok());
    let damages: [(&str, usize, u64); 3] = [
        ("free space of 0 bytes", free + 8, 0),
        ("free space of 16 bytes, zeros after it", free + 8, 16),
        ("an object size wrapping to a step of 0", heap + 16 + 8, u64::MAX - 15),
    ];
    for (i, (what, off, with)) in damages.iter().enumerate() {
        let mut b = bytes.clone();
        if i == 1 {
            // what follows the shortened free space: zeros to the collection's end
            let end = heap + u64::from_le_bytes(b[heap + 8..heap + 16].try_into().unwrap()) as usize;
            b[free + 16..end].fill(0);
        }
        b[*off..*off + 8].copy_from_slice(&with.to_le_bytes());
        let p = tmp.path().join(format!("damaged{i}.h5"));
        std::fs::write(&p, &b).unwrap();
        let e = flexrom::io::h5::check_global_heaps(&p).unwrap_err().to_string();
        assert!(e.contains("global heap") && e.contains("damaged"), "{what}: {e}");
        let f = flexrom::io::h5_open::open(&p).unwrap();
        let e = flexrom::io::h5::read_attr_str(&f, "note").unwrap_err().to_string();
        assert!(e.contains("damaged"), "{what}: {e}");
    }
}

/// A dataset of texts (a sweep's `/message`) is read through the same check as a text
/// attribute: a damaged heap reference (another index, another collection, a shorter
/// length) is refused naming the dataset, before libhdf5 follows it; the sound file reads
/// back equal.
#[test]
fn damaged_heap_references_of_text_datasets_are_refused() {
    use hdf5::types::VarLenUnicode;
    let _one = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let tmp = tempfile::tempdir().unwrap();
    let good = tmp.path().join("good.h5");
    let texts = ["", "a text of some length, stored in a global heap"];
    {
        let f = flexrom::io::h5_open::create(&good).unwrap();
        let v: Vec<VarLenUnicode> = texts.iter().map(|t| t.parse().unwrap()).collect();
        flexrom::io::h5_text::write_strings(&f, "message", &v).unwrap();
    }
    let f = flexrom::io::h5_open::open(&good).unwrap();
    assert_eq!(flexrom::io::h5::read_strings(&f.dataset("message").unwrap()).unwrap(), texts);
    drop(f);
    let bytes = std::fs::read(&good).unwrap();
    let heap = global_heap_at(&bytes) as u64;
    // the second text's reference: its length and the collection's address (then its index)
    let mut stored = (texts[1].len() as u32).to_le_bytes().to_vec();
    stored.extend(heap.to_le_bytes());
    let at = bytes.windows(12).position(|w| w == stored.as_slice()).expect("the stored reference");
    let damages: [(&str, usize, Vec<u8>); 3] = [
        ("index", at + 12, 7u32.to_le_bytes().to_vec()),
        ("address", at + 4, (heap + 8).to_le_bytes().to_vec()),
        ("length", at, 3u32.to_le_bytes().to_vec()),
    ];
    for (i, (what, off, with)) in damages.iter().enumerate() {
        let mut b = bytes.clone();
        b[*off..*off + with.len()].copy_from_slice(with);
        let p = tmp.path().join(format!("damaged{i}.h5"));
        std::fs::write(&p, &b).unwrap();
        let f = flexrom::io::h5_open::open(&p).unwrap();
        let e = flexrom::io::h5::read_strings(&f.dataset("message").unwrap()).unwrap_err().to_string();
        assert!(e.contains("message") && e.contains("damaged"), "{what}: {e}");
    }
}

/// The text of [`file_with_heap_text`]'s attribute `note`.
const HEAP_TEXT: &str = "a text of some length, stored in a global heap";

/// Writes an HDF5 file at `path` holding one text attribute, `note` = [`HEAP_TEXT`] (stored
/// in a global heap), and returns its bytes.
fn file_with_heap_text(path: &std::path::Path) -> Vec<u8> {
    {
        let f = flexrom::io::h5_open::create(path).unwrap();
        flexrom::io::h5::attr_str(&f, "note", HEAP_TEXT).unwrap();
    }
    std::fs::read(path).unwrap()
}

/// The byte offset of the first global heap collection ("GCOL", version 1) of a file.
fn global_heap_at(bytes: &[u8]) -> usize {
    bytes.windows(8).position(|w| w == b"GCOL\x01\0\0\0").expect("a global heap")
}
