"""Global attributes that say how a cube was made (docs/interface.md, "The cube")."""

from __future__ import annotations

import dataclasses
import datetime as dt
import os
import platform
from pathlib import Path

import numpy as np
import yaml

from .. import __version__
from ..config import ResolvedConfig, parse_config
from ..files.material_files import read_chamber_file
from ..config.tracking import tracking_section
from ..kernels import source_digest
from ..materials import (COOLING_PARAMETERS, Cooling, Nylon, Silicone, cooling_parameters,
                         nylon_parameters, silicone_parameters)
from ..physics.bending import NEWTON_RTOL, QUADRATURE_ORDERS
from ..physics.limits import STROKE_RTOL
from ..units import InputError, decimal_to_si, from_si
from .model_slab import chamber_coefficients
from ..variables import is_complete  # noqa: F401 - re-exported
from ..variables import AXES, VARIABLES

__all__ = ["CUBE_FORMAT", "CubeSettings", "RECORD_HOST_ENV", "VOLATILE_ATTRS", "chamber_spec",
           "cube_settings", "is_complete", "provenance", "run_attrs", "runnable_config",
           "settings_attrs", "typed_info"]

#: Value of the ``nylonflex_cube`` attribute that marks a file as a cube of this format:
#: "3" stores the pressure curves over the dimension ``pressure_point``, with ``pressure``
#: their auxiliary coordinate (``storage.netcdf4.STORED_DIMS``: CF-clean), "2" over
#: ``pressure``; both store the settings as typed attributes (:func:`settings_attrs`), "1"
#: (before issue 28) only as YAML text, which :func:`cube_settings` still reads.
CUBE_FORMAT = "3"
#: Attributes that differ between two runs of the same config (timing, host, when).
VOLATILE_ATTRS = ("created", "run_seconds", "designs_per_second", "scheduler", "workers",
                  "resumed_slabs", "python_version", "hostname", "history")
#: Set this environment variable (to anything but "" or "0") to record the host's name in
#: a cube (``hostname``); by default a cube says nothing about the machine it came from.
RECORD_HOST_ENV = "NYLONFLEX_RECORD_HOST"


def typed_info(info: dict) -> dict:
    """An executor's ``scheduler`` and ``workers`` with ``workers`` an integer."""
    out = dict(info)
    try:
        out["workers"] = np.int64(int(out["workers"]))
    except (KeyError, TypeError, ValueError):
        pass
    return out


def run_attrs(info: dict, *, complete: bool, seconds: float, computed: int,
              resumed: int, command: str | None = None) -> dict:
    """The global attributes a finished (or stopped) run adds, typed: ``complete`` int8
    1/0, ``run_seconds`` [s] and ``designs_per_second`` [1/s] as float64, counts as ints,
    ``created`` and ``history`` (CF's audit line); the host name only when
    :data:`RECORD_HOST_ENV` asks for it.

    Parameters
    ----------
    info : dict
        The executor's ``scheduler`` and ``workers``.
    complete : bool
        Every slab is in the cube.
    seconds : float
        The slab loop's wall time [s].
    computed : int
        Designs computed by this run (not restored from the journal) [-].
    resumed : int
        Slabs restored from the journal [-].
    command : str, optional
        The command line that ran the sweep, for the ``history`` line (CF: "a list of the
        applications that have modified the original data", with their arguments); None:
        ``nylonflex.run_sweep`` from Python.
    """
    created = dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds")
    out = typed_info(info)
    out.update({
        "complete": np.int8(1 if complete else 0),
        "created": created,
        "history": f"{created} nylonflex {__version__}: {command or 'nylonflex.run_sweep'}"
                   f"{'' if complete else ' (stopped; resume with --resume)'}"
                   f"{f' ({resumed} slabs resumed)' if resumed else ''}",
        "run_seconds": np.float64(round(seconds, 3)),
        "designs_per_second": np.float64(round(computed / seconds) if seconds > 0
                                         else np.nan),
        "resumed_slabs": np.int64(resumed),
        "python_version": platform.python_version(),
    })
    if os.environ.get(RECORD_HOST_ENV, "") not in ("", "0"):
        out["hostname"] = platform.node()
    return out


