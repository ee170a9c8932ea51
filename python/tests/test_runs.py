"""The package's runs against the command line's files: the same computation, so the same
numbers to the bit (both call the library's one solver with the same inputs)."""

import pathlib
import warnings

import h5py
import numpy as np
import pytest

import flexrom
from conftest import ROOT

PENDULUM = ROOT / "data" / "models" / "pendulum.toml"
DP_PIPELINE = ROOT / "pipelines" / "double_pendulum.toml"


def same(a, b):
    """Equal to the bit (NaN where NaN), and of the same shape."""
    a, b = np.asarray(a), np.asarray(b)
    assert a.shape == b.shape, (a.shape, b.shape)
    assert np.array_equal(a.view(np.uint64), b.view(np.uint64))


def test_simulate_equals_cli_file(cli, tmp_path):
    """Model.simulate at λ = 1.1 gives the arrays `flexrom simulate --load-scale 1.1` writes."""
    out = tmp_path / "cli.h5"
    cli("simulate", PENDULUM, "--load-scale", "1.1", "-o", out)
    r = flexrom.Model.from_file(PENDULUM).simulate(load_scale=1.1)
    assert r.probes, "the pendulum has a tip probe"
    with h5py.File(out, "r") as f:
        for name in ["t", "q", "qd", "multipliers"]:
            same(getattr(r, name), f[name][()])
        for name, xy in r.probes.items():
            same(xy, f["probes"][name][()])
        assert r.labels["dof"] == [s.decode() if isinstance(s, bytes) else s for s in f["labels/dof"][()]]
        assert f["q"].attrs["units"] == r.units["q"]
    assert r.load_scale == 1.1 and not r.reduced and r.error_estimate is None


def test_energies_are_the_files_and_balance(cli, tmp_path):
    """Result.energies holds the series `flexrom simulate -o` writes under /energy, to the
    bit, and `total` is their balance T + U + V + springs − W − W_d: the pendulum has no
    damping and runs at ρ∞ = 1 (no numerical dissipation), so it stays within 1e-3 of the
    energy exchanged, the largest kinetic energy (measured: 0.0215 J of 70.1 J, 3.1e-4)."""
    out = tmp_path / "cli.h5"
    cli("simulate", PENDULUM, "-o", out)
    e = flexrom.Model.from_file(PENDULUM).simulate().energies
    names = ["kinetic", "strain", "strain_axial", "strain_bending", "gravity", "springs", "external_work", "drive_work"]
    assert sorted(e) == sorted(names + ["total"])
    with h5py.File(out, "r") as f:
        for n in names:
            same(e[n], f["energy"][n][()])
    balance = e["kinetic"] + e["strain"] + e["gravity"] + e["springs"] - e["external_work"] - e["drive_work"]
    same(e["total"], balance)
    drift = np.abs(e["total"] - e["total"][0]).max()
    assert drift <= 1e-3 * e["kinetic"].max(), (drift, e["kinetic"].max())


def test_to_hdf5_writes_the_cli_layout(cli, tmp_path):
    """Result.to_hdf5 writes the file `flexrom simulate -o` writes: same datasets, same
    values, same attributes except the run's wall time."""
    cli("simulate", PENDULUM, "--load-scale", "0.9", "-o", tmp_path / "cli.h5")
    r = flexrom.Model.from_file(PENDULUM).simulate(load_scale=0.9)
    r.to_hdf5(tmp_path / "py.h5")
    with h5py.File(tmp_path / "cli.h5", "r") as a, h5py.File(tmp_path / "py.h5", "r") as b:
        names = []
        a.visit(names.append)
        other = []
        b.visit(other.append)
        assert sorted(names) == sorted(other)
        for n in names:
            if isinstance(a[n], h5py.Dataset):
                x, y = a[n][()], b[n][()]
                if x.dtype.kind == "f":
                    same(x, y)
                else:
                    assert (x == y).all()
        skip = {"wall_seconds", "model_path"}
        assert {k for k in a.attrs} == {k for k in b.attrs}
        for k in a.attrs:
            if k not in skip:
                assert np.all(a.attrs[k] == b.attrs[k]), k
    # written through a temporary file: nothing else is left in the folder
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cli.h5", "py.h5"]


