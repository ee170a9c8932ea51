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

from ._flexrom import (
    Basis,
    BasisMismatchError,
    FlexromError,
    FlexromWarning,
    Model,
    ModelError,
    Modes,
    Result,
    SolverError,
    __version__,
    train,
    validate,
)

__all__ = [
    "Basis",
    "BasisMismatchError",
    "FlexromError",
    "FlexromWarning",
    "Model",
    "ModelError",
    "Modes",
    "Result",
    "SolverError",
    "__version__",
    "train",
    "validate",
]
