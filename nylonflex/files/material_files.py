"""The material file a fit writes, and reading it back as a material set.

A silicone file (``kind: silicone``) holds the Ogden ``mu`` [Pa] and ``alpha`` [-] (or a
Yeoh ``c1``, ``c2`` [Pa], which a sweep cannot use), their standard errors, intervals and
covariance, the fitted stretch range, the fit statistics and the provenance (the data
file's path and SHA-256, the nylonflex version, the time). A nylon file (``kind: nylon``)
names a ``base`` set and holds the fields of :class:`nylonflex.materials.Nylon` it replaces.
Configs use either as ``silicone: {file: fits/my.yaml}`` / ``nylon: {file: ...}``; a
relative path is taken from the config file's folder.
"""

from __future__ import annotations

import datetime
import os
from pathlib import Path

import numpy as np
import yaml

from .._version import __version__
from ..units import InputError
from .safe_yaml import read_yaml

__all__ = ["CHAMBER_FIELDS", "anchor_material_files", "material_document", "read_chamber_file",
           "read_material_set", "write_material_file"]

_OGDEN_FORMS = ("ogden1", "ogden2", "ogden3", "neo_hookean")


def _plain(obj):
    if isinstance(obj, dict):
        return {str(k): _plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple, np.ndarray)):
        return [_plain(v) for v in obj]
    if isinstance(obj, (np.floating, float)):
        return float(obj)
    if isinstance(obj, (np.integer, int)) and not isinstance(obj, bool):
        return int(obj)
    return obj


def material_document(result, name=None, fields=None) -> dict:
    """The YAML document of a fit (see the module docstring), SI.

    Parameters
    ----------
    result : FitResult
        A fit of :mod:`nylonflex.calibration`.
    name : str, optional
        Name of the set (default: the result's name, or the data file's stem).
    fields : dict, optional
        For a nylon fit: ``{"base": set name, field: value, ...}`` to write.
    """
    name = name or result.name or Path(result.data["path"]).stem
    kind = result.kind if result.kind in ("silicone", "chamber") else "nylon"
    doc = {"kind": kind, "name": name, "fit": result.kind, "model": result.model}
    if result.test:
        doc["test"] = result.test
    if result.kind in ("silicone", "chamber"):
        doc.update(result.parameters)
        if "design" in result.extra:  # the chamber's: the actuator it was measured on
            doc["design"] = dict(result.extra["design"])
    else:
        doc.update(fields if fields is not None else result.extra.get("fields", {}))
    doc["parameters"] = dict(result.parameters)
    doc["units"] = dict(result.units)
    doc["stderr"] = result.stderr
    doc["ci95"] = result.ci95
    doc["parameter_order"] = list(result.parameter_order)
    doc["covariance"] = np.asarray(result.covariance).tolist()
    doc["uncertainty"] = result.uncertainty
    for key, d in result.derived.items():
        doc[key] = {"value": d["value"], "stderr": d["stderr"], "ci95": d["ci95"]}
    doc["fitted_range"] = result.fitted_range
    doc["statistics"] = {"rmse": result.rmse, "rmse_units": result.units.get("rmse", ""),
                         "r2": result.r2, "n_points": result.n_points}
    doc["provenance"] = {
        "data": {"path": str(result.data["path"]), "sha256": result.data["sha256"]},
        "nylonflex_version": __version__,
        "created": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
    }
    if result.notes:
        doc["notes"] = list(result.notes)
    return _plain(doc)


def write_material_file(result, path, name=None, overwrite=False, fields=None,
                        inputs=()) -> Path:
    """Write a fit's material file (YAML); refuses to replace a file unless ``overwrite``.

    Written through a new temporary and a rename (:func:`nylonflex.files.atomic.replacing`):
    never through a link, onto a special file, or onto the fit's data file or one of
    ``inputs``.

    Raises
    ------
    InputError
        The file exists and ``overwrite`` is false, or it may not be written (see above).
    """
    from .atomic import refuse_special, write_atomic

    path = Path(path)
    inputs = (result.data.get("path", ""), *inputs)
    refuse_special(path, "--out", inputs)
    if os.path.lexists(path) and not overwrite:
        raise InputError(f"{path}: exists; give --overwrite to replace it")
    doc = material_document(result, name, fields)
    header = f"# nylonflex {doc['kind']} set fitted by 'nylonflex fit {result.kind}'\n"
    text = header + yaml.safe_dump(doc, sort_keys=False, width=100)
    return write_atomic(path, text.encode("utf-8"), "--out", inputs)


def read_material_file(path) -> dict:
    """Read a material file; InputError naming it when missing or malformed."""
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{path}: no such material file")
    doc = read_yaml(p)
    if not isinstance(doc, dict) or doc.get("kind") not in ("silicone", "nylon", "chamber"):
        raise InputError(f"{path}: not a nylonflex material file (needs 'kind: silicone', "
                         "'kind: nylon' or 'kind: chamber')")
    return doc


#: A chamber file's fitted values (``nylonflex fit chamber``), their SI units and ranges.
CHAMBER_FIELDS = {"stiffness": ("Pa", 0.0, 1e9), "rounding": ("1", -20.0, 1.5),
                  "air_heating": ("1", 0.0, 1.0), "squeeze": ("1", 0.0, 20.0)}


