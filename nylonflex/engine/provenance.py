"""Global attributes that say how a cube was made (docs/interface.md, "The cube")."""

from __future__ import annotations

import numpy as np

from ..config import ResolvedConfig
from ..physics.bending import NEWTON_RTOL, QUADRATURE_ORDERS
from ..physics.limits import STROKE_RTOL

__all__ = ["CUBE_FORMAT", "VOLATILE_ATTRS", "evaluate_settings", "provenance"]

#: Value of the ``nylonflex_cube`` attribute that marks a file as a cube of this format.
CUBE_FORMAT = "1"
#: Attributes that differ between two runs of the same config (timing, host, when).
VOLATILE_ATTRS = ("created", "run_seconds", "designs_per_second", "scheduler", "workers",
                  "resumed_slabs", "python_version", "hostname")


def provenance(cfg: ResolvedConfig) -> dict:
    """Global attributes that describe how the cube was made (the stable part)."""
    from importlib.metadata import version

    import h5py
    import numba
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
        # the reader's version, not imported by a sweep (importing it costs 0.4 s)
        "xarray_version": version("xarray"),
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
        **_sampling(cfg),
    }


def evaluate_settings(attrs) -> dict:
    """Keyword arguments of :func:`nylonflex.evaluate` that reproduce a cube's designs.

    Rebuilds the silicone and nylon sets, the base thickness and the model (and the supply,
    when the cube's config names one) from the cube's ``config_yaml`` attribute, the
    resolved config in SI that :func:`provenance` stores.

    Parameters
    ----------
    attrs : mapping
        Global attributes of a cube (``ds.attrs`` or
        :func:`nylonflex.storage.cube_attrs`).

    Returns
    -------
    dict
        ``silicone`` (:class:`~nylonflex.materials.Silicone`), ``nylon``
        (:class:`~nylonflex.materials.Nylon`), ``base_thickness`` [m] or None, and
        ``model`` (and ``supply_voltage`` [V] when the cube has a supply).

    Raises
    ------
    ValueError
        The attributes hold no readable ``config_yaml`` (not a nylonflex cube).
    """
    import dataclasses

    import yaml

    from ..materials import Nylon, Silicone

    text = attrs.get("config_yaml") if attrs is not None else None
    try:
        doc = yaml.safe_load(text) if text else None
    except yaml.YAMLError:
        doc = None
    if not isinstance(doc, dict) or "silicone" not in doc or "nylon" not in doc:
        raise ValueError("cube: no readable config_yaml attribute; cannot rebuild its "
                         "materials (was it written by 'nylonflex sweep'?)")

    def rebuild(cls, values):
        known = {f.name for f in dataclasses.fields(cls)} - {"description", "sources"}
        kw = {k: tuple(float(x) for x in v) if isinstance(v, list) else v
              for k, v in values.items() if k in known}
        return cls(**kw)

    base = doc.get("base_thickness", "wall")
    out = {"silicone": rebuild(Silicone, doc["silicone"]),
           "nylon": rebuild(Nylon, doc["nylon"]),
           "base_thickness": None if base in (None, "wall") else float(base),
           "model": "paper"}
    model = doc.get("model")
    if isinstance(model, str):
        out["model"] = model
    elif isinstance(model, list) and len(model) == 1:
        out["model"] = str(model[0])
    elif model is not None:  # several models: the caller picks one
        out["model"] = [str(m) for m in model]
    # the resolved config stores the supply as supply_voltage [V] (config.canonical_yaml)
    supply = doc.get("supply_voltage", doc.get("supply"))
    if isinstance(supply, dict) and supply.get("voltage") is not None:
        out["supply_voltage"] = float(supply["voltage"])
    elif isinstance(supply, (int, float)) and not isinstance(supply, bool):
        out["supply_voltage"] = float(supply)
    return out


def _sampling(cfg: ResolvedConfig) -> dict:
    """The distributions, sample count and seed of a sampled sweep; its requirements."""
    import yaml

    out = {}
    if cfg.uncertainty is not None:
        spec = cfg.uncertainty
        out["uncertainty"] = yaml.safe_dump(spec.to_dict(), sort_keys=False, width=100)
        out["uncertainty_samples"] = str(spec.samples)
        out["uncertainty_seed"] = str(spec.seed)
        out["uncertainty_method"] = ("scrambled Sobol' points (scipy.stats.qmc.Sobol), "
                                     "normal or uniform quantile functions; a fit's "
                                     "covariance by its Cholesky factor")
    if cfg.requirements:
        out["requirements"] = "; ".join(cfg.requirements)
    return out
