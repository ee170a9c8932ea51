//! Sharded sweeps and `merge` (docs/scaling.md), through the `flexrom` command.
//!
//! Checks, and where each expectation comes from:
//! - a 9-load sweep run as 4 shards (`sweep --shard K/4`) and merged (parts given out of
//!   order) is the file a single `sweep` over the same list writes: the same datasets with
//!   the same shapes and types, equal bit for bit, except the measured times (`rom_seconds`,
//!   `estimate_seconds`), which must only be NaN in the same rows; the same attributes on
//!   `/`, equal except `wall_seconds` and `threads` (whole-sweep measurements). The
//!   reference is the single sweep itself: without `--continuation` every load runs on its
//!   own (module docs of `workflows::sweep`), so nothing but the run order differs;
//! - `merge` refuses, with one line naming the file: a part of another load list, a part of
//!   another basis, a file that is no part, two parts of the same shard (naming the
//!   duplicate loads), a missing shard (naming its loads: shard 4/4 of 9 loads holds loads
//!   3 and 7, 0-based, i.e. 0.95 and 1.15 of 0.8:1.2:9); `-o` naming one of the parts;
//! - `--partial` with shard 4 missing writes the merge with `/status` 2 in exactly those
//!   rows, and `sweep --resume` over the whole list on that file runs exactly those 2 loads;
//! - `--shard 10/10` of a 9-load list is a usage error (that shard would hold load 9, 0-based: none);
//! - full sweeps (`sweep --full`) alike: two shards merged, and one shard merged `--partial`
//!   then resumed, are the single full sweep (as above); `merge` refuses a full part beside a
//!   reduced one, and `--resume` a file of the other route, each with one line naming
//!   `route`.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn flexrom() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_flexrom"));
    // a child must not inherit a lock on a file this test has open
    c.env("HDF5_USE_FILE_LOCKING", "FALSE");
    c
}

/// A coarse pendulum pipeline in `dir` trained at [1.0] with `modes` modes into `basis`.
fn setup(dir: &Path, modes: usize, basis: &str) -> PathBuf {
    let model = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("data/models/pendulum.toml"))
        .unwrap()
        .replace("elements = 50", "elements = 8")
        .replace("t_end = 1.1", "t_end = 0.1");
    std::fs::write(dir.join("model.toml"), model).unwrap();
    let p = dir.join(format!("pipe_{modes}.toml"));
    std::fs::write(
        &p,
        format!(
            "model = \"model.toml\"\nbasis = \"{basis}\"\nreport = \"report\"\n[train]\nload_scales = [0.9, 1.1]\n[reduction]\nvariant = \"galerkin\"\nmodes = {{ count = {modes} }}\n"
        ),
    )
    .unwrap();
    let (o, err) = run(flexrom().args(["train", p.to_str().unwrap()]));
    assert!(o.status.success(), "{err}");
    p
}

