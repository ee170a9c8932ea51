"""A Result pickles (joblib, multiprocessing): `pickle.loads(pickle.dumps(r))` answers every
attribute and no-argument method as `r` does, arrays to the bit, for every kind of run; bytes
that are not such a pickle, are damaged, or come from another flexrom version are refused
with a ValueError naming what is wrong."""

import inspect
import math
import multiprocessing
import pickle

import h5py
import numpy as np
import pytest

import flexrom
from conftest import ROOT

PENDULUM = ROOT / "data" / "models" / "pendulum.toml"
STIFFNESS = ROOT / "data" / "models" / "fourbar_stiffness.toml"
DP_PIPELINE = ROOT / "pipelines" / "double_pendulum.toml"

# the payload's header (python/src/pickle.rs): marker, format (u32 LE), version length, version
MAGIC = b"flexrom.Result\0"


def equal(a, b, where="r"):
    """a and b alike: arrays of the same shape and dtype with the same bits (NaN where NaN),
    floats with the same bits, dicts, lists and tuples item by item, anything else by ==."""
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        a, b = np.asarray(a), np.asarray(b)
        assert a.shape == b.shape and a.dtype == b.dtype, (where, a.shape, b.shape, a.dtype, b.dtype)
        if a.dtype.kind == "O":  # strings of a file: by value
            assert a.tolist() == b.tolist(), where
        else:
            assert a.tobytes() == b.tobytes(), where
    elif isinstance(a, float) and isinstance(b, float):
        assert np.float64(a).tobytes() == np.float64(b).tobytes(), (where, a, b)
    elif isinstance(a, dict):
        assert isinstance(b, dict) and list(a) == list(b), (where, list(a), b)
        for k in a:
            equal(a[k], b[k], f"{where}[{k!r}]")
    elif isinstance(a, (list, tuple)):
        assert type(a) is type(b) and len(a) == len(b), (where, a, b)
        for i, (x, y) in enumerate(zip(a, b)):
            equal(x, y, f"{where}[{i}]")
    else:
        assert type(a) is type(b) and a == b, (where, a, b)


def answers(r):
    """Every public attribute of r and every public method callable without arguments, by
    name (read from dir(r), so that one added later is compared too)."""
    out = {}
    for name in dir(r):
        if name.startswith("_"):
            continue
        value = getattr(r, name)
        if callable(value):
            required = [
                p
                for p in inspect.signature(value).parameters.values()
                if p.default is p.empty and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)
            ]
            if required:
                continue
            value = value()
        out[name] = value
    return out


def same_files(a, b):
    """Two result files with the same datasets and attributes, to the bit."""
    with h5py.File(a, "r") as x, h5py.File(b, "r") as y:
        names, other = [], []
        x.visit(names.append)
        y.visit(other.append)
        assert names == other
        for n in ["/", *names]:
            assert sorted(x[n].attrs) == sorted(y[n].attrs), n
            for k in x[n].attrs:
                equal(np.asarray(x[n].attrs[k]), np.asarray(y[n].attrs[k]), f"{n}@{k}")
            if isinstance(x[n], h5py.Dataset):
                equal(x[n][()], y[n][()], n)


def round_trip(r, tmp_path):
    """Pickles r, checks that the copy answers as r does (repr, every attribute and method,
    the result file it writes) and that pickling the copy gives the same bytes; the copy."""
    data = pickle.dumps(r)
    c = pickle.loads(data)
    assert type(c) is flexrom.Result
    assert repr(c) == repr(r)
    want, got = answers(r), answers(c)
    # the attributes the Result has at the time of writing: dir() found them all
    assert {"q", "t", "probes", "reactions", "labels", "stats", "error_estimate", "parameters"} <= set(want)
    equal(want, got)
    r.to_hdf5(tmp_path / "original.h5")
    c.to_hdf5(tmp_path / "copy.h5")
    same_files(tmp_path / "original.h5", tmp_path / "copy.h5")
    assert pickle.dumps(c) == data, "the payload holds everything: a copy pickles to the same bytes"
    return c


def test_a_full_run_pickles(tmp_path):
    """Model.simulate: arrays, probes, energies' file layout, statistics, wall time."""
    r = flexrom.Model.from_file(PENDULUM).simulate(load_scale=1.1)
    c = round_trip(r, tmp_path)
    assert c.load_scale == 1.1 and not c.reduced and c.error_estimate is None


def test_a_run_with_parameters_pickles(tmp_path):
    """A named parameter (the four-bar's coupler stiffness) comes back with the run."""
    r = flexrom.Model.from_file(STIFFNESS).simulate(t_end=0.02, E_coupler=6e6)
    c = round_trip(r, tmp_path)
    assert c.parameters == {"E_coupler": 6e6}


def test_a_model_without_a_file_and_its_statics_pickle(tmp_path):
    """A model given as text (no file behind it: the payload carries the text) and its
    static equilibrium (load factors, the statics part of the result file)."""
    model = flexrom.Model.from_toml(
        """
[time]
t_end = 0.1
dt = 0.01
rho_inf = 0.9
[[bodies]]
name = "beam"
start = [0.0, 0.0]
angle = 0.0
length = 1.0
elements = 4
density = 7800.0
area = 1e-4
inertia = 8.333333333333334e-10
youngs_modulus = 2.1e11
[[joints]]
type = "clamp"
body = "beam"
node = "start"
[[loads]]
type = "force"
body = "beam"
node = "end"
value = [0.0, -10.0]
scaled = true
[[probes]]
name = "tip"
body = "beam"
node = "end"
quantities = ["position", "strain", "curvature"]
""",
        path="cantilever.toml",
    )
    s = model.statics(2.0, steps=3)
    c = round_trip(s, tmp_path)
    assert c.load_factor.tolist() == [1 / 3, 2 / 3, 1.0] and c.model_path == "cantilever.toml"
    round_trip(model.simulate(), tmp_path)