def provenance(cfg: ResolvedConfig) -> dict:
    """Global attributes that describe how the cube was made (the stable part)."""
    from importlib.metadata import version

    import h5py

    def material(m):
        d = {**m.to_dict(), "description": m.description, "sources": dict(m.sources)}
        if hasattr(m, "stretch_range"):  # the silicone fit's stretch window
            d["stretch_range"] = [float(x) for x in m.stretch_range]
        return yaml.safe_dump(d, sort_keys=False, width=100)

    return {
        "nylonflex_cube": CUBE_FORMAT,
        "title": f"nylonflex design cube '{cfg.name}'",
        # CF 1.8 is what the cube follows (nothing of 1.9-1.11 is used)
        "Conventions": "CF-1.8",
        "name": cfg.name,
        "config_yaml": cfg.text,
        "config_sha256": cfg.sha256,
        "nylonflex_version": __version__,
        "model_sources_sha256": source_digest(),
        "numba_version": version("numba"),
        "numpy_version": np.__version__,
        # the reader's version, not imported by a sweep (importing it costs 0.4 s)
        "xarray_version": version("xarray"),
        "h5py_version": h5py.__version__,
        "silicone": cfg.silicone.name,
        "silicone_parameters": material(cfg.silicone),
        "nylon": cfg.nylon.name,
        "nylon_parameters": material(cfg.nylon),
        **settings_attrs(cfg),
        "quadrature": (f"Gauss-Legendre phi={QUADRATURE_ORDERS['phi']} "
                       f"base={QUADRATURE_ORDERS['base']}; Newton rtol curvature "
                       f"{NEWTON_RTOL:g}, stroke {STROKE_RTOL:g}"),
        "model": "docs/model.md (nylonflex), after the paper 'Soft fluidic actuator based on "
                 "nylon artificial muscles' and Polygerinos et al. 2015",
        "complete": np.int8(0),
        **_sampling(cfg),
    }


#: The numeric fields of :class:`~nylonflex.materials.Silicone` and
#: :class:`~nylonflex.materials.Nylon`, each stored as the attribute ``<kind>_<field>``
#: (float64; a tuple as a float64 array) in the units of ``materials.FIELD_UNITS``.
SILICONE_FIELDS = ("mu", "alpha", "stretch_range")
NYLON_FIELDS = tuple(f.name for f in dataclasses.fields(Nylon)
                     if f.name not in ("name", "description", "sources"))


def settings_attrs(cfg: ResolvedConfig) -> dict:
    """The settings a cube was computed with, as typed global attributes (cube formats 2 and 3).

    ``silicone`` and ``nylon`` (the sets' names) with ``<kind>_description`` (text) and
    ``<kind>_<field>`` for every numeric field (:data:`SILICONE_FIELDS`,
    :data:`NYLON_FIELDS`; float64, tuples as float64 arrays, SI); ``models`` (the model
    variants' names, space-separated); ``base_thickness`` [m] float64, only where b is not
    t; ``supply_voltage`` [V] float64, only with a supply; and, only with cooling,
    ``cooling`` and ``cooling_fluid`` (the sets' names and fluids, space-separated) with
    ``cooling_speed`` [m/s] (a float64 array, one speed a set); only with ``fidelity:
    spread``, ``model_spread`` (the variants its ``<var>_model_lo``/``_hi`` range over,
    space-separated); with ``sealed_chamber`` among the models,
    ``sealed_chamber_coefficients`` (float64 (13,), the coefficients it ran with; (7,) in a
    cube written before the blocked pressure's, read with its neutral values).
    :func:`cube_settings` reads them back.
    """
    def numbers(material, names, kind):
        out = {}
        for name in names:
            value = getattr(material, name)
            out[f"{kind}_{name}"] = np.asarray(value, np.float64) if isinstance(value, tuple) \
                else np.float64(value)
        return out

    out = {"silicone": cfg.silicone.name, "silicone_description": cfg.silicone.description,
           **numbers(cfg.silicone, SILICONE_FIELDS, "silicone"),
           "nylon": cfg.nylon.name, "nylon_description": cfg.nylon.description,
           **numbers(cfg.nylon, NYLON_FIELDS, "nylon"),
           "models": " ".join(cfg.models)}
    if cfg.base_thickness is not None:
        out["base_thickness"] = np.float64(cfg.base_thickness)
    if cfg.supply_voltage is not None:
        out["supply_voltage"] = np.float64(cfg.supply_voltage)
    coolings = cfg.coolings or ((cfg.cooling,) if cfg.cooling is not None else ())
    if coolings:
        out["cooling"] = " ".join(c.name for c in coolings)
        out["cooling_fluid"] = " ".join(c.fluid for c in coolings)
        out["cooling_speed"] = np.array([c.speed for c in coolings], np.float64)
    if cfg.spread:  # fidelity: spread (docs/model.md s. 23)
        out["model_spread"] = " ".join(cfg.spread)
    if "sealed_chamber" in cfg.models:  # the coefficients it ran with (docs/model.md s. 22)
        out["sealed_chamber_coefficients"] = np.asarray(chamber_coefficients(cfg), np.float64)
    return out


