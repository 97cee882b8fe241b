"""nylonflex: design-space sweeps of nylon-muscle-driven soft bending actuators.

>>> import nylonflex as nf
>>> nf.design_limits(radius=7.5e-3, wall_thickness=2e-3, length=70e-3, coil_index=1.7,
...                  wrap_angle=0.1396)["tip_force_max"]  # doctest: +ELLIPSIS
0.150...
"""

import importlib

from ._version import __version__


__all__ = [
    "CompileWarning",
    "NYLON_PARAMETERS",
    "SILICONE_PARAMETERS",
    "__version__",
    "bend_angle",
    "design_limits",
    "evaluate",
    "fe_bend",
    "fe_stroke",
    "load_config",
    "nylon_parameters",
    "open_cube",
    "run_design",
    "run_sweep",
    "silicone_parameters",
]

#: Public names and the module each comes from, imported on first use: `nylonflex
#: --version` and `--help` then load nothing but the CLI (no numpy, scipy, numba, xarray).
_LAZY = {"NYLON_PARAMETERS": "materials", "SILICONE_PARAMETERS": "materials",
         "nylon_parameters": "materials", "silicone_parameters": "materials",
         "design_limits": "engine", "evaluate": "engine", "load_config": "config",
         "bend_angle": "engine", "fe_bend": "fe", "fe_stroke": "fe",
         "run_sweep": "sweep.conductor", "open_cube": "storage", "run_design": "design",
         "CompileWarning": "kernels.compiling"}


def __dir__():
    return sorted(__all__)


def __getattr__(name):
    if name in _LAZY:
        value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
        globals()[name] = value  # later look-ups are plain (20 us a call of nf.evaluate)
        return value
    raise AttributeError(f"module 'nylonflex' has no attribute {name!r}")
