"""JSON Schema of the YAML configs, generated from their pydantic models.

An editor's YAML language server (``# yaml-language-server: $schema=sweep.schema.json`` on a
config's first line) then completes keys and flags unknown ones while the config is typed;
nylonflex itself still validates every config (units, ranges) before any work.
"""

from __future__ import annotations

from typing import Any, Literal, Union

from .base import _Strict
from .simulate import SimConfigModel
from .sweep import FixedThickness, Grid, SweepConfig

__all__ = ["SCHEMAS", "json_schema"]


class _Objective(_Strict):
    """``{max: NAME}`` or ``{min: NAME}``: a design variable or axis to optimise."""

    max: str | None = None
    min: str | None = None


class _Refine(_Strict):
    starts: int | None = None
    maxiter: int | None = None


class DesignSpecModel(_Strict):
    """A design spec (``nylonflex design SPEC.yaml``; nylonflex.design.spec), as typed.

    The spec's own validation is :func:`nylonflex.design.spec.parse_spec`; this model only
    describes its keys for editors (one of ``cube`` or ``grid``).
    """

    name: str | None = None
    cube: str | None = None
    grid: Grid | None = None
    silicone: Union[str, dict[str, Any]] | None = None
    nylon: Union[str, dict[str, Any]] | None = None
    base_thickness: Union[Literal["wall"], FixedThickness] | None = None
    model: str | None = None
    objectives: Union[list[Union[_Objective, str]], _Objective, str]
    constraints: Union[list[str], str] = []
    refine: Union[bool, _Refine] = True
    #: per axis, the step a design is built to: a number (the axis's display unit) or
    #: "0.5 mm" (nylonflex.design.resolution)
    resolution: dict[Literal["radius", "wall_thickness", "length", "coil_index",
                             "wrap_angle"], Union[float, str]] | None = None


def _models() -> dict:
    return {"sweep": SweepConfig, "simulate": SimConfigModel, "design": DesignSpecModel}


#: The configs with a schema: ``nylonflex schema NAME``.
SCHEMAS = ("sweep", "simulate", "design")

_TITLES = {"sweep": "nylonflex sweep config", "simulate": "nylonflex simulate config",
           "design": "nylonflex design spec"}


def json_schema(kind: str) -> dict:
    """The JSON Schema (draft 2020-12) of a config ``kind`` (one of :data:`SCHEMAS`).

    Raises
    ------
    ValueError
        An unknown ``kind``.
    """
    if kind not in SCHEMAS:
        raise ValueError(f"schema: must be one of {', '.join(SCHEMAS)}, got {kind!r}")
    schema = _models()[kind].model_json_schema(mode="validation")
    return {"$schema": "https://json-schema.org/draft/2020-12/schema",
            "title": _TITLES[kind], **{k: v for k, v in schema.items() if k != "title"}}