fn run(c: &mut Command) -> (Output, String) {
    let o = c.output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert_ne!(o.status.code(), Some(101), "panic: {err}");
    assert!(o.status.code().is_some(), "killed by a signal: {err}");
    (o, err)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn shard(p: &Path, list: &str, k: usize, n: usize, out: &Path) {
    let (o, err) =
        run(flexrom().args(["sweep", s(p), "--load-scales", list, "--shard", &format!("{k}/{n}"), "-o", s(out)]));
    assert!(o.status.success(), "shard {k}/{n}: {err}");
}

/// A dataset's values as comparable bits, whatever its element type.
fn values(d: &hdf5::Dataset) -> Vec<String> {
    use hdf5::types::{FloatSize, IntSize, TypeDescriptor};
    match d.dtype().unwrap().to_descriptor().unwrap() {
        TypeDescriptor::Float(FloatSize::U8) => {
            d.read_raw::<f64>().unwrap().iter().map(|x| format!("{:016x}", x.to_bits())).collect()
        }
        TypeDescriptor::Unsigned(IntSize::U1) => d.read_raw::<u8>().unwrap().iter().map(|x| x.to_string()).collect(),
        TypeDescriptor::Unsigned(IntSize::U8) => d.read_raw::<u64>().unwrap().iter().map(|x| x.to_string()).collect(),
        TypeDescriptor::VarLenUnicode => {
            d.read_raw::<hdf5::types::VarLenUnicode>().unwrap().iter().map(|x| x.as_str().to_string()).collect()
        }
        other => panic!("{}: unexpected type {other:?}", d.name()),
    }
}

/// Every dataset below `g`, by path.
fn datasets(g: &hdf5::Group, prefix: &str, out: &mut Vec<(String, hdf5::Dataset)>) {
    for name in g.member_names().unwrap() {
        let path = format!("{prefix}/{name}");
        if let Ok(d) = g.dataset(&name) {
            out.push((path, d));
        } else {
            datasets(&g.group(&name).unwrap(), &path, out);
        }
    }
}

fn attrs(f: &hdf5::File) -> Vec<(String, String)> {
    let mut v: Vec<(String, String)> = f
        .attr_names()
        .unwrap()
        .into_iter()
        .map(|n| {
            let a = f.attr(&n).unwrap();
            let text = a
                .read_scalar::<hdf5::types::VarLenUnicode>()
                .map(|x| x.as_str().to_string())
                .or_else(|_| a.read_scalar::<u64>().map(|x| x.to_string()))
                .or_else(|_| a.read_scalar::<f64>().map(|x| format!("{:016x}", x.to_bits())))
                .unwrap();
            (n, text)
        })
        .collect();
    v.sort();
    v
}

/// The two sweep files hold the same datasets and values (times: the same NaN rows only).
fn assert_same_sweep(a: &Path, b: &Path) {
    let (fa, fb) = (flexrom::io::h5_open::open(a).unwrap(), flexrom::io::h5_open::open(b).unwrap());
    let (mut da, mut db) = (Vec::new(), Vec::new());
    datasets(&fa, "", &mut da);
    datasets(&fb, "", &mut db);
    let names = |d: &[(String, hdf5::Dataset)]| d.iter().map(|(n, _)| n.clone()).collect::<Vec<_>>();
    assert_eq!(names(&da), names(&db));
    assert!(da.len() >= 12, "{:?}", names(&da));
    for ((name, x), (_, y)) in da.iter().zip(&db) {
        assert_eq!(x.shape(), y.shape(), "{name}");
        let (vx, vy) = (values(x), values(y));
        if name.ends_with("_seconds") {
            let nan = |v: &[String]| {
                v.iter().map(|b| f64::from_bits(u64::from_str_radix(b, 16).unwrap()).is_nan()).collect::<Vec<_>>()
            };
            assert_eq!(nan(&vx), nan(&vy), "{name}");
        } else {
            assert_eq!(vx, vy, "{name}");
        }
    }
    let keep = |v: Vec<(String, String)>| {
        v.into_iter().filter(|(n, _)| n != "wall_seconds" && n != "threads").collect::<Vec<_>>()
    };
    assert_eq!(keep(attrs(&fa)), keep(attrs(&fb)));
}

fn one_line_error(o: &Output, err: &str, needle: &str) {
    assert_eq!(o.status.code(), Some(1), "{err}");
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "{err}");
    assert!(lines[0].contains(needle), "{needle:?} not in {err}");
}

