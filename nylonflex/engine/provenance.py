"""Global attributes that say how a cube was made (INTERFACE.md, "The cube")."""

from __future__ import annotations

import numpy as np

from ..config import ResolvedConfig
from ..physics.bending import NEWTON_RTOL, QUADRATURE_ORDERS
from ..physics.limits import STROKE_RTOL

__all__ = ["CUBE_FORMAT", "VOLATILE_ATTRS", "provenance"]

#: Value of the ``nylonflex_cube`` attribute that marks a file as a cube of this format.
CUBE_FORMAT = "1"
#: Attributes that differ between two runs of the same config (timing, host, when).
VOLATILE_ATTRS = ("created", "run_seconds", "designs_per_second", "scheduler", "workers",
                  "resumed_slabs", "python_version", "hostname")


def provenance(cfg: ResolvedConfig) -> dict:
    """Global attributes that describe how the cube was made (the stable part)."""
    import h5py
    import numba
    import xarray
    import yaml

    from .. import __version__
    from ..kernels._compile import source_digest

    def material(m):
        d = {**m.to_dict(), "description": m.description, "sources": dict(m.sources)}
        if hasattr(m, "stretch_range"):  # the silicone fit's stretch window
            d["stretch_range"] = [float(x) for x in m.stretch_range]
        return yaml.safe_dump(d, sort_keys=False, width=100)

    return {
        "nylonflex_cube": CUBE_FORMAT,
        "title": f"nylonflex design cube '{cfg.name}'",
        "Conventions": "CF-1.10",
        "name": cfg.name,
        "config_yaml": cfg.text,
        "config_sha256": cfg.sha256,
        "nylonflex_version": __version__,
        "model_sources_sha256": source_digest(),
        "numba_version": numba.__version__,
        "numpy_version": np.__version__,
        "xarray_version": xarray.__version__,
        "h5py_version": h5py.__version__,
        "silicone": cfg.silicone.name,
        "silicone_parameters": material(cfg.silicone),
        "nylon": cfg.nylon.name,
        "nylon_parameters": material(cfg.nylon),
        "base_thickness": "wall" if cfg.base_thickness is None else
        f"{cfg.base_thickness} m",
        "quadrature": (f"Gauss-Legendre phi={QUADRATURE_ORDERS['phi']} "
                       f"base={QUADRATURE_ORDERS['base']}; Newton rtol curvature "
                       f"{NEWTON_RTOL:g}, stroke {STROKE_RTOL:g}"),
        "model": "docs/model.md (nylonflex), after the paper 'Soft fluidic actuator based on "
                 "nylon artificial muscles' and Polygerinos et al. 2015",
        "models": " ".join(cfg.models),
        "supply_voltage": "none" if cfg.supply_voltage is None else f"{cfg.supply_voltage:g} V",
        "complete": "false",
    }