@dataclasses.dataclass(frozen=True)
class CubeSettings:
    """The settings a cube was computed with (:func:`cube_settings`): evaluating a design
    under them (:meth:`evaluate_kwargs`) gives the cube's values at its grid designs.

    Attributes
    ----------
    silicone : Silicone
    nylon : Nylon
        The material sets, equal to the sweep's (their ``sources`` aside, which stay in the
        ``<kind>_parameters`` provenance text).
    base_thickness : float or None
        b [m]; None for b = t.
    models : tuple of str
        The model variants; several: the cube's ``model`` dimension.
    supply_voltage : float or None
        The supply [V]; None: no supply limit.
    cooling : Cooling or None
        The cube's one cooling set; None without one, or with several.
    coolings : tuple of Cooling
        Several cooling sets: the cube's ``cooling`` dimension; () otherwise.
    spread : tuple of str
        The variants of the cube's model spread (``fidelity: spread``); () without one.
    """

    silicone: Silicone
    nylon: Nylon
    base_thickness: float | None = None
    models: tuple[str, ...] = ("paper",)
    supply_voltage: float | None = None
    cooling: Cooling | None = None
    coolings: tuple[Cooling, ...] = ()
    spread: tuple[str, ...] = ()
    #: ``sealed_chamber``'s coefficients (k0, k1, g0, g1, c0, c1, cb, ca, r0..r4) the cube
    #: ran with; None: the shipped ones (a cube without that model, or from before they
    #: were stored)
    chamber: tuple | None = None

    def evaluate_kwargs(self, model: str | None = None, cooling: Cooling | None = None) -> dict:
        """Keyword arguments of :func:`nylonflex.evaluate` under one model variant and
        cooling set of the cube (by default its only ones).

        Raises
        ------
        ValueError
            The cube holds several models (or cooling sets) and none is named.
        """
        if model is None:
            if len(self.models) != 1:
                raise ValueError(f"cube: holds {len(self.models)} model variants "
                                 f"({', '.join(self.models)}); name one")
            model = self.models[0]
        if cooling is None and self.coolings:
            raise ValueError(f"cube: holds {len(self.coolings)} cooling sets "
                             f"({', '.join(c.label for c in self.coolings)}); name one")
        out = {"silicone": self.silicone, "nylon": self.nylon,
               "base_thickness": self.base_thickness, "model": model}
        if self.supply_voltage is not None:
            out["supply_voltage"] = self.supply_voltage
        cooling = self.cooling if cooling is None else cooling
        if cooling is not None:
            out["cooling"] = cooling
        if self.chamber is not None:
            out["chamber"] = self.chamber
        return out


