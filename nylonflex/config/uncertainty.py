"""The ``uncertainty:`` section of a sweep config: its schema and its resolution to SI
(docs/uncertainty.md)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from ..materials import FIELD_UNITS
from ..units import InputError, parse_quantity, to_si
from ..variables import AXES, VARIABLES
from .base import Number, _Strict, range_error

__all__ = ["Distribution", "UncertainParameter", "Uncertainty", "UncertaintySpec",
           "resolve_uncertainty"]


class Distribution(_Strict):
    """One uncertain parameter: ``sd`` (with ``units``) or ``rel_sd``, or ``from_fit``."""

    distribution: Literal["normal", "uniform"] = "normal"
    sd: Number | None = None
    rel_sd: float | None = None
    units: str | None = None
    from_fit: bool = False


class Uncertainty(_Strict):
    """The ``uncertainty:`` section (docs/uncertainty.md)."""

    samples: int = 256
    seed: int = 0
    quantiles: list[float] = [0.05, 0.5, 0.95]
    parameters: dict[str, Distribution] = {}


_MAX_SAMPLES = 65536

#: Lowest factor a sampled material field may scale its nominal value by [-]: a normal
#: tail reaching a negative modulus (``rel_sd``), or a fitted parameter crossing zero
#: (``from_fit``), is truncated here, keeping the field's sign.
MIN_FACTOR = 0.05
#: The largest share of draws [-] in which ``from_fit`` may truncate a fitted parameter at
#: :data:`MIN_FACTOR`: a fit whose standard deviation is a large part of a value does not
#: pin that value down, and propagating it would mostly measure the truncation. The ogden2
#: fit of the shipped Ecoflex 00-50 test to stretch 4 has mu_2 = 9.1 +- 17.9 Pa: a third of
#: its draws flip the term's sign (mu_i alpha_i < 0, a silicone softening without bound),
#: and before this rule the sampled bend angles reached 1e121 rad.
MAX_TRUNCATED = 0.01
#: Aliases of material table fields in ``uncertainty.parameters``.
_FIELD_ALIASES = {"stroke_max": "stroke_max_table", "tensile_strength": "tensile_strength_table",
                  "coil_index": "coil_index_table"}


@dataclass(frozen=True)
class UncertainParameter:
    """One uncertain input, resolved: what it perturbs and by how much (SI).

    ``target`` is an axis name (``wall_thickness``) or ``silicone.mu`` /
    ``nylon.stroke_max_table`` (a material field; a table or the Ogden terms move together
    by one standard variable). With ``from_fit``, ``target`` is ``silicone`` or ``nylon``,
    ``fields`` names each dimension (``mu_1``) and ``covariance`` is theirs, SI.
    """

    name: str
    target: str
    distribution: str
    sd: float | None = None
    rel_sd: float | None = None
    fields: tuple[str, ...] = ()
    covariance: tuple[tuple[float, ...], ...] = ()

    @property
    def dims(self) -> int:
        """Standard variables this parameter takes (1, or the fit's parameter count)."""
        return len(self.fields) if self.fields else 1

    def to_dict(self) -> dict:
        d = {"target": self.target, "distribution": self.distribution}
        if self.sd is not None:
            d["sd"] = float(self.sd)
        if self.rel_sd is not None:
            d["rel_sd"] = float(self.rel_sd)
        if self.fields:
            d.update(fields=list(self.fields),
                     covariance=[[float(x) for x in row] for row in self.covariance])
        return d


@dataclass(frozen=True)
class UncertaintySpec:
    """The resolved ``uncertainty:`` section: scrambled Sobol' samples of the parameters."""

    samples: int
    seed: int
    quantiles: tuple[float, ...]
    parameters: tuple[UncertainParameter, ...]

    def to_dict(self) -> dict:
        return {"samples": self.samples, "seed": self.seed,
                "quantiles": [float(q) for q in self.quantiles],
                "parameters": {p.name: p.to_dict() for p in self.parameters}}


def _material_numeric(kind, material) -> dict:
    return {k: v for k, v in material.to_dict().items()
            if k != "name" and isinstance(v, (int, float, list, tuple))}


def _fitted_field(p, numeric):
    """A fit's parameter name as a field of the material's numbers ``numeric``: ``mu_2``
    -> ("mu", the second term's value), a scalar field ``t_g`` -> ("t_g", its value), or
    None where it names no field."""
    field_name, _, idx = str(p).rpartition("_")
    if field_name in numeric and idx.isdigit() and isinstance(numeric[field_name], list) \
            and 1 <= int(idx) <= len(numeric[field_name]):
        return field_name, numeric[field_name][int(idx) - 1]
    if p in numeric and not isinstance(numeric[p], list):
        return str(p), numeric[p]
    return None


def _fit_parameter(name, dist, path, raw_material, material):
    from ..files.material_files import read_material_file

    if not (isinstance(raw_material, dict) and isinstance(raw_material.get("file"), str)):
        raise InputError(f"{path}.from_fit: {name} must come from a fitted material file "
                         f"({name}: {{file: fits/....yaml}})")
    doc = read_material_file(raw_material["file"])
    order, cov = doc.get("parameter_order"), doc.get("covariance")
    try:
        cov = np.asarray(cov, dtype=float)
    except (TypeError, ValueError):
        cov = None
    if not isinstance(order, list) or cov is None or cov.shape != (len(order), len(order)):
        raise InputError(f"{path}.from_fit: {raw_material['file']} has no 'covariance' of "
                         "its 'parameter_order'")
    numeric = _material_numeric(name, material)
    fields = [_fitted_field(p, numeric) for p in order]
    for p, found in zip(order, fields):
        if found is None:
            raise InputError(f"{path}.from_fit: the fitted parameter {p!r} of "
                             f"{raw_material['file']} is not a field of the {name} set")
    if not np.allclose(cov, cov.T) or np.any(np.linalg.eigvalsh(cov) < -1e-12 *
                                             np.abs(cov).max()):
        raise InputError(f"{path}.from_fit: the covariance of {raw_material['file']} is not "
                         "symmetric positive semi-definite")
    if dist.distribution != "normal" or dist.sd is not None or dist.rel_sd is not None:
        raise InputError(f"{path}: from_fit takes the fit's multivariate normal; give no "
                         "sd, rel_sd or distribution")
    for p, (field_name, value), sd in zip(order, fields,
                                          np.sqrt(np.maximum(np.diag(cov), 0.0))):
        unit = FIELD_UNITS.get(field_name, "1")
        unit = "" if unit == "1" else f" {unit}"
        # the share of normal draws below MIN_FACTOR times the value (truncated there)
        share = 0.5 * math.erfc((1.0 - MIN_FACTOR) * abs(value) / (sd * math.sqrt(2.0))) \
            if sd > 0 else 0.0
        if not share <= MAX_TRUNCATED:
            raise InputError(
                f"{path}.from_fit: {raw_material['file']} fits {p} = {value:.4g}{unit} with "
                f"a standard deviation of {sd:.3g}{unit}: {100 * share:.0f} % of normal "
                f"draws would cross zero or nearly (at most {100 * MAX_TRUNCATED:g} % "
                f"accepted): the fit does not pin it down; give "
                f"{name}.{field_name} a rel_sd (a batch's spread) instead, "
                "or fit with fewer terms or to a test that determines it")
    return UncertainParameter(name, name, "normal", fields=tuple(str(p) for p in order),
                              covariance=tuple(tuple(float(x) for x in row) for row in cov))


def resolve_uncertainty(unc: Uncertainty, silicone, nylon, raw) -> UncertaintySpec:
    """Resolve the ``uncertainty:`` section; InputError naming the field otherwise."""
    if not 2 <= unc.samples <= _MAX_SAMPLES:
        raise range_error("uncertainty.samples", 2, _MAX_SAMPLES, "1", unc.samples)
    if not 0 <= unc.seed < 2**32:
        raise range_error("uncertainty.seed", 0, 2**32 - 1, "1", unc.seed)
    if not unc.quantiles or any(not 0 < q < 1 for q in unc.quantiles) or \
            np.any(np.diff(unc.quantiles) <= 0):
        raise InputError(f"uncertainty.quantiles: must be increasing probabilities in (0, 1), "
                         f"got {unc.quantiles}")
    params = []
    # sorted by name: the Sobol' column of each parameter, like the config hash (sorted
    # YAML), must not depend on the order the keys were written in
    for name, dist in sorted(unc.parameters.items()):
        path = f"uncertainty.parameters.{name}"
        kind, _, fld = name.partition(".")
        if dist.from_fit:
            if fld or kind not in ("silicone", "nylon"):
                raise InputError(f"{path}.from_fit: only 'silicone' or 'nylon' take a fit's "
                                 "covariance")
            params.append(_fit_parameter(kind, dist, path, raw.get(kind),
                                         silicone if kind == "silicone" else nylon))
            continue
        if (dist.sd is None) == (dist.rel_sd is None):
            raise InputError(f"{path}: give one of sd (with units) or rel_sd")
        if dist.rel_sd is not None and not 0 < dist.rel_sd <= 1:
            raise range_error(f"{path}.rel_sd", 0, 1, "1", dist.rel_sd, lo_open=True)
        if name in AXES:
            target = name
            v = VARIABLES[name]
            sd = None if dist.sd is None else float(parse_quantity(
                dist.sd, f"{path}.sd", v.kind, dist.units or v.display))
        elif kind in ("silicone", "nylon") and fld:
            fld = _FIELD_ALIASES.get(fld, fld) if kind == "nylon" else fld
            numeric = _material_numeric(kind, silicone if kind == "silicone" else nylon)
            if fld not in numeric:
                raise InputError(f"{path}: unknown {kind} field; accepted: "
                                 f"{', '.join(sorted(numeric))}")
            target = f"{kind}.{fld}"
            if dist.units is not None and dist.sd is None:
                raise InputError(f"{path}.units: only with sd")
            sd = None if dist.sd is None else float(parse_quantity(
                dist.sd, f"{path}.sd", "dimensionless", "1") if dist.units is None else
                to_si(float(dist.sd), dist.units, f"{path}.units"))
        else:
            raise InputError(f"{path}: unknown parameter; accepted: {', '.join(AXES)}, "
                             "silicone.FIELD, nylon.FIELD, or silicone/nylon with from_fit")
        if sd is not None and not (math.isfinite(sd) and sd > 0):
            raise InputError(f"{path}.sd: must be > 0, got {dist.sd!r}")
        params.append(UncertainParameter(name, target, dist.distribution, sd=sd,
                                         rel_sd=dist.rel_sd))
    targets = [p.target for p in params]
    for p in params:
        if p.fields and any(t.startswith(p.target + ".") for t in targets):
            raise InputError(f"uncertainty.parameters.{p.name}: from_fit and a field of "
                             f"{p.target} at once; keep one")
    if len(set(targets)) != len(targets):
        raise InputError("uncertainty.parameters: a parameter is given twice")
    return UncertaintySpec(unc.samples, unc.seed, tuple(float(q) for q in unc.quantiles),
                           tuple(params))