def test_reduced_runs_pickle(dp_basis, tmp_path):
    """Basis.online: reduced coordinates, the estimate by time and by quantity, the trust
    (training range, tolerance, sensitivity) the result file's attributes come from; also
    at rest (NaN estimates), without an estimate, outside the training range, and the full model's
    answer in place of the reduced one (fallback, exact estimate 0)."""
    b = flexrom.Basis.load(dp_basis, pipeline=DP_PIPELINE)
    r = b.online(load_scale=1.05)
    c = round_trip(r, tmp_path)
    assert c.reduced and c.n_modes == b.n_modes and c.quantity_error_estimates
    with pytest.warns(flexrom.FlexromWarning):
        outside = b.online(load_scale=1.8)
    assert round_trip(outside, tmp_path).extrapolated
    # at rest (λ = 0 scales every load of the double pendulum to zero) the displacement
    # estimate is the 0/0 NaN, which JSON has no form for: its bits come back
    with pytest.warns(flexrom.FlexromWarning):
        rest = b.online(load_scale=0.0)
    assert math.isnan(rest.error_estimate_displacement) and math.isnan(rest.quantity_error_estimates["tip"]["position"])
    round_trip(rest, tmp_path)
    bare = flexrom.Basis.load(dp_basis, no_estimate=True).online(load_scale=0.9)
    assert round_trip(bare, tmp_path).error_estimate is None
    full = b.online(load_scale=2.5, fallback="full")
    c = round_trip(full, tmp_path)
    assert c.fallback and c.error_estimate == 0 and not c.reduced


def simulate_pendulum(load_scale):
    """A worker's run (module level: multiprocessing imports it by name)."""
    return flexrom.Model.from_file(PENDULUM).simulate(load_scale=load_scale, t_end=0.2)


def tip_of(r):
    """A worker's use of a Result sent to it."""
    return r.probes["tip"], r


def test_results_travel_through_a_multiprocessing_pool():
    """Results made in worker processes (spawned: fresh interpreters) come back equal to the
    parent's own runs, and Results sent to workers come back unchanged."""
    scales = [0.8, 1.2]
    mine = [simulate_pendulum(x) for x in scales]
    with multiprocessing.get_context("spawn").Pool(2) as pool:
        theirs = pool.map(simulate_pendulum, scales)
        back = pool.map(tip_of, mine)
    for a, b, (tip, c) in zip(mine, theirs, back):
        # a run's wall time is its own; everything else is the same computation's
        want, got = answers(a), answers(b)
        assert want.pop("stats").pop("wall_seconds") > 0 and got.pop("stats").pop("wall_seconds") > 0
        equal(want, got)
        equal(tip, a.probes["tip"])
        equal(answers(c), answers(a))


def test_results_travel_through_joblib():
    """joblib's process pool (loky) sends Results both ways, when joblib is installed."""
    joblib = pytest.importorskip("joblib")
    mine = simulate_pendulum(0.9)
    (tip, c), theirs = joblib.Parallel(n_jobs=2)(
        [joblib.delayed(tip_of)(mine), joblib.delayed(simulate_pendulum)(0.9)]
    )
    equal(answers(c), answers(mine))
    equal(theirs.q, mine.q)


def payload(r):
    """The bytes a Result pickles as, and the function that reads them back."""
    unpickle, (data,) = r.__reduce__()
    return unpickle, data


def test_damaged_or_foreign_bytes_are_refused():
    """Bytes that are not a pickled Result, a payload cut short or with one byte changed, and
    one from another flexrom version or payload format each raise a ValueError that says so."""
    r = simulate_pendulum(1.0)
    unpickle, data = payload(r)
    assert data.startswith(MAGIC)
    with pytest.raises(ValueError, match="not a pickled flexrom.Result"):
        unpickle(b"something else entirely")
    with pytest.raises(ValueError, match="ends inside its header"):
        unpickle(data[: len(MAGIC) + 3])
    with pytest.raises(ValueError, match="damaged: its .* bytes of data do not match their SHA-256"):
        unpickle(data[:-1])
    changed = bytearray(data)
    changed[len(data) // 2] ^= 0x01
    with pytest.raises(ValueError, match="damaged"):
        unpickle(bytes(changed))
    # the same through pickle itself: the payload is most of the pickle's bytes
    stream = bytearray(pickle.dumps(r))
    stream[len(stream) // 2] ^= 0x01
    with pytest.raises(ValueError, match="damaged"):
        pickle.loads(bytes(stream))
    # another version: the header's version text (its length byte follows the format)
    at = len(MAGIC) + 4
    n = data[at]
    version = data[at + 1 : at + 1 + n].decode()
    assert version == flexrom.__version__
    other = data[: at + 1] + b"9" * n + data[at + 1 + n :]
    with pytest.raises(ValueError, match=f"pickled by flexrom {'9' * n} .* this is flexrom {version}"):
        unpickle(other)
    newer = data[: len(MAGIC)] + (2**31).to_bytes(4, "little") + data[at:]
    with pytest.raises(ValueError, match=f"payload format {2**31}"):
        unpickle(newer)