def test_named_parameters_as_keywords(cli, tmp_path):
    """simulate(E_coupler=6e6) is `--param E_coupler=6e6` (the four-bar with a stiffness
    parameter, data/models/fourbar_stiffness.toml), over a shortened run."""
    model = ROOT / "data" / "models" / "fourbar_stiffness.toml"
    out = tmp_path / "cli.h5"
    cli("simulate", model, "--param", "E_coupler=6e6", "--t-end", "0.05", "-o", out)
    r = flexrom.Model.from_file(model).simulate(t_end=0.05, E_coupler=6e6)
    with h5py.File(out, "r") as f:
        same(r.q, f["q"][()])
    assert r.parameters == {"E_coupler": 6e6}


def test_online_equals_cli_file(cli, dp_basis, tmp_path):
    """Basis.online at λ = 1.05 gives the reduced run, its reduced coordinates and its error
    estimate that `flexrom online --load-scale 1.05` writes with the same basis."""
    out = tmp_path / "online.h5"
    cli("online", DP_PIPELINE, "--basis", dp_basis, "--load-scale", "1.05", "-o", out)
    basis = flexrom.Basis.load(dp_basis, pipeline=DP_PIPELINE)
    r = basis.online(load_scale=1.05)
    with h5py.File(out, "r") as f:
        for name in ["t", "q", "qd", "multipliers"]:
            same(getattr(r, name), f[name][()])
        same(r.reduced_q, f["reduced/q"][()])
        same(r.error_estimate, f.attrs["error_estimate"])
        assert r.estimate_method == f.attrs["error_estimate_method"]
        assert bool(f.attrs["extrapolated"]) is r.extrapolated is False
    assert r.error_estimate_by_time.shape == (5,)
    assert r.n_modes == basis.n_modes == basis.modes.shape[1]
    # the basis file alone (its stored pipeline and model) gives the same run
    same(flexrom.Basis.load(dp_basis).online(load_scale=1.05).q, r.q)


def test_basis_contents(dp_basis):
    """The basis's arrays as /basis/modes, /basis/singular_values and the training loads of
    greedy training (/training/load_scales, sorted, each once) hold them."""
    b = flexrom.Basis.load(dp_basis)
    with h5py.File(dp_basis, "r") as f:
        same(b.modes, f["basis/modes"][()])
        same(b.singular_values, f["basis/singular_values"][()])
        same(b.training_loads, np.unique(f["training/load_scales"][()]))
        notes = [f["training"].attrs[k] for k in ("held_out_note", "estimate_note") if k in f["training"].attrs]
    # the /training attributes, as str, in that order
    assert b.training_notes == [n.decode() if isinstance(n, bytes) else n for n in notes]
    assert np.allclose(b.modes.T @ b.modes, np.eye(b.n_modes), atol=1e-10)  # orthonormal columns