#[test]
fn four_shards_merged_equal_one_sweep_and_bad_parts_are_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let p = setup(d, 4, "basis.h5");
    let list = "0.8:1.2:9";
    let single = d.join("single.h5");
    let (o, err) = run(flexrom().args(["sweep", s(&p), "--load-scales", list, "-o", s(&single)]));
    assert!(o.status.success(), "{err}");
    let parts: Vec<PathBuf> = (1..=4).map(|k| d.join(format!("part{k}.h5"))).collect();
    for (k, part) in parts.iter().enumerate() {
        shard(&p, list, k + 1, 4, part);
    }
    let merged = d.join("merged.h5");
    let (o, err) =
        run(flexrom().args(["merge", s(&parts[2]), s(&parts[0]), s(&parts[3]), s(&parts[1]), "-o", s(&merged)]));
    assert!(o.status.success(), "{err}");
    assert_same_sweep(&single, &merged);
    // a merged file is no part
    let (o, err) = run(flexrom().args(["merge", s(&merged), s(&parts[0]), "-o", s(&d.join("x.h5"))]));
    one_line_error(&o, &err, "not a part file");

    // another load list
    let other_list = d.join("other_list.h5");
    shard(&p, "0.8:1.2:10", 4, 4, &other_list);
    let (o, err) = run(flexrom().args([
        "merge",
        s(&parts[0]),
        s(&parts[1]),
        s(&parts[2]),
        s(&other_list),
        "-o",
        s(&d.join("x.h5")),
    ]));
    one_line_error(&o, &err, "another load list");
    // another basis (5 modes)
    let p5 = setup(d, 5, "basis5.h5");
    let other_basis = d.join("other_basis.h5");
    shard(&p5, list, 4, 4, &other_basis);
    let (o, err) = run(flexrom().args([
        "merge",
        s(&parts[0]),
        s(&parts[1]),
        s(&parts[2]),
        s(&other_basis),
        "-o",
        s(&d.join("x.h5")),
    ]));
    one_line_error(&o, &err, "another basis");
    // a duplicate shard
    let (o, err) = run(flexrom().args([
        "merge",
        s(&parts[0]),
        s(&parts[1]),
        s(&parts[1]),
        s(&parts[2]),
        s(&parts[3]),
        "-o",
        s(&d.join("x.h5")),
    ]));
    one_line_error(&o, &err, "is shard 2/4 again");
    assert!(err.contains("duplicate load scales 0.85"), "{err}");
    // a missing shard
    let (o, err) = run(flexrom().args(["merge", s(&parts[0]), s(&parts[1]), s(&parts[2]), "-o", s(&d.join("x.h5"))]));
    one_line_error(&o, &err, "shard(s) 4/4 missing: load scales 0.95");
    assert!(!d.join("x.h5").exists());
    // never over a part
    let (o, err) = run(flexrom().args(["merge", s(&parts[0]), s(&parts[1]), "-o", s(&parts[1])]));
    one_line_error(&o, &err, "part file");

    // --partial: the gaps marked not run, then filled by --resume
    let partial = d.join("partial.h5");
    let (o, err) =
        run(flexrom().args(["merge", "--partial", s(&parts[0]), s(&parts[1]), s(&parts[2]), "-o", s(&partial)]));
    assert!(o.status.success(), "{err}");
    let status = flexrom::io::h5_open::open(&partial).unwrap().dataset("status").unwrap().read_raw::<u8>().unwrap();
    assert_eq!(status, vec![0, 0, 0, 2, 0, 0, 0, 2, 0]);
    let (o, err) = run(flexrom().args(["sweep", s(&p), "--load-scales", list, "--resume", "-o", s(&partial)]));
    assert!(o.status.success(), "{err}");
    assert!(err.contains("7 of 9 load scales already finished, running 2"), "{err}");
    assert_same_sweep(&single, &partial);

    // a shard without loads
    let (o, err) =
        run(flexrom().args(["sweep", s(&p), "--load-scales", list, "--shard", "10/10", "-o", s(&d.join("y.h5"))]));
    one_line_error(&o, &err, "has no load for shard 10");
}

