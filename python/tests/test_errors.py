"""Errors as Python exceptions with the command line's messages, each of its class."""

import shutil

import pytest

import flexrom
from conftest import ROOT

PENDULUM = ROOT / "data" / "models" / "pendulum.toml"


def test_bad_model_names_file_and_field(tmp_path):
    """A negative length is a ModelError naming the file, the field and its line (as the CLI's)."""
    text = PENDULUM.read_text().replace("length = 1.2", "length = -1.2", 1)
    assert text != PENDULUM.read_text(), "the pendulum's length line moved: update the test"
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(flexrom.ModelError, match=r"bad\.toml: bodies\[0\]\.length \(line 14\): "):
        flexrom.Model.from_file(path)
    with pytest.raises(flexrom.ModelError, match=r"bodies\[0\]\.length"):
        flexrom.Model.from_toml(text)
    with pytest.raises(flexrom.ModelError, match="missing.toml"):
        flexrom.Model.from_file(tmp_path / "missing.toml")


def test_unknown_parameter_and_non_number():
    """A parameter the model does not name, or a value that is not a number, is refused."""
    m = flexrom.Model.from_file(PENDULUM)
    with pytest.raises(flexrom.ModelError, match="dirve"):
        m.simulate(dirve=1.1)
    assert issubclass(flexrom.ModelError, flexrom.FlexromError)


def test_basis_of_another_model(dp_basis, tmp_path):
    """A basis checked against another pipeline's model, a missing basis and a file that is
    not HDF5 are BasisMismatchError."""
    with pytest.raises(flexrom.BasisMismatchError, match="double_pendulum.h5"):
        flexrom.Basis.load(dp_basis, pipeline=ROOT / "pipelines" / "pendulum.toml")
    with pytest.raises(flexrom.BasisMismatchError, match="does not exist"):
        flexrom.Basis.load(tmp_path / "none.h5")
    # a pipeline file that is wrong is the pipeline's error, not the basis's
    with pytest.raises(flexrom.ModelError, match="missing.toml"):
        flexrom.Basis.load(dp_basis, pipeline=tmp_path / "missing.toml")
    junk = tmp_path / "junk.h5"
    junk.write_text("not HDF5")
    with pytest.raises(flexrom.BasisMismatchError, match="junk.h5"):
        flexrom.Basis.load(junk)


def test_blow_up_is_a_solver_error():
    """The pendulum at ten thousand times its load leaves the plausible strain: SolverError,
    with the stage, the load and the time in the message. (At a thousand times it does too,
    from t ≈ 0.04–0.06 s, once the time step resolves the motion; at the model's own step
    the run is not resolved, and where it goes depends on where Newton starts: from the
    adaptive start its strain stays below the bound.)"""
    m = flexrom.Model.from_file(PENDULUM)
    with pytest.raises(flexrom.SolverError, match=r"simulate at load scale 10000.*t = "):
        m.simulate(load_scale=10000.0, t_end=0.2)


def test_output_path_refused_never_overwritten(tmp_path):
    """to_hdf5 onto the model file, or onto a folder, is refused and leaves them as they were."""
    model = tmp_path / "pendulum.toml"
    shutil.copy(PENDULUM, model)
    r = flexrom.Model.from_file(model).simulate(t_end=0.02)
    with pytest.raises(flexrom.ModelError, match="model file"):
        r.to_hdf5(model)
    assert model.read_text() == PENDULUM.read_text()
    (tmp_path / "folder").mkdir()
    with pytest.raises(flexrom.ModelError):
        r.to_hdf5(tmp_path / "folder")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["folder", "pendulum.toml"]


def test_to_hdf5_replaces_only_its_own_results(tmp_path):
    """An existing file that is not a result flexrom wrote (notes, a TOML file) is refused
    and left as it was; a result written before is replaced."""
    r = flexrom.Model.from_file(PENDULUM).simulate(t_end=0.02)
    notes = tmp_path / "notes.toml"
    notes.write_text("keep me")
    with pytest.raises(flexrom.ModelError, match="not an HDF5 file flexrom wrote"):
        r.to_hdf5(notes)
    assert notes.read_text() == "keep me"
    r.to_hdf5(tmp_path / "r.h5")
    flexrom.Model.from_file(PENDULUM).simulate(t_end=0.04).to_hdf5(tmp_path / "r.h5")
    import h5py

    with h5py.File(tmp_path / "r.h5", "r") as f:
        assert f["t"].shape[0] == 9  # the second run's 0.04 s / 0.005 s + 1 instants


def test_python_names_in_messages():
    """Messages name the call's keywords, not the command line's options; a keyword that is
    not a number is a TypeError; a NaN in a model dict is named."""
    m = flexrom.Model.from_file(PENDULUM)
    with pytest.raises(flexrom.ModelError) as e:
        m.simulate(load_scale=float("nan"))
    assert "load_scale" in str(e.value) and "--" not in str(e.value), str(e.value)
    with pytest.raises(TypeError, match="drive=fast"):
        m.simulate(drive="fast")
    d = {"time": {"t_end": float("nan")}}
    with pytest.raises(flexrom.ModelError, match="NaN"):
        flexrom.Model.from_dict(d)
