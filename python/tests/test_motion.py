"""Seeing the motion. `--paraview`: the XDMF file beside a result, read back with meshio
(PyPI) as a user's script would: the polyline cells, the first instant's points on the
undeformed pendulum (straight along x from the pin at the origin: y = 0, x increasing), and
per instant the time, strain, curvature and velocity at every point. `Result.animate`: a GIF
flexrom recognises as its own (replaced), and no temporary file left beside it."""

import pathlib

import numpy as np
import pytest

import flexrom

ROOT = pathlib.Path(__file__).resolve().parents[2]


def test_result_animate_writes_a_gif(tmp_path):
    r = flexrom.Model.from_file(ROOT / "data/models/pendulum.toml").simulate(t_end=0.02)
    out = tmp_path / "p.gif"
    r.animate(out, size=(300, 200))
    data = out.read_bytes()
    assert data.startswith(b"GIF89a") and data.endswith(b"flexrom animation\x00\x3b")
    r.animate(out, fps=10)  # flexrom's own: replaced
    assert [p.name for p in tmp_path.iterdir()] == ["p.gif"]
    with pytest.raises(Exception, match="gif"):
        r.animate(tmp_path / "p.png")


def test_meshio_reads_the_xdmf(cli, tmp_path):
    import meshio  # installed with the test requirements (Makefile: deps)
    out = tmp_path / "p.h5"
    cli("simulate", "data/models/pendulum.toml", "-o", out, "--t-end", "0.02", "--paraview")
    xdmf = pathlib.Path(tmp_path / "p.xdmf")
    with meshio.xdmf.TimeSeriesReader(xdmf) as r:
        points, cells = r.read_points_cells()
        n = 4 * 50 + 1  # 4 samples an element and the last node (docs/file-formats.md)
        assert points.shape == (n, 3)
        assert cells[0].type == "line" and cells[0].data.shape == (n - 1, 2)
        # t = 0: the straight beam from the pin at the origin along +x
        assert np.allclose(points[:, 1], 0.0, atol=1e-12)
        assert points[0, 0] == pytest.approx(0.0, abs=1e-12)
        assert np.all(np.diff(points[:, 0]) > 0)
        assert r.num_steps == 5  # t = 0 and 4 steps of 0.005 s
        times = []
        for k in range(r.num_steps):
            t, point_data, _ = r.read_data(k)
            times.append(t)
            assert set(point_data) == {"strain", "curvature", "velocity"}
            assert point_data["velocity"].shape == (n, 3)
            assert point_data["strain"].shape == (n,)
        assert times == pytest.approx([0.0, 0.005, 0.01, 0.015, 0.02])


def test_meshio_reads_the_modes_xdmf(cli, tmp_path):
    """`modes --paraview`: one mesh on the straight pendulum with one displacement field per
    mode, named by number and frequency; the pin (first point) does not move."""
    import h5py
    import meshio
    out = tmp_path / "m.h5"
    cli("modes", "data/models/pendulum.toml", "--count", "3", "-o", out, "--paraview")
    m = meshio.read(tmp_path / "m.xdmf")
    n = 4 * 50 + 1  # 4 samples an element and the last node (docs/file-formats.md)
    assert m.points.shape == (n, 3)
    assert m.cells[0].type == "line" and m.cells[0].data.shape == (n - 1, 2)
    with h5py.File(out) as f:
        freq = f["frequencies"][:]
    assert list(m.point_data) == [f"mode_{k + 1} ({freq[k]:.6f} Hz)" for k in range(3)]
    for u in m.point_data.values():
        assert u.shape == (n, 3)
        assert np.allclose(u[0], 0.0, atol=1e-12 * np.abs(u).max())