#[test]
fn full_sweeps_shard_merge_and_resume_and_do_not_mix_with_reduced_ones() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let p = setup(d, 4, "basis.h5");
    let list = "0.8:1.2:5";
    let full = |extra: &[&str], out: &Path| {
        let mut args = vec!["sweep", s(&p), "--full", "--load-scales", list, "-o", s(out)];
        args.extend_from_slice(extra);
        run(flexrom().args(&args))
    };
    let single = d.join("single.h5");
    let (o, err) = full(&[], &single);
    assert!(o.status.success(), "{err}");
    let parts: Vec<PathBuf> = (1..=2).map(|k| d.join(format!("full{k}.h5"))).collect();
    for (k, part) in parts.iter().enumerate() {
        let (o, err) = full(&["--shard", &format!("{}/2", k + 1)], part);
        assert!(o.status.success(), "{err}");
    }
    let merged = d.join("merged.h5");
    let (o, err) = run(flexrom().args(["merge", s(&parts[1]), s(&parts[0]), "-o", s(&merged)]));
    assert!(o.status.success(), "{err}");
    assert_same_sweep(&single, &merged);

    // the gaps of a partial merge run by --resume
    let partial = d.join("partial.h5");
    let (o, err) = run(flexrom().args(["merge", "--partial", s(&parts[0]), "-o", s(&partial)]));
    assert!(o.status.success(), "{err}");
    let status = flexrom::io::h5_open::open(&partial).unwrap().dataset("status").unwrap().read_raw::<u8>().unwrap();
    assert_eq!(status, vec![0, 2, 0, 2, 0]);
    let (o, err) = full(&["--resume"], &partial);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("3 of 5 load scales already finished, running 2"), "{err}");
    assert_same_sweep(&single, &partial);

    // a reduced part beside a full one
    let reduced_part = d.join("reduced2.h5");
    shard(&p, list, 2, 2, &reduced_part);
    let (o, err) = run(flexrom().args(["merge", s(&parts[0]), s(&reduced_part), "-o", s(&d.join("x.h5"))]));
    one_line_error(&o, &err, "route");
    assert!(err.contains("full model") && err.contains("reduced model") && err.contains(s(&reduced_part)), "{err}");
    assert!(!d.join("x.h5").exists());
    // resuming across routes, either way
    let reduced = d.join("reduced.h5");
    let (o, err) = run(flexrom().args(["sweep", s(&p), "--load-scales", list, "-o", s(&reduced)]));
    assert!(o.status.success(), "{err}");
    let (o, err) = full(&["--resume"], &reduced);
    one_line_error(&o, &err, "route");
    let (o, err) = run(flexrom().args(["sweep", s(&p), "--load-scales", list, "--resume", "-o", s(&single)]));
    one_line_error(&o, &err, "route");
    assert!(err.contains("`--full`"), "{err}");
}

/// A 64-load four-bar sweep as a 4-task Slurm job array plus a dependent merge job
/// (scripts/slurm/sweep.sbatch), against the same sweep run locally: probes within 1e-12 m
/// (a sharded sweep must be the local one) and, beyond it, every dataset as in [`assert_same_sweep`]. Needs a
/// running Slurm (`SLURM_CONF` set, `sbatch` on PATH): scripts/slurm/ci-test.sh brings up a
/// single-node one and runs this test; without one it prints "skipped: …" and passes.
/// The four-bar is shortened to 0.3 s (about 43 steps) and trained at one load so that the whole
/// test takes seconds of computing; the comparison does not depend on the length.
#[test]
#[ignore = "needs a running Slurm: scripts/slurm/ci-test.sh"]
fn slurm_array_sweep_equals_local_sweep() {
    let sbatch_ok = Command::new("sbatch").arg("--version").output().is_ok_and(|o| o.status.success());
    if std::env::var_os("SLURM_CONF").is_none() || !sbatch_ok {
        println!("skipped: no Slurm here (SLURM_CONF unset or no sbatch); scripts/slurm/ci-test.sh brings one up");
        return;
    }
    let t0 = std::time::Instant::now();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let model =
        std::fs::read_to_string(root.join("data/models/fourbar.toml")).unwrap().replace("t_end = 1.1", "t_end = 0.3");
    assert!(model.contains("t_end = 0.3"));
    std::fs::write(d.join("model.toml"), model).unwrap();
    let p = d.join("pipe.toml");
    std::fs::write(
        &p,
        "model = \"model.toml\"\nbasis = \"basis.h5\"\nreport = \"report\"\n[train]\nload_scales = [0.935]\n[reduction]\nvariant = \"constraint-preserving\"\nmodes = { count = 12 }\n",
    )
    .unwrap();
    let (o, err) = run(flexrom().args(["train", s(&p)]));
    assert!(o.status.success(), "{err}");
    let list = "0.7:1.2:64";
    let local = d.join("local.h5");
    let (o, err) = run(flexrom().args(["sweep", s(&p), "--load-scales", list, "-o", s(&local)]));
    assert!(o.status.success(), "{err}");
    let t_local = t0.elapsed().as_secs_f64();

    let script = root.join("scripts/slurm/sweep.sbatch");
    let (parts, merged) = (d.join("parts"), d.join("merged.h5"));
    let sbatch = |extra: &[&str], args: &[&Path]| -> String {
        let mut c = Command::new("sbatch");
        c.env("FLEXROM", env!("CARGO_BIN_EXE_flexrom"))
            .arg("--parsable")
            .arg(format!("--chdir={}", d.display()))
            .arg(format!("--output={}/slurm-%A_%a.out", d.display()))
            .args(extra)
            .arg(&script)
            .arg(&p)
            .arg(list)
            .args(args);
        let o = c.output().unwrap();
        assert!(o.status.success(), "sbatch: {}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stdout).trim().split(';').next().unwrap().to_string()
    };
    let t1 = std::time::Instant::now();
    let array = sbatch(&["--array=1-4"], &[&parts]);
    let merge = sbatch(&[&format!("--dependency=afterok:{array}")], &[&parts, &merged]);
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(600);
    loop {
        let q = Command::new("squeue").args(["-h", "-j", &format!("{array},{merge}")]).output().unwrap();
        if String::from_utf8_lossy(&q.stdout).trim().is_empty() {
            break;
        }
        assert!(std::time::Instant::now() < deadline, "the Slurm jobs did not finish in 600 s");
        std::thread::sleep(std::time::Duration::from_millis(500));
    }
    let t_slurm = t1.elapsed().as_secs_f64();
    let logs: String = std::fs::read_dir(d)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().starts_with("slurm-"))
        .map(|e| std::fs::read_to_string(e.path()).unwrap_or_default())
        .collect();
    assert!(merged.exists(), "no merged file; job output:\n{logs}");
    for k in 1..=4 {
        assert!(parts.join(format!("part_{k}.h5")).exists(), "part {k} missing:\n{logs}");
    }
    let (fl, fm) = (flexrom::io::h5_open::open(&local).unwrap(), flexrom::io::h5_open::open(&merged).unwrap());
    let names = fl.group("probes").unwrap().member_names().unwrap();
    assert!(!names.is_empty());
    let mut worst = 0.0f64;
    for n in &names {
        let a = fl.dataset(&format!("probes/{n}")).unwrap().read_raw::<f64>().unwrap();
        let b = fm.dataset(&format!("probes/{n}")).unwrap().read_raw::<f64>().unwrap();
        assert_eq!(a.len(), b.len());
        assert!(a.len() >= 64 * 2 * 40 && a.len() % (64 * 2) == 0, "{n}: {} values", a.len());
        for (x, y) in a.iter().zip(&b) {
            assert!(x.is_finite() && y.is_finite(), "{n}: a load failed");
            worst = worst.max((x - y).abs());
        }
    }
    assert!(worst <= 1e-12, "probes differ by {worst:e} m");
    assert_same_sweep(&local, &merged);
    println!(
        "slurm: 64 four-bar loads, 4-task array + merge in {t_slurm:.1} s (local sweep {t_local:.1} s incl. training); probes differ by at most {worst:e} m"
    );
}