def test_sweep_equals_online(dp_basis):
    """Basis.sweep runs each load as online does (independent runs): the probes and
    estimates at each load equal online's, load axis first."""
    b = flexrom.Basis.load(dp_basis)
    loads = [0.6, 1.0, 1.4]
    s = b.sweep(loads)
    assert s["load_scales"].tolist() == loads and s["failed"] == [None] * 3 and s["parameters"] == {}
    for i, x in enumerate(loads):
        r = b.online(load_scale=x)
        for name, xy in r.probes.items():
            same(s["probes"][name][i], xy)
        same(s["error_estimate"][i], r.error_estimate)
        same(s["error_estimate_by_time"][i], r.error_estimate_by_time)
        # each probe quantity's estimate (the tip's position: its error over its range)
        assert set(r.quantity_error_estimates) == {"tip"}
        for name, quantities in r.quantity_error_estimates.items():
            for q, v in quantities.items():
                same(s["quantity_error_estimates"][name][q][i], v)
        # each joint's reaction on each node it holds has its own estimate; the pins'
        # forces swing (their moments are zero: no estimate)
        reactions = r.reaction_error_estimates
        assert set(reactions) == set(r.labels["reaction"])
        assert all(0 < e["force"] < float("inf") for e in reactions.values()), reactions
        for name, quantities in reactions.items():
            for q, v in quantities.items():
                same(s["reaction_error_estimates"][name][q][i], v)
    assert s["probes"]["tip"].shape == (3, len(s["t"]), 2)
    # no probe records strain or curvature on the double pendulum
    assert s["strains"] == {} and s["curvatures"] == {}
    # the same points given as dicts of parameters
    p = b.sweep(points=[{"load_scale": x} for x in loads])
    same(p["probes"]["tip"], s["probes"]["tip"])
    same(p["error_estimate"], s["error_estimate"])


def test_sweep_falls_back_to_the_full_model(dp_basis):
    """fallback="full" (`sweep --fallback full`): at λ = 2.5, outside the range [0.5, 1.5],
    the estimate reads 5.2e-3 against greedy's tolerance 1e-3 (measured 2026-11-27), so the
    answer there is the full model's, bit for bit Model.simulate's, with error estimate 0
    and the reason; at 1.0 it is the reduced answer, as without the fallback. Basis.online
    takes the same way."""
    b = flexrom.Basis.load(dp_basis)
    s = b.sweep([1.0, 2.5], fallback="full")
    assert s["fallback"][0] is None, s["fallback"]
    assert s["fallback"][1].startswith("full model in place of the reduced one: error estimate "), s["fallback"]
    assert s["error_estimate"][1] == 0 and s["extrapolated"][1]  # the load is outside the range
    assert s["fallback_failed"] == [None, None]
    same(s["probes"]["tip"][0], b.sweep([1.0])["probes"]["tip"][0])
    full = flexrom.Model.from_file(ROOT / "data" / "models" / "double_pendulum.toml").simulate(load_scale=2.5)
    same(s["probes"]["tip"][1], full.probes["tip"])
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        assert b.sweep([2.5], fallback="none")["fallback"] == [None]
    assert any("above the tolerance" in str(w.message) for w in seen), [str(w.message) for w in seen]
    with pytest.raises(ValueError, match="fallback"):
        b.sweep([1.0], fallback="bogus")
    with pytest.raises(ValueError, match="needs the error estimate"):
        flexrom.Basis.load(dp_basis, no_estimate=True).sweep([1.0], fallback="full")
    # online takes the same way: the full run, its reason, no reduced coordinates
    r = b.online(load_scale=2.5, fallback="full")
    assert not r.reduced and r.reduced_q is None and r.fallback == s["fallback"][1]
    assert r.error_estimate == 0 and r.extrapolated  # exact, at a load outside [0.5, 1.5]
    same(r.q, full.q)
    kept = b.online(load_scale=1.0, fallback="full")
    assert kept.reduced and kept.fallback is None and kept.fallback_failed is None


def test_outside_the_training_range_warns(dp_basis):
    """A load outside the trained range [0.5, 1.5] is marked extrapolated and warns."""
    b = flexrom.Basis.load(dp_basis)
    with pytest.warns(flexrom.FlexromWarning) as said:
        r = b.online(load_scale=1.7)
    assert r.extrapolated
    # outside, the estimate (1.4e-3) is also above the training tolerance 1e-3: both said
    assert any("outside" in str(w.message) for w in said), [str(w.message) for w in said]
    # inside the range nothing is said of extrapolation, nor of unreadable reactions (read
    # from each body's balance, the ground pin's force is within 0.11 of its range there)
    with warnings.catch_warnings(record=True) as inside:
        warnings.simplefilter("always")
        assert not b.online(load_scale=1.2).extrapolated
    said_inside = [str(w.message) for w in inside]
    assert not any("outside" in m or "extrapolat" in m or "range over the run" in m for m in said_inside), said_inside
    # a warning points at the caller's line, for the module functions too
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        flexrom.validate(DP_PIPELINE, load_scale=1.7, basis=dp_basis, dense=False)
    assert w and all(x.filename == __file__ for x in w), [(x.filename, str(x.message)) for x in w]