def cube_settings(ds_or_attrs) -> CubeSettings:
    """The settings a cube was computed with, from its typed attributes
    (:func:`settings_attrs`), or, in a cube of format 1 (before them), from its YAML text.

    Parameters
    ----------
    ds_or_attrs : xarray.Dataset, h5py.File or mapping
        A cube (``nf.open_cube``) or its global attributes (``ds.attrs``,
        :func:`nylonflex.storage.cube_attrs`).

    Returns
    -------
    CubeSettings

    Raises
    ------
    ValueError
        An attribute it needs is missing or unreadable (one line naming it).
    """
    attrs = getattr(ds_or_attrs, "attrs", ds_or_attrs)
    if attrs is None or "nylonflex_cube" not in attrs:
        raise ValueError("cube: no nylonflex_cube attribute; cannot rebuild its settings "
                         "(was it written by 'nylonflex sweep'?)")
    if _text(attrs, "nylonflex_cube") == "1":
        return _yaml_settings(attrs)

    def material(cls, kind, names, plain):
        kw = {}
        for name in names:
            key = f"{kind}_{name}"
            kw[name] = _numbers(attrs, key) if name not in plain else _number(attrs, key)
        return cls(**kw, name=_text(attrs, kind),
                   description=_text(attrs, f"{kind}_description"))

    silicone = material(Silicone, "silicone", SILICONE_FIELDS, ())
    nylon = material(Nylon, "nylon", NYLON_FIELDS,
                     {n for n in NYLON_FIELDS if not n.endswith("_table")})
    coolings = ()
    if "cooling" in attrs:
        names = _text(attrs, "cooling").split()
        fluids = _text(attrs, "cooling_fluid").split()
        speeds = _numbers(attrs, "cooling_speed")
        if not len(names) == len(fluids) == len(speeds):
            raise ValueError(f"cube: attributes cooling, cooling_fluid and cooling_speed "
                             f"differ in length ({len(names)}, {len(fluids)}, {len(speeds)})")
        coolings = tuple(_cooling(n, f, s) for n, f, s in zip(names, fluids, speeds))
    return CubeSettings(
        silicone, nylon,
        base_thickness=_number(attrs, "base_thickness") if "base_thickness" in attrs else None,
        models=tuple(_text(attrs, "models").split()),
        supply_voltage=_number(attrs, "supply_voltage") if "supply_voltage" in attrs else None,
        cooling=coolings[0] if len(coolings) == 1 else None,
        coolings=coolings if len(coolings) > 1 else (),
        spread=tuple(_text(attrs, "model_spread").split()) if "model_spread" in attrs else (),
        chamber=tuple(float(c) for c in _numbers(attrs, "sealed_chamber_coefficients"))
        if "sealed_chamber_coefficients" in attrs else None)


def _value(attrs, key):
    if key not in attrs:
        raise ValueError(f"cube: no {key} attribute; cannot rebuild its settings (was it "
                         "written by 'nylonflex sweep'?)")
    return attrs[key]


def _text(attrs, key) -> str:
    """A text attribute (h5py may give it as bytes, or as a one-element array)."""
    value = _value(attrs, key)
    if isinstance(value, np.ndarray) and value.size == 1:
        value = value.reshape(-1)[0]
    if isinstance(value, bytes):
        value = value.decode("utf-8", "replace")
    if not isinstance(value, str):
        raise ValueError(f"cube: attribute {key}: must be text, got {type(value).__name__}")
    return str(value)


def _numbers(attrs, key) -> tuple[float, ...]:
    """A float attribute as a tuple of floats (a one-element array reads as a scalar)."""
    value = np.atleast_1d(np.asarray(_value(attrs, key)))
    if value.dtype.kind not in "fiu" or value.ndim != 1 or value.size == 0:
        raise ValueError(f"cube: attribute {key}: must be numbers, got "
                         f"{value.dtype} of shape {value.shape}")
    return tuple(float(x) for x in value)


def _number(attrs, key) -> float:
    value = _numbers(attrs, key)
    if len(value) != 1:
        raise ValueError(f"cube: attribute {key}: must be one number, got {len(value)}")
    return value[0]


def _cooling(name: str, fluid: str, speed: float) -> Cooling:
    """A cube's cooling set: the named set at its speed, as the config resolved it (its
    description and sources from the set's table), or, for a set this version does not
    name, the fluid and speed alone."""
    own = COOLING_PARAMETERS.get(name)
    if own is not None and own.get("fluid") == fluid:
        return cooling_parameters({"set": name, "speed": speed})
    return Cooling(fluid, speed, name=name)


