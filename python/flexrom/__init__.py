"""flexrom: planar flexible multibody dynamics (ANCF beams) with POD reduced-order models.

    import flexrom
    m = flexrom.Model.from_file("data/models/fourbar.toml")
    full = m.simulate(load_scale=1.1)              # a Result: t, q, multipliers, probes, ...
    basis = flexrom.train("pipelines/fourbar.toml")  # full runs, POD, written to HDF5
    r = basis.online(load_scale=1.1)               # the reduced run and its error estimate
    s = basis.sweep(np.linspace(0.8, 1.2, 100))    # arrays with the load axis first

Arrays are numpy arrays in the layout of flexrom's HDF5 files (time first). Errors are
`FlexromError` and its subclasses, with the command line's messages; a load outside the
training range, or an estimate over the tolerance, warns with `FlexromWarning`. Long work
releases the GIL and stops on Ctrl-C (`KeyboardInterrupt`). The library's progress lines
go to the `logging` logger "flexrom" (silent unless logging is configured).
"""

from __future__ import annotations

import json
from os import PathLike
from typing import Any, Callable, Dict, List, Optional, Union

from ._flexrom import (
    Basis,
    BasisMismatchError,
    FlexromError,
    FlexromWarning,
    Model,
    ModelError,
    Result,
    SolverError,
    __version__,
    train as _train,
    validate_json as _validate_json,
)

__all__ = [
    "Basis",
    "BasisMismatchError",
    "FlexromError",
    "FlexromWarning",
    "Model",
    "ModelError",
    "Result",
    "SolverError",
    "__version__",
    "train",
    "validate",
]

_Path = Union[str, "PathLike[str]"]


def train(
    pipeline: _Path,
    output: Optional[_Path] = None,
    progress: Union[None, bool, Callable[[str, int, int], Any]] = None,
) -> Basis:
    """Trains the pipeline's basis (`flexrom train`): full runs, POD (and hyper-reduction,
    greedy training where the pipeline asks), written to `output` (default: the pipeline's
    `basis`). Returns the basis, loaded. `progress`: True for a text bar on stderr, or a
    callable(label, done, total) called as greedy's candidates finish."""
    return _train(pipeline, output, progress)


def validate(
    pipeline: _Path,
    load_scale: Optional[float] = None,
    basis: Optional[_Path] = None,
    estimate: Optional[str] = None,
    dense: Optional[bool] = None,
    **params: float,
) -> Union[Dict[str, Any], List[Dict[str, Any]]]:
    """Full and reduced runs compared (`flexrom validate --json`): a dict of the figures
    (`rel_error`, `error_estimate`, `speedup`, ...) where `load_scale` or the named
    parameters name one point, else a list of them (the pipeline's validation points, or
    the named values at each of its `[validate]` loads). `estimate`: the estimate's method
    over the pipeline's; `dense`: None skips the dense-LU timing above 256 MiB, True runs
    it, False skips it. Warns as the command does (an estimate over the tolerance, a load
    outside the training range)."""
    return json.loads(_validate_json(pipeline, load_scale, params or None, basis, estimate, dense))