def test_validate_as_cli_json(cli, dp_basis):
    """flexrom.validate returns the record `flexrom validate --json` prints (all but times)."""
    import json

    p = cli("validate", DP_PIPELINE, "--basis", dp_basis, "--load-scale", "0.8", "--json", "--no-dense")
    want = json.loads(p.stdout)
    got = flexrom.validate(DP_PIPELINE, load_scale=0.8, basis=dp_basis)
    for key in ["rel_error", "error_estimate", "max_probe_error", "n_modes", "load_scale"]:
        assert got[key] == want[key], key
    # no point given: the pipeline's [validate] loads, a list as the command prints
    p = cli("validate", DP_PIPELINE, "--basis", dp_basis, "--json", "--no-dense")
    want = json.loads(p.stdout)
    got = flexrom.validate(DP_PIPELINE, basis=dp_basis, dense=False)
    assert [v["load_scale"] for v in got] == [v["load_scale"] for v in want] == [0.8, 1.3]
    assert [v["rel_error"] for v in got] == [v["rel_error"] for v in want]


def test_progress_callback_counts_every_run(dp_basis):
    """progress=callback is called on the calling thread with the sweep's count, ending at
    every load done; an exception in it stops the sweep and is raised."""
    import threading

    b = flexrom.Basis.load(dp_basis)
    loads = [0.6 + 0.01 * i for i in range(40)]
    seen = []
    main = threading.get_ident()
    b.sweep(loads, progress=lambda label, done, total: seen.append((done, total, threading.get_ident())))
    assert seen and seen[-1][:2] == (40, 40), seen[-3:]
    assert all(t == main for _, _, t in seen)
    assert [d for d, _, _ in seen] == sorted(d for d, _, _ in seen)

    calls = []

    def refuse(label, done, total):
        calls.append(done)
        raise RuntimeError("enough")

    many = [0.5 + 0.0025 * i for i in range(400)]  # a few hundred ms: the first look comes after 50 ms
    with pytest.raises(RuntimeError, match="enough"):
        b.sweep(many, progress=refuse)
    # raised at its first call, which stopped the sweep before its end: no call at the end
    assert len(calls) == 1 and calls[0] < len(many), calls
    with pytest.raises(flexrom.ModelError, match="progress"):
        b.sweep([1.0], progress="yes")
    # the stop does not outlive the call
    assert b.sweep(loads[:4])["failed"] == [None] * 4


def test_model_from_dict_is_the_file():
    """A model given as the dict tomllib reads from the file runs as the file does, numpy
    numbers in it too."""
    tomllib = pytest.importorskip("tomllib")  # Python >= 3.11

    d = tomllib.loads(PENDULUM.read_text())
    a = flexrom.Model.from_dict(d).simulate(load_scale=1.1, t_end=0.05)
    b = flexrom.Model.from_file(PENDULUM).simulate(load_scale=1.1, t_end=0.05)
    same(a.q, b.q)
    d["bodies"][0]["length"] = np.float64(d["bodies"][0]["length"])
    same(flexrom.Model.from_dict(d).simulate(load_scale=1.1, t_end=0.05).q, b.q)
    d["bodies"][0]["length"] = -1.0
    with pytest.raises(flexrom.ModelError, match=r"bodies\[0\]\.length"):
        flexrom.Model.from_dict(d)


