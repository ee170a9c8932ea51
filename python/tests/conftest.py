"""Shared fixtures: the repository, the command-line binary the Python results are compared
with (built by `cargo test --release`, which `make test` runs first), and a small basis."""

import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
BINARY = ROOT / "target" / "release" / "flexrom"

# the tests hold result files open while the binary writes others (as the Rust tests do)
os.environ.setdefault("HDF5_USE_FILE_LOCKING", "FALSE")


@pytest.fixture(scope="session")
def cli():
    """Runs the flexrom binary with the given arguments, in the repository; returns stdout."""
    if not BINARY.exists():
        pytest.fail(f"{BINARY} is missing: run `cargo build --release` (make test does)")

    def run(*args, check=True):
        p = subprocess.run([str(BINARY), "-q", *map(str, args)], cwd=ROOT, capture_output=True, text=True)
        if check and p.returncode != 0:
            raise AssertionError(f"flexrom {' '.join(map(str, args))} failed: {p.stderr}")
        return p

    return run


@pytest.fixture(scope="session")
def dp_basis(tmp_path_factory):
    """The tutorial's double pendulum trained greedily (pipelines/double_pendulum.toml),
    by the Python package, into a temporary folder (about 1 s)."""
    import flexrom

    path = tmp_path_factory.mktemp("basis") / "double_pendulum.h5"
    flexrom.train(ROOT / "pipelines" / "double_pendulum.toml", output=path)
    return path
