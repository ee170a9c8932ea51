"""Model.statics and Model.modes against closed forms and against the command line's files
(the same library calls, so the same numbers to the bit)."""

import math

import h5py
import numpy as np
import pytest

import flexrom

# a 1 m steel cantilever, 10 mm × 10 mm
L, E, RHO, A, I = 1.0, 2.1e11, 7800.0, 1e-4, 1e-8 / 12.0


def cantilever(elements, p=0.0):
    return flexrom.Model.from_toml(
        f"""
[time]
t_end = 1.0
dt = 0.01
rho_inf = 1.0
[[bodies]]
name = "beam"
start = [0.0, 0.0]
angle = 0.0
length = {L}
elements = {elements}
density = {RHO}
area = {A}
inertia = {I}
youngs_modulus = {E}
[[joints]]
type = "clamp"
body = "beam"
node = "start"
[[loads]]
type = "force"
body = "beam"
node = "end"
value = [0.0, {-p}]
scaled = true
[[probes]]
name = "tip"
body = "beam"
node = "end"
""",
        path="cantilever.toml",
    )


def test_statics_gives_the_tip_deflection_and_the_clamp_s_reaction():
    """δ = P L³/(3 E I) (Euler–Bernoulli; cubic elements are nodally exact for a tip load, the
    geometric stiffening at δ/L = 1e-4 is ~1e-8); the clamp holds (0, P) and P x_tip."""
    p = 1e-4 * 3.0 * E * I / L**3
    s = cantilever(8, p).statics(load_scale=1.0, steps=2)
    assert s.load_factor.tolist() == [0.5, 1.0]
    tip = s.probes["tip"][-1]
    expected = p * L**3 / (3.0 * E * I)
    assert abs(-tip[1] - expected) < 1e-3 * expected
    # half the load at the first step: half the deflection (linear to ~1e-8)
    assert abs(s.probes["tip"][0][1] / tip[1] - 0.5) < 1e-6
    (name,) = s.reactions
    assert name == s.labels["reaction"][0] == "joint 0 (clamp beam node 0) on beam node 0"
    fx, fy, m = s.reactions[name][-1]
    assert abs(fx) < 1e-9 * p and abs(fy - p) < 1e-9 * p
    assert abs(m - p * tip[0]) < 1e-9 * p * L
    assert s.units["reactions/force"] == "N" and s.units["load_factor"] == "1"


def test_statics_to_hdf5_writes_the_cli_file(cli, tmp_path):
    """Result.to_hdf5 of Model.statics writes what `flexrom statics -o` writes."""
    p = 1e-4 * 3.0 * E * I / L**3
    model = cantilever(4, p)
    (tmp_path / "c.toml").write_text(model.text)
    cli("statics", tmp_path / "c.toml", "--steps", "3", "--load-scale", "2", "-o", tmp_path / "cli.h5")
    s = model.statics(2.0, steps=3)
    s.to_hdf5(tmp_path / "py.h5")
    with h5py.File(tmp_path / "cli.h5", "r") as a, h5py.File(tmp_path / "py.h5", "r") as b:
        names, other = [], []
        a.visit(names.append)
        b.visit(other.append)
        assert sorted(names) == sorted(other)
        for n in ["q", "multipliers", "load_factor", "reactions/force", "reactions/moment", "energy/strain"]:
            assert np.array_equal(a[n][()], b[n][()]), n
        for k in ["analysis", "time", "load_steps"]:
            assert a.attrs[k] == b.attrs[k], k


def test_modes_give_the_cantilever_frequencies():
    """f_i = (β_i L)²/(2π L²) √(EI/ρA) with β L = 1.8751, 4.6941, 7.8548 (clamped-free
    Euler–Bernoulli beam, e.g. Blevins, Formulas for Natural Frequency and Mode Shape,
    Table 8-1); 16 cubic elements are within 1e-4 of them."""
    m = cantilever(16).modes(3)
    assert isinstance(m, flexrom.Modes) and len(m) == 3 and m.at == "initial"
    exact = [bl**2 / (2 * math.pi * L**2) * math.sqrt(E * I / (RHO * A)) for bl in (1.8751, 4.6941, 7.8548)]
    assert np.allclose(m.frequencies, exact, rtol=1e-4), (m.frequencies, exact)
    assert not any(m.rigid)
    assert m.shapes.shape == (3, cantilever(16).n_dof) and len(m.labels["dof"]) == m.shapes.shape[1]
    # the lowest mode is a bending mode: of the nodes' y, the tip's moves most, the x hardly
    y = m.shapes[0][1::4]
    assert np.argmax(np.abs(y)) == 16 and m.labels["dof"][1 + 4 * 16] == "beam node 16 y"
    assert np.abs(m.shapes[0][0::4]).max() < 1e-6 * np.abs(y).max()


def test_modes_to_hdf5_writes_the_cli_file(cli, tmp_path):
    """Modes.to_hdf5 writes the file `flexrom modes -o` writes (same frequencies and shapes);
    `--count` above the free coordinates is refused as on the command line."""
    model = cantilever(4)
    (tmp_path / "c.toml").write_text(model.text)
    cli("modes", tmp_path / "c.toml", "--count", "2", "-o", tmp_path / "cli.h5")
    m = model.modes(2)
    m.to_hdf5(tmp_path / "py.h5")
    with h5py.File(tmp_path / "cli.h5", "r") as a, h5py.File(tmp_path / "py.h5", "r") as b:
        for n in ["frequencies", "omega_squared", "rigid", "shapes", "q"]:
            assert np.array_equal(a[n][()], b[n][()]), n
        assert a.attrs["at"] == b.attrs["at"] == "initial"
    with pytest.raises(flexrom.FlexromError, match="unconstrained coordinates"):
        model.modes(100)
    with pytest.raises(flexrom.ModelError, match="initial"):
        model.modes(2, at="sagged")