def test_a_motor_by_angle_from_a_dict_holds_its_drive():
    """A crank written as a dict with a ground pin and a driven angle (the model file's
    keys): the hub's slope turns with the drive, θ(t) = 0.4 + λ · 5 t², to round-off."""
    d = {
        "time": {"t_end": 0.2, "dt": 0.002, "rho_inf": 0.9},
        "bodies": [
            {"name": "crank", "start": [0.0, 0.0], "angle": 0.4, "length": 0.5, "elements": 4,
             "density": 7850.0, "area": 1.0e-4, "inertia": 8.33e-10, "youngs_modulus": 2.1e11},
        ],
        "joints": [
            {"type": "ground_pin", "body": "crank", "node": "start"},
            {"type": "driven_angle", "body": "crank", "node": "start",
             "function": {"type": "polynomial", "coefficients": [0.0, 0.0, 5.0]}},
        ],
    }
    r = flexrom.Model.from_dict(d).simulate(load_scale=1.5)
    q, t = np.asarray(r.q), np.asarray(r.t)
    theta = 0.4 + 1.5 * 5.0 * t**2
    assert np.abs(-np.sin(theta) * q[:, 2] + np.cos(theta) * q[:, 3]).max() < 1e-12


def test_reduced_to_hdf5_is_the_online_file(cli, dp_basis, tmp_path):
    """A reduced Result written with to_hdf5 holds what `flexrom online -o` writes (reduced
    coordinates, estimate attributes); the basis and pipeline files are refused as paths."""
    out = tmp_path / "cli.h5"
    cli("online", DP_PIPELINE, "--basis", dp_basis, "--load-scale", "0.9", "-o", out)
    r = flexrom.Basis.load(dp_basis, pipeline=DP_PIPELINE).online(load_scale=0.9)
    r.to_hdf5(tmp_path / "py.h5")
    with h5py.File(out, "r") as a, h5py.File(tmp_path / "py.h5", "r") as b:
        for name in ["q", "reduced/q", "multipliers"]:
            same(a[name][()], b[name][()])
        for k in ["error_estimate", "error_estimate_method", "extrapolated", "n_modes", "variant", "basis"]:
            assert np.all(a.attrs[k] == b.attrs[k]), k
    before = dp_basis.read_bytes()
    with pytest.raises(flexrom.ModelError, match="basis file"):
        r.to_hdf5(dp_basis)
    with pytest.raises(flexrom.ModelError, match="pipeline file"):
        r.to_hdf5(DP_PIPELINE)
    assert dp_basis.read_bytes() == before


def test_reconstruct_reduce_and_nodes(dp_basis):
    """reconstruct(reduced_q) is the run's q (x_ref + V z, as the reduced run maps back; to
    round-off of the product), reduce inverts it on the basis's span; nodes are the rows of
    q per body and node, the tip probe's track among them."""
    b = flexrom.Basis.load(dp_basis)
    r = b.online(load_scale=1.2)
    x = b.reconstruct(r.reduced_q)
    assert x.shape == r.q.shape
    assert np.abs(x - r.q).max() <= 1e-12 * np.abs(r.q).max()
    assert np.allclose(b.reconstruct(r.reduced_q[7]), x[7], rtol=0, atol=1e-12)
    z = b.reduce(x)
    assert np.abs(z - r.reduced_q).max() <= 1e-10 * np.abs(r.reduced_q).max()
    with pytest.raises(flexrom.ModelError, match="shape"):
        b.reconstruct(np.zeros(3))
    nodes = r.nodes
    assert list(nodes) == r.labels["body"]
    lower = nodes["lower"]
    assert lower.shape == (len(r.t), 9, 2)  # 8 elements, 9 nodes
    same(lower[:, -1, :], r.probes["tip"])


SPRING_PENDULUM = ROOT / "data" / "models" / "spring_pendulum.toml"