def _yaml_settings(attrs) -> CubeSettings:
    """The settings of a cube of format 1, from ``config_yaml`` (the resolved config, SI)
    and the sets' ``<kind>_parameters`` (their descriptions and stretch range)."""
    def load(key):
        try:
            doc = yaml.safe_load(_text(attrs, key))
        except yaml.YAMLError:
            doc = None
        if not isinstance(doc, dict):
            raise ValueError(f"cube: attribute {key}: not a readable YAML mapping; cannot "
                             "rebuild its settings")
        return doc

    doc = load("config_yaml")
    for kind in ("silicone", "nylon"):
        if not isinstance(doc.get(kind), dict):
            raise ValueError(f"cube: attribute config_yaml: no {kind} set; cannot rebuild "
                             "its settings")

    def rebuild(cls, kind):
        known = {f.name for f in dataclasses.fields(cls)} - {"sources"}
        extra = load(f"{kind}_parameters") if f"{kind}_parameters" in attrs else {}
        values = {**{k: v for k, v in extra.items() if k in ("description", "stretch_range")},
                  **doc[kind]}
        kw = {k: tuple(float(x) for x in v) if isinstance(v, list) else v
              for k, v in values.items() if k in known}
        missing = [f.name for f in dataclasses.fields(cls)
                   if f.name not in kw and f.default is dataclasses.MISSING and
                   f.default_factory is dataclasses.MISSING]
        if missing:
            raise ValueError(f"cube: attribute config_yaml: the {kind} set has no "
                             f"{missing[0]}; cannot rebuild its settings")
        return cls(**kw)

    base = doc.get("base_thickness", "wall")
    model = doc.get("model", ["paper"])
    supply = doc.get("supply_voltage")
    coolings = doc.get("cooling")
    coolings = [coolings] if isinstance(coolings, dict) else list(coolings or [])
    if not all(isinstance(c, dict) and "fluid" in c for c in coolings):
        raise ValueError("cube: attribute config_yaml: a cooling entry has no fluid; cannot "
                         "rebuild its settings")
    coolings = tuple(_cooling(str(c.get("name", "custom")), str(c["fluid"]),
                              float(c.get("speed", 0.0))) for c in coolings)
    return CubeSettings(
        rebuild(Silicone, "silicone"), rebuild(Nylon, "nylon"),
        base_thickness=None if base in (None, "wall") else float(base),
        models=(model,) if isinstance(model, str) else tuple(str(m) for m in model),
        supply_voltage=None if supply is None else float(supply),
        cooling=coolings[0] if len(coolings) == 1 else None,
        coolings=coolings if len(coolings) > 1 else ())


def _cooling_spec(resolved):
    """A config's ``cooling`` entry (a set name, or the set with its speed) of a resolved
    one (one set or a list)."""
    def one(c):
        env = _cooling(str(c.get("name", "custom")), str(c["fluid"]), float(c["speed"]))
        # the set's own speed: its name alone (Cooling.label, the cube's coordinate)
        return env.name if env.label == env.name else {"set": env.name, "speed": env.speed}

    return [one(c) for c in resolved] if isinstance(resolved, list) else one(resolved)


def _sampling(cfg: ResolvedConfig) -> dict:
    """The distributions, sample count and seed of a sampled sweep; its requirements."""
    out = {}
    if cfg.uncertainty is not None:
        spec = cfg.uncertainty
        out["uncertainty"] = yaml.safe_dump(spec.to_dict(), sort_keys=False, width=100)
        out["uncertainty_samples"] = np.int64(spec.samples)
        out["uncertainty_seed"] = np.int64(spec.seed)
        out["uncertainty_method"] = ("scrambled Sobol' points (scipy.stats.qmc.Sobol), "
                                     "normal or uniform quantile functions; a fit's "
                                     "covariance by its Cholesky factor")
    if cfg.requirements:
        out["requirements"] = "; ".join(cfg.requirements)
    return out


