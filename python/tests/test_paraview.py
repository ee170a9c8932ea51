"""ParaView reads flexrom's XDMF files: `pvpython pv_check.py` (ParaView's own interpreter,
Debian's `paraview` package) opens them with the reader File → Open picks and reports what
it sees, compared here with the HDF5 datasets the files name (h5py): for `simulate
--paraview` one time step per row of `/t` at those times, the points and cells of
`/paraview/lines` and `/paraview/points/<k>`, the point data strain, curvature and velocity
with the values of instant k, and one rendered frame that is not blank; for `modes
--paraview` one displacement field per mode with the values of `/paraview/shapes/<k>`.

Skipped where `pvpython` is absent (the reason says so), unless FLEXROM_REQUIRE_PARAVIEW=1
(CI, `.ci/run`, installs ParaView and sets it): there a missing ParaView fails. Rendering
needs an X display (Debian's ParaView renders through X: `--force-offscreen-rendering`
crashes in XSync without one), so without $DISPLAY it runs under `xvfb-run`."""

import json
import os
import pathlib
import shutil
import subprocess

import numpy as np
import pytest

CHECK = pathlib.Path(__file__).resolve().parent / "pv_check.py"
REQUIRED = os.environ.get("FLEXROM_REQUIRE_PARAVIEW") == "1"
VTK_POLY_LINE = 4  # vtkCellType.h; XDMF's Polyline topology becomes VTK polylines (here of 2 points)


def pvpython_command(render):
    """The command that runs pv_check.py, or a skip (a failure under
    FLEXROM_REQUIRE_PARAVIEW=1) naming what is missing."""
    missing = None
    if shutil.which("pvpython") is None:
        missing = "pvpython is not installed (Debian: apt-get install paraview python3-paraview)"
    elif render and not os.environ.get("DISPLAY") and shutil.which("xvfb-run") is None:
        missing = "no X display and no xvfb-run to render with (Debian: apt-get install xvfb xauth)"
    if missing:
        (pytest.fail if REQUIRED else pytest.skip)(missing)
    base = ["pvpython", str(CHECK)]
    return ["xvfb-run", "-a", *base] if render and not os.environ.get("DISPLAY") else base


def paraview_sees(xdmf, step=0, png=None):
    """pv_check.py's report on `xdmf` at instant `step` (and the frame rendered into `png`).
    The path is absolute: ParaView 5.11's Xdmf3 reader joins a bare file name's folder
    wrongly (`m.xdmf` → `m.xdmfm.h5`)."""
    cmd = pvpython_command(png is not None) + [str(pathlib.Path(xdmf).resolve()), str(step)]
    cmd += [str(png)] if png is not None else []
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, f"{' '.join(cmd)} failed ({p.returncode}): {p.stderr[-3000:]}"
    return json.loads(p.stdout.strip().splitlines()[-1])


def assert_the_mesh(seen, f):
    """Points and segments as `/paraview/lines` describes them: one 2-point polyline a segment."""
    lines = f["paraview/lines"][:]
    n_points = lines.max() + 1  # the segments join consecutive samples; the last sample ends one
    assert seen["class"] == "vtkUnstructuredGrid"
    assert seen["n_points"] == n_points
    assert seen["n_cells"] == lines.shape[0]
    assert seen["cell_types"] == [VTK_POLY_LINE] and seen["cell_sizes"] == [2]


def test_paraview_reads_the_time_series_and_renders_a_frame(cli, tmp_path):
    import h5py
    from matplotlib.image import imread

    out = tmp_path / "dp.h5"
    cli("simulate", "data/models/double_pendulum.toml", "--paraview", "-o", out)
    k = 100  # an instant mid-run (t = 0.5 s of the model's 1 s), where the beams have moved and bent
    seen = paraview_sees(tmp_path / "dp.xdmf", k, tmp_path / "frame.png")
    assert seen["reader"].startswith("Xdmf3Reader")  # what File → Open picks for .xdmf
    with h5py.File(out) as f:
        t = f["t"][:]
        # one time step per row of /t, at its time (the XDMF's Time values, printed with {:e})
        assert len(seen["times"]) == len(t) == 201  # t = 0 and 200 steps of 0.005 s
        np.testing.assert_allclose(seen["times"], t, rtol=1e-15, atol=0)
        assert_the_mesh(seen, f)
        # instant k's own datasets, not the first instant's: the points moved since t = 0
        points = f[f"paraview/points/{k:06}"][:]
        assert not np.allclose(points, f["paraview/points/000000"][:])
        np.testing.assert_array_equal(seen["points"], points)
        assert {a: v["components"] for a, v in seen["arrays"].items()} == {"strain": 1, "curvature": 1, "velocity": 3}
        for name in ("strain", "curvature", "velocity"):
            np.testing.assert_array_equal(seen["arrays"][name]["values"], f[f"paraview/{name}/{k:06}"][:])
    # the frame: a 400×300 PNG on white with the centre lines drawn in the speed's colours
    image = imread(tmp_path / "frame.png")
    assert image.shape[:2] == (300, 400)
    rgb = (image[..., :3] * 255).round().astype(int).reshape(-1, 3)
    drawn = np.any(rgb != 255, axis=1)
    assert 200 <= drawn.sum() <= 0.2 * len(rgb)  # two beams 4 px wide across much of the frame, not a fill
    assert len(np.unique(rgb[drawn], axis=0)) >= 5  # coloured along the lines, not one flat colour


def test_paraview_reads_the_modes_file(cli, tmp_path):
    import h5py

    out = tmp_path / "m.h5"
    cli("modes", "data/models/double_pendulum.toml", "--count", "3", "--paraview", "-o", out)
    seen = paraview_sees(tmp_path / "m.xdmf")
    assert seen["reader"].startswith("Xdmf3Reader")
    assert seen["times"] == []  # one grid, no time series
    with h5py.File(out) as f:
        assert_the_mesh(seen, f)
        np.testing.assert_array_equal(seen["points"], f["paraview/points"][:])
        freq = f["frequencies"][:]
        names = [f"mode_{k + 1} ({freq[k]:.6f} Hz)" for k in range(3)]  # docs/file-formats.md
        assert sorted(seen["arrays"]) == sorted(names)
        for k, name in enumerate(names):
            assert seen["arrays"][name]["components"] == 3
            np.testing.assert_array_equal(seen["arrays"][name]["values"], f[f"paraview/shapes/{k:06}"][:])