def test_model_from_dict_takes_springs():
    """`[[springs]]` reaches Model.from_dict through the schema: the dict runs as the file
    does, and a bad spring is refused naming its key."""
    tomllib = pytest.importorskip("tomllib")  # Python >= 3.11

    d = tomllib.loads(SPRING_PENDULUM.read_text())
    assert d["springs"][0]["stiffness"] == 40.0
    a = flexrom.Model.from_dict(d).simulate(t_end=0.05)
    b = flexrom.Model.from_file(SPRING_PENDULUM).simulate(t_end=0.05)
    same(a.q, b.q)
    d["springs"][0]["damping"] = -1.0
    with pytest.raises(flexrom.ModelError, match=r"springs\[0\]\.damping"):
        flexrom.Model.from_dict(d)


def test_a_spring_stiffness_and_a_point_mass_as_parameters_from_a_dict():
    """A spring's `stiffness = { value, parameter }` and a point mass's `mass = { value,
    parameter }` reach Model.from_dict; simulate(k=60, payload=0.02) runs what the dict with
    those values written in runs, to 1e-12 m (the mass is bound as the value itself, the
    stiffness as 40 · 60/40, exact; the weight is the file's times 0.02/0.01, a rounding
    apart)."""
    tomllib = pytest.importorskip("tomllib")  # Python >= 3.11

    d = tomllib.loads(SPRING_PENDULUM.read_text())
    d["masses"] = [{"body": "bar", "node": "end", "mass": {"value": 0.01, "parameter": "payload"}}]
    d["springs"][0]["stiffness"] = {"value": 40.0, "parameter": "k"}
    model = flexrom.Model.from_dict(d)
    a = model.simulate(t_end=0.05, k=60.0, payload=0.02)
    assert a.parameters == {"k": 60.0, "payload": 0.02}
    d["masses"][0]["mass"], d["springs"][0]["stiffness"] = 0.02, 60.0
    b = flexrom.Model.from_dict(d).simulate(t_end=0.05)
    np.testing.assert_allclose(a.q, b.q, rtol=0, atol=1e-12)
    # at the file's values it is another run
    assert np.abs(model.simulate(t_end=0.05).q - b.q).max() > 1e-6


def test_a_basis_pickles_as_its_file(dp_basis, tmp_path, monkeypatch):
    """A Basis pickles as its file's absolute path and `load`'s arguments (joblib and
    multiprocessing send it so): unpickled in another folder it is the same basis, whose
    online run gives the same bits."""
    import pickle

    b = flexrom.Basis.load(dp_basis, pipeline=DP_PIPELINE, estimate="corrected")
    monkeypatch.chdir(tmp_path)
    c = pickle.loads(pickle.dumps(b))
    assert pathlib.Path(c.path).is_absolute() and pathlib.Path(c.path).samefile(dp_basis)
    same(np.asarray(c.modes), np.asarray(b.modes))
    ra, rb = b.online(load_scale=0.9), c.online(load_scale=0.9)
    same(np.asarray(ra.q), np.asarray(rb.q))
    assert ra.error_estimate == rb.error_estimate, "the same estimate method after the round trip"


def test_model_from_dict_errors_name_the_key_path():
    """An error in a model given as a dict names the key path (the dict has no lines: the
    TOML text flexrom wrote it as is not the caller's)."""
    tomllib = pytest.importorskip("tomllib")  # Python >= 3.11

    d = tomllib.loads(PENDULUM.read_text())
    d["bodies"][0]["elements"] = 0
    with pytest.raises(flexrom.ModelError) as e:
        flexrom.Model.from_dict(d)
    assert "bodies[0].elements" in str(e.value) and "line" not in str(e.value), str(e.value)
    d = tomllib.loads(PENDULUM.read_text())
    d["time"]["dt"] = "fast"
    with pytest.raises(flexrom.ModelError) as e:
        flexrom.Model.from_dict(d)
    assert "time.dt" in str(e.value) and "line" not in str(e.value), str(e.value)