def runnable_config(attrs) -> str:
    """A sweep config (YAML text) that recomputes a cube: ``nylonflex info CUBE --config``.

    Built from the cube's resolved config (``config_yaml``, SI) and material attributes:
    each grid axis as ``start/stop/num`` or ``values`` in its display unit (mm, deg, kPa)
    where those decimals resolve to exactly the cube's coordinates, else as SI values;
    materials by set name (with the fields that differ), or by their fitted file where it
    is still there and unchanged, else every field; the model, supply, cooling, uncertainty,
    requirements, tracking and model spread as the cube has them, and its codec. Sweeping it gives a cube whose
    data equal this one's bit for bit (the slab size aside, which does not change them).

    Parameters
    ----------
    attrs : mapping
        Global attributes of a cube (``ds.attrs`` or :func:`nylonflex.storage.cube_attrs`).

    Returns
    -------
    str
        The config, YAML, with a comment naming the cube's config hash.

    Raises
    ------
    ValueError
        The attributes hold no readable ``config_yaml`` (not a nylonflex cube).
    """
    doc = yaml.safe_load(attrs.get("config_yaml") or "null") if attrs else None
    if not isinstance(doc, dict) or "grid" not in doc:
        raise ValueError("cube: no readable config_yaml attribute; cannot rebuild its "
                         "config (was it written by 'nylonflex sweep'?)")
    out = {"name": doc["name"],
           "silicone": _material_spec("silicone", doc["silicone"],
                                      attrs.get("silicone_parameters")),
           "nylon": _material_spec("nylon", doc["nylon"], attrs.get("nylon_parameters"))}

    out["grid"] = {k: _axis_spec(k, doc["grid"][k]) for k in AXES}
    base = doc.get("base_thickness", "wall")
    out["base_thickness"] = "wall" if base in (None, "wall") else \
        {"value": float(base), "units": "m"}
    out["curves"] = {k: _axis_spec(k, doc["curves"][k]) for k in ("stroke", "pressure")}
    if "model" in doc:
        out["model"] = list(doc["model"]) if len(doc["model"]) > 1 else doc["model"][0]
    if doc.get("supply_voltage") is not None:
        out["supply"] = {"voltage": float(doc["supply_voltage"]), "units": "V"}
    if doc.get("cooling") is not None:  # docs/model.md s. 9
        out["cooling"] = _cooling_spec(doc["cooling"])
    if "uncertainty" in doc:
        out["uncertainty"] = _uncertainty_spec(doc["uncertainty"])
    if doc.get("requirements"):
        out["requirements"] = list(doc["requirements"])
    if "tracking" in doc:  # docs/model.md s. 19
        out["tracking"] = tracking_section(doc["tracking"])
    if isinstance(doc.get("fidelity"), dict):  # docs/model.md s. 23
        out["fidelity"] = {"spread": [str(m) for m in doc["fidelity"]["spread"]]}
    if "chamber" in doc:  # docs/bench.md: by its file, while that still says the same
        out["chamber"] = chamber_spec(doc["chamber"])
    if attrs.get("compression"):
        out["compression"] = str(attrs["compression"])
    out["charts"] = []
    # any axis whose display decimals do not resolve to the very same floats: SI values
    cfg = parse_config(out)
    for group, axes in (("grid", cfg.axes), ("curves", cfg.curves)):
        for name, values in axes.items():
            if values.tolist() != [float(x) for x in doc[group][name]]:
                out[group][name] = {"values": [float(x) for x in doc[group][name]],
                                    "units": _SI_UNITS.get(name, "1")}
    head = (f"# the config of cube '{doc['name']}' (config sha256 "
            f"{str(attrs.get('config_sha256', ''))[:16]}), written by nylonflex info "
            "--config\n")
    return head + yaml.safe_dump(out, sort_keys=False, default_flow_style=None, width=100)


def chamber_spec(chamber: dict) -> dict:
    """``chamber: {file: ...}`` of a cube's config (its resolved ``chamber``, the file and
    the values read from it), the file checked to hold the values the cube ran with (a
    ValueError naming it otherwise: no other form can recompute it)."""
    path = str(chamber.get("file", ""))
    try:
        now = read_chamber_file(path)
    except InputError as err:
        raise ValueError(f"cube: its chamber file cannot be read ({err}); cannot rebuild "
                         "its config") from None
    if any(now.get(k) != v for k, v in chamber.items() if k != "file"):
        raise ValueError(f"cube: its chamber file {path} has changed since the sweep; "
                         "cannot rebuild its config")
    return {"file": path}


