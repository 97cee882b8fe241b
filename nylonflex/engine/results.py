"""Results of :func:`nylonflex.evaluate` as a labelled ``xarray.Dataset`` (``as_dataset=
True``): every design variable with its registry attributes (``units``, ``long_name``,
``description``, CF flags), the five design inputs as coordinates, for notebooks and
plots (issue 50)."""

from __future__ import annotations

import numpy as np

from ..variables import AXES, VARIABLES


def design_dims(shape: tuple) -> tuple[str, ...]:
    """Dimension names of designs of ``shape``: none for one design, ``design`` for a
    1-D batch, ``design_0``, ``design_1``, ... for more axes."""
    if len(shape) == 1:
        return ("design",)
    return tuple(f"design_{i}" for i in range(len(shape)))


def to_dataset(out: dict, inputs: dict, attrs: dict | None = None):
    """``out`` (name -> array of one broadcast shape, SI) as a Dataset.

    Parameters
    ----------
    out : dict of str to ndarray
        :func:`nylonflex.evaluate`'s result.
    inputs : dict of str to float or ndarray
        The design inputs (``radius``, ... [m, rad, -]) that broadcast to that shape; each
        becomes a coordinate with its registry attributes.
    attrs : dict, optional
        Global attributes (the model, the material sets).
    """
    import xarray as xr

    shape = np.shape(next(iter(out.values()))) if out else ()
    dims = design_dims(shape)
    data = {name: (dims, np.asarray(value), VARIABLES[name].attrs() if name in VARIABLES
                   else {}) for name, value in out.items()}
    coords = {}
    for name in (*AXES, "base_thickness"):
        value = inputs.get(name)
        if value is None:
            continue
        meta = VARIABLES[name].attrs() if name in VARIABLES else {"units": "m"}
        coords[name] = (dims, np.broadcast_to(np.asarray(value, dtype=float), shape).copy(),
                        meta)
    return xr.Dataset(data, coords=coords, attrs=dict(attrs or {}))