def read_chamber_file(path) -> dict:
    """A chamber file (``kind: chamber``, written by ``nylonflex fit chamber``) as its fitted
    values {name: SI float} (:data:`CHAMBER_FIELDS`), checked against the units it names,
    with the ``radius`` and ``wall_thickness`` [m] of the actuator it was measured on and
    its silicone's ``initial_shear_modulus`` [Pa].

    Raises
    ------
    InputError
        A missing or malformed file, another kind, a value missing, outside its range or
        with another unit than the file's ``units`` table says.
    """
    doc = read_material_file(path)
    if doc["kind"] != "chamber":
        raise InputError(f"chamber.file: {path} is a {doc['kind']} file, not chamber")
    units = doc.get("units") or {}
    out = {}
    for key, (unit, lo, hi) in CHAMBER_FIELDS.items():
        v = doc.get(key)
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not lo <= v <= hi:
            raise InputError(f"{path}: {key}: must be a number in [{lo:g}, {hi:g}] {unit}, "
                             f"got {v!r}")
        if units.get(key) != unit:
            raise InputError(f"{path}: {key}: the file's units must say {unit!r}, got "
                             f"{units.get(key)!r}")
        out[key] = float(v)
    design = doc.get("design") or {}
    for key, lo, hi, shown in (("radius", 1e-4, 1.0, "[0.1, 1000] mm (written in m)"),
                               ("wall_thickness", 1e-4, 1.0, "[0.1, 1000] mm (written in m)"),
                               ("initial_shear_modulus", 1e2, 1e8,
                                "[100 Pa, 100 MPa] (written in Pa)")):
        v = design.get(key) if isinstance(design, dict) else None
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not lo <= v <= hi:
            raise InputError(f"{path}: design.{key}: must be the measured actuator's, in "
                             f"{shown}, got {v!r}")
        out[key] = float(v)
    return out


def read_material_set(kind: str, path, table: dict, known=()) -> tuple[str, dict]:
    """A material file as ``(name, parameters)`` in the form of the named-set tables.

    Parameters
    ----------
    kind : str
        ``"silicone"`` or ``"nylon"``: what the config expects there.
    path : str or Path
        The material file.
    table : dict
        The named sets (:data:`~nylonflex.materials.NYLON_PARAMETERS` for a nylon ``base``).
    known : iterable of str
        The fields a nylon file may set (those of :class:`nylonflex.materials.Nylon`).

    Raises
    ------
    InputError
        A missing or malformed file, a file of the other kind, or a Yeoh fit (the model's
        silicone is Ogden only).
    """
    doc = read_material_file(path)
    if doc["kind"] != kind:
        raise InputError(f"{kind}.file: {path} is a {doc['kind']} file, not {kind}")
    prov = doc.get("provenance") or {}
    data = prov.get("data") or {}
    name = f"file:{doc.get('name') or Path(path).stem}"
    note = (f"K: nylonflex fit ({doc.get('model', '?')}) to {data.get('path', '?')} "
            f"(sha256 {data.get('sha256', '?')})")
    sources = {"file": str(path), "data_path": str(data.get("path", "")),
               "data_sha256": str(data.get("sha256", ""))}
    if kind == "silicone":
        model = doc.get("model")
        if model not in _OGDEN_FORMS:
            raise InputError(f"silicone.file: {path} holds a {model} fit; the actuator model "
                             "uses an Ogden silicone, so only ogden1, ogden2, ogden3 or "
                             "neo_hookean fits can be used (refit with --model ogden2)")
        if "mu" not in doc or "alpha" not in doc:
            raise InputError(f"silicone.file: {path} needs 'mu' [Pa] and 'alpha' [-]")
        params = {"mu": doc["mu"], "alpha": doc["alpha"]}
        sources.update({"mu": note, "alpha": note})
    else:
        base = doc.get("base", "silver_nylon66")
        if base not in table:
            raise InputError(f"nylon.file: {path}: base {base!r} is not a named set; "
                             f"accepted: {', '.join(sorted(table))}")
        params = dict(table[base])
        params["sources"] = dict(params.get("sources", {}))
        for key in set(known) & set(doc):
            # a thermal fit writes its derived constants with their intervals:
            # {value, stderr, ci95}; the set takes the value
            value = doc[key]
            params[key] = value["value"] if isinstance(value, dict) and "value" in value \
                else value
            sources[key] = note
        sources = {**params["sources"], **sources}
    rng = (doc.get("fitted_range") or {})
    if kind == "silicone" and isinstance(rng, dict) and rng.get("stretch"):
        params["stretch_range"] = tuple(float(x) for x in rng["stretch"])
        sources["stretch_range"] = note
    params["description"] = (f"fitted {doc.get('model', '')} from {data.get('path', '?')}"
                             + (f", range {rng}" if rng else ""))
    params["sources"] = sources
    return name, params


def anchor_material_files(raw, folder):
    """Make relative ``file`` paths of ``silicone``/``nylon``/``chamber`` mappings relative to
    ``folder``.

    Walks the config mapping (top level and nested actuators) and returns a copy.
    """
    folder = Path(folder)
    if isinstance(raw, list):
        return [anchor_material_files(v, folder) for v in raw]
    if not isinstance(raw, dict):
        return raw
    out = {}
    for key, value in raw.items():
        if key in ("silicone", "nylon", "chamber") and isinstance(value, dict) and \
                isinstance(value.get("file"), str) and not Path(value["file"]).is_absolute():
            value = {**value, "file": str(folder / value["file"])}
        elif isinstance(value, (dict, list)):
            value = anchor_material_files(value, folder)
        out[key] = value
    return out