#: The SI unit a config may give each axis in (the last resort of :func:`runnable_config`).
_SI_UNITS = {"radius": "m", "wall_thickness": "m", "length": "m", "wrap_angle": "rad",
             "pressure": "Pa"}


def _decimals(name: str, values) -> list | None:
    """The shortest decimals in the axis's display unit that convert back to ``values``
    [SI] exactly, or None."""
    unit = VARIABLES[name].display
    out = []
    for x in values:
        shown = from_si(float(x), unit)
        for digits in range(1, 18):
            d = float(f"{shown:.{digits}g}")
            if decimal_to_si(d, unit) == x:
                out.append(int(d) if d.is_integer() and abs(d) < 1e15 else d)
                break
        else:
            return None
    return out


def _axis_spec(name: str, values) -> dict:
    """An axis as a config gives it: start/stop/num when its display-unit decimals are
    evenly spaced, else values (exactness is checked by :func:`runnable_config`)."""
    from fractions import Fraction

    unit = VARIABLES[name].display
    units = {} if unit == "1" else {"units": unit}
    dec = _decimals(name, values)
    if dec is None:
        return {"values": [float(x) for x in values], "units": _SI_UNITS.get(name, "1")}
    if len(dec) >= 3:
        steps = {Fraction(repr(b)) - Fraction(repr(a)) for a, b in zip(dec, dec[1:])}
        if len(steps) == 1:
            return {"start": dec[0], "stop": dec[-1], "num": len(dec), **units}
    return {"values": dec, **units}


def _material_spec(kind: str, resolved: dict, parameters_text):
    """A material as a config names it: the set's name, ``{set, changed fields}``, the
    fitted file (where it still holds these values), or every field over the default set."""
    make = silicone_parameters if kind == "silicone" else nylon_parameters
    fields = {k: v for k, v in resolved.items() if k != "name"}
    name = str(resolved.get("name", ""))
    try:
        extra = yaml.safe_load(parameters_text) if parameters_text else {}
    except yaml.YAMLError:
        extra = {}
    extra = extra if isinstance(extra, dict) else {}
    base = name.removesuffix("+override")
    try:
        ref = make(base).to_dict()
    except ValueError:
        ref = None
    if ref is not None:
        changed = {k: v for k, v in fields.items() if ref.get(k) != v}
        if not changed and name == base:
            return base
        return {"set": base, **changed}
    source = (extra.get("sources") or {}).get("file")
    if source:
        path = Path(source).resolve()
        try:
            if path.is_file() and make({"file": str(path)}).to_dict() == resolved:
                return {"file": str(path)}
        except ValueError:
            pass
    default = "tc5005" if kind == "silicone" else "silver_nylon66"
    spec = {"set": default, **fields}
    if kind == "silicone" and isinstance(extra.get("stretch_range"), list):
        spec["stretch_range"] = [float(x) for x in extra["stretch_range"]]
    return spec


def _uncertainty_spec(resolved: dict) -> dict:
    """The ``uncertainty:`` section from its resolved form (SI sd, sorted parameters)."""
    params = {}
    for name, p in resolved.get("parameters", {}).items():
        if p.get("fields"):  # a fit's covariance: from_fit of the material's file
            params[name] = {"from_fit": True}
            continue
        d = {"distribution": p["distribution"]}
        if p.get("rel_sd") is not None:
            d["rel_sd"] = float(p["rel_sd"])
        if p.get("sd") is not None:
            d["sd"] = float(p["sd"])
            if name in _SI_UNITS:
                d["units"] = _SI_UNITS[name]
            elif "." in name:
                d["units"] = "1"
        params[name] = d
    return {"samples": int(resolved["samples"]), "seed": int(resolved["seed"]),
            "quantiles": [float(q) for q in resolved["quantiles"]], "parameters": params}
