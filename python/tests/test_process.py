"""flexrom in a Python process beside other native libraries and threads: h5py's HDF5 and
numpy's OpenBLAS in either import order, the GIL released while it computes, Ctrl-C."""

import signal
import subprocess
import sys
import textwrap
import threading
import time

import numpy as np
import pytest

import flexrom
from conftest import ROOT


def python(code, **kw):
    """Runs `code` in a fresh interpreter (imports in the order the code gives)."""
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)], cwd=ROOT, capture_output=True, text=True, timeout=300, **kw
    )


# flexrom writes a result, h5py reads it and writes a copy of a basis, flexrom reads that
# copy: each library reads the other's files, both loaded in one process
SIDE_BY_SIDE = """
import sys, numpy as np
{imports}
src, tmp = sys.argv[1], sys.argv[2]
r = flexrom.Model.from_file("data/models/pendulum.toml").simulate(load_scale=1.2, t_end=0.1)
r.to_hdf5(tmp + "/r.h5")
with h5py.File(tmp + "/r.h5", "r") as f:
    assert np.array_equal(f["q"][()], r.q)
with h5py.File(src, "r") as a, h5py.File(tmp + "/copy.h5", "w") as b:
    for k in a:
        a.copy(a[k], b, name=k)
    for k, v in a.attrs.items():
        b.attrs[k] = v
b = flexrom.Basis.load(tmp + "/copy.h5")
assert np.array_equal(b.modes, flexrom.Basis.load(src).modes)
print("ok", b.online(load_scale=1.1).error_estimate)
"""


@pytest.mark.parametrize("order", ["h5py first", "flexrom first"])
def test_h5py_side_by_side(dp_basis, tmp_path, order):
    imports = "import h5py\nimport flexrom" if order == "h5py first" else "import flexrom\nimport h5py"
    code = SIDE_BY_SIDE.format(imports=imports)
    p = subprocess.run(
        [sys.executable, "-c", code, str(dp_basis), str(tmp_path)], cwd=ROOT, capture_output=True, text=True, timeout=300
    )
    assert p.returncode == 0 and p.stdout.startswith("ok"), p.stderr


def test_numpy_blas_beside(cli, tmp_path):
    """numpy's multi-threaded OpenBLAS busy before and after: flexrom's run (its own static
    OpenBLAS, one thread) still equals the command line's to the bit."""
    out = tmp_path / "cli.h5"
    cli("simulate", ROOT / "data" / "models" / "pendulum.toml", "--load-scale", "1.3", "-o", out)
    a = np.random.default_rng(1).standard_normal((400, 400))
    w0 = np.linalg.eigvalsh(a + a.T)
    r = flexrom.Model.from_file(ROOT / "data" / "models" / "pendulum.toml").simulate(load_scale=1.3)
    assert np.array_equal(np.linalg.eigvalsh(a + a.T), w0)
    import h5py

    with h5py.File(out, "r") as f:
        assert np.array_equal(f["q"][()], r.q)


def test_gil_released_while_computing():
    """Another Python thread keeps running while a full run of 5000 elements computes."""
    ticks = []
    stop = threading.Event()

    def tick():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.01)

    m = flexrom.Model.from_file(ROOT / "data" / "models" / "pendulum_5000.toml")
    t = threading.Thread(target=tick)
    t.start()
    start = time.perf_counter()
    m.simulate(t_end=0.05)
    end = time.perf_counter()
    stop.set()
    t.join()
    during = [x for x in ticks if start < x < end]
    # ticks every 10 ms: a held GIL would give none during the run
    assert len(during) >= max(1, int((end - start) / 0.01) // 4), (len(during), end - start)


def test_ctrl_c_stops_training_and_leaves_no_file(tmp_path):
    """SIGINT during a training of the four-bar (about 20 s) raises KeyboardInterrupt within a
    fraction of a second, and the output folder holds no file, temporary or not."""
    out = tmp_path / "out"
    out.mkdir()
    code = f"""
    import signal, time, flexrom
    # a parent that ignores SIGINT (a background job of a non-interactive shell) hands
    # SIG_IGN down, and Python keeps it: Ctrl-C needs Python's own handler here
    signal.signal(signal.SIGINT, signal.default_int_handler)
    print("start", flush=True)
    t0 = time.perf_counter()
    try:
        flexrom.train("pipelines/fourbar.toml", output={str(out / "fourbar.h5")!r})
    except KeyboardInterrupt:
        print("interrupted", time.perf_counter(), flush=True)
    # the stop does not outlive the call
    r = flexrom.Model.from_file("data/models/pendulum.toml").simulate(t_end=0.02)
    print("after", r.stats["steps"], flush=True)
    """
    p = subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent(code)], cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    assert p.stdout.readline().strip() == "start"
    time.sleep(2.0)
    sent = time.perf_counter()
    p.send_signal(signal.SIGINT)
    stdout, stderr = p.communicate(timeout=60)
    assert p.returncode == 0, stderr
    words = stdout.split()
    assert words[0] == "interrupted", (stdout, stderr)
    # perf_counter is CLOCK_MONOTONIC: comparable across the two processes
    assert float(words[1]) - sent < 0.5, float(words[1]) - sent  # measured 14-63 ms
    assert list(out.iterdir()) == []
    assert words[2] == "after" and int(words[3]) > 0, stdout


def test_file_held_by_h5py_is_named_as_locked(dp_basis, tmp_path):
    """A basis h5py holds open for writing in the same process cannot be opened (HDF5's file
    lock, with locking on as by default): the error says so and how to fix it; once closed,
    the basis loads."""
    import os
    import shutil

    path = tmp_path / "held.h5"
    shutil.copy(dp_basis, path)
    code = f"""
    import h5py, flexrom
    f = h5py.File({str(path)!r}, "r+")
    try:
        flexrom.Basis.load({str(path)!r})
    except flexrom.BasisMismatchError as e:
        print("refused:", e)
    f.close()
    print("loaded:", flexrom.Basis.load({str(path)!r}).n_modes)
    """
    env = {k: v for k, v in os.environ.items() if k != "HDF5_USE_FILE_LOCKING"}
    p = python(code, env=env)
    assert p.returncode == 0, p.stderr
    assert "refused:" in p.stdout and "locked by another open handle" in p.stdout, p.stdout
    assert "loaded:" in p.stdout