/// The modes (columns of `/basis/modes`) of two basis files: the same shape, and each
/// column equal up to its sign within `tol`.
fn max_mode_difference(a: &Path, b: &Path) -> f64 {
    let read =
        |p: &Path| flexrom::io::h5_open::open(p).unwrap().dataset("basis/modes").unwrap().read_2d::<f64>().unwrap();
    let (va, vb) = (read(a), read(b));
    assert_eq!(va.dim(), vb.dim());
    let mut worst = 0.0f64;
    for j in 0..va.ncols() {
        let (x, y) = (va.column(j), vb.column(j));
        let same = x.iter().zip(y.iter()).map(|(p, q)| (p - q).abs()).fold(0.0, f64::max);
        let flipped = x.iter().zip(y.iter()).map(|(p, q)| (p + q).abs()).fold(0.0, f64::max);
        worst = worst.max(same.min(flipped));
    }
    worst
}

/// Sharded training (docs/scaling.md): the pendulum trained at 8 fixed loads as 8
/// `train --snapshots-only --shard K/8` jobs and `train --from-snapshots` (files given out
/// of order) gives the basis of a single `train`: modes equal up to sign within 1e-10 (the
/// target), the same singular values within 1e-10 relative, the same number of modes.
/// The reference is the single `train` itself: the snapshot matrix is put together in the
/// pipeline's order either way. Also: a missing load, a doubled one and a snapshot file
/// of another model are refused with one line naming them, and greedy pipelines refuse
/// `--shard` (their full runs are sequential).
#[test]
fn eight_snapshot_jobs_give_the_single_machine_basis() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let model = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("data/models/pendulum.toml"))
        .unwrap()
        .replace("elements = 50", "elements = 8")
        .replace("t_end = 1.1", "t_end = 0.2");
    std::fs::write(d.join("model.toml"), &model).unwrap();
    let p = d.join("pipe.toml");
    std::fs::write(
        &p,
        "model = \"model.toml\"\nbasis = \"single.h5\"\nreport = \"report\"\n[train]\nload_scales = [0.6, 0.75, 0.9, 1.0, 1.1, 1.25, 1.4, 1.5]\n[reduction]\nvariant = \"galerkin\"\nmodes = { count = 6 }\n",
    )
    .unwrap();
    let (o, err) = run(flexrom().args(["train", s(&p)]));
    assert!(o.status.success(), "{err}");
    let snaps: Vec<PathBuf> = (1..=8).map(|k| d.join(format!("snaps_{k}.h5"))).collect();
    for (k, f) in snaps.iter().enumerate() {
        let (o, err) =
            run(flexrom().args(["train", s(&p), "--snapshots-only", "--shard", &format!("{}/8", k + 1), "-o", s(f)]));
        assert!(o.status.success(), "{err}");
    }
    let sharded = d.join("sharded.h5");
    let mut args =
        vec!["train".to_string(), s(&p).into(), "--basis".into(), s(&sharded).into(), "--from-snapshots".into()];
    args.extend([7, 2, 0, 5, 1, 6, 3, 4].iter().map(|&k| s(&snaps[k]).to_string()));
    let (o, err) = run(flexrom().args(&args));
    assert!(o.status.success(), "{err}");
    let worst = max_mode_difference(&d.join("single.h5"), &sharded);
    assert!(worst <= 1e-10, "modes differ by {worst:e}");
    let sv = |f: &Path| {
        flexrom::io::h5_open::open(f).unwrap().dataset("basis/singular_values").unwrap().read_raw::<f64>().unwrap()
    };
    let (a, b) = (sv(&d.join("single.h5")), sv(&sharded));
    assert_eq!(a.len(), b.len());
    assert!(a.iter().zip(&b).all(|(x, y)| (x - y).abs() <= 1e-10 * a[0]), "{a:?} {b:?}");

    let other = d.join("other.h5");
    // a missing load: 7 of the 8 files
    let (o, err) = run(flexrom().args(["train", s(&p), "--basis", s(&other), "--from-snapshots"]).args(&snaps[..7]));
    one_line_error(&o, &err, "training load(s) [1.5]");
    // a doubled load
    let (o, err) =
        run(flexrom().args(["train", s(&p), "--basis", s(&other), "--from-snapshots"]).args(&snaps).arg(&snaps[2]));
    one_line_error(&o, &err, "is also in");
    // another model (a longer run)
    std::fs::create_dir(d.join("long")).unwrap();
    std::fs::write(d.join("long/model.toml"), model.replace("t_end = 0.2", "t_end = 0.25")).unwrap();
    std::fs::copy(&p, d.join("long/pipe.toml")).unwrap();
    let foreign = d.join("foreign.h5");
    let (o, err) = run(flexrom().args([
        "train",
        s(&d.join("long/pipe.toml")),
        "--snapshots-only",
        "--load-scale",
        "1.5",
        "-o",
        s(&foreign),
    ]));
    assert!(o.status.success(), "{err}");
    let (o, err) =
        run(flexrom().args(["train", s(&p), "--basis", s(&other), "--from-snapshots"]).args(&snaps[..7]).arg(&foreign));
    one_line_error(&o, &err, "another model");
    assert!(!other.exists());
    // greedy training has no list to split
    let g = d.join("greedy.toml");
    std::fs::write(
        &g,
        "model = \"model.toml\"\nbasis = \"g.h5\"\nreport = \"report\"\n[train]\ngreedy = { range = [0.5, 1.5], tolerance = 1e-3, max_runs = 3 }\n[reduction]\nvariant = \"galerkin\"\n",
    )
    .unwrap();
    let (o, err) = run(flexrom().args(["train", s(&g), "--snapshots-only", "--shard", "1/2", "-o", s(&other)]));
    one_line_error(&o, &err, "greedy training is sequential");
}
