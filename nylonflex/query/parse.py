"""Parsing of ``nylonflex query``'s ``--at``, ``--where`` and ``--sort`` (SI inside)."""

from __future__ import annotations

import re

import numpy as np

from ..units import InputError, parse_quantity
from ..variables import AXES, DESIGN, TRACKING, VARIABLES

#: Columns of every row: the five axes, then the design variables (registry order).
COLUMNS = (*AXES, *DESIGN)
#: Columns a cube has only when its sweep asked for them (``requirements``, ``tracking:``).
OPTIONAL = ("feasibility", *TRACKING)
_FIELDS = ", ".join(COLUMNS + OPTIONAL)
#: What a table shows after the axes and the variables a query tests or sorts by (the
#: limit, the two headline performance numbers and the validity flags, by name).
HEADLINE = ("limit", "tip_force_max", "bend_angle_max", "validity")
#: How an ``--at`` design was found: on the grid, by the exact model, interpolated.
GRID, EXACT, INTERPOLATED = "grid point", "exact model", "interpolated"
_LIMIT_WORDS = {"stroke": 0, "stroke_limited": 0, "strength": 1, "strength_limited": 1,
                "supply": 2, "supply_limited": 2, "load": 3, "load_limited": 3}


#: ``--where "model == NAME"``: picks a model's slice of a cube (not a Condition).
_MODEL_WHERE = re.compile(r"^\s*model\s*(==|=)\s*([A-Za-z0-9_]+)\s*$")


def _quantity(name, text, field):
    v = VARIABLES[name]
    if name == "limit" and str(text).strip().lower() in _LIMIT_WORDS:
        return float(_LIMIT_WORDS[str(text).strip().lower()])
    return parse_quantity(text, field, v.kind, v.display)


def parse_at(text) -> dict:
    """Parse ``"radius=7.5mm,wall_thickness=2mm"`` into ``{axis: SI value}``.

    Bare numbers are in the axis's display unit (mm, deg; none for ``coil_index``). A list
    of such texts (``--at`` given several times) is merged into one design.

    Raises
    ------
    InputError
        Not ``NAME=VALUE``, an unknown axis, an axis given twice (in one text or across
        several) or a bad value.
    """
    texts = [text] if isinstance(text, str) else list(text or ())
    repeated = len(texts) > 1
    out = {}
    for part in [p for t in texts for p in str(t).split(",") if p.strip()]:
        if "=" not in part:
            raise InputError(f"--at: expected NAME=VALUE, got {part.strip()!r}; names: "
                             f"{', '.join(AXES)}")
        name, value = (s.strip() for s in part.split("=", 1))
        if name not in AXES:
            raise InputError(f"--at: unknown axis {name!r}; accepted: {', '.join(AXES)}")
        if name in out:
            where = " (across repeated --at options, which are merged into one design)" \
                if repeated else ""
            raise InputError(f"--at: {name} given twice{where}; --at picks one design: "
                             f"give each axis once, or use --where for a range, e.g. "
                             f"--where \"{name} >= ...\"")
        out[name] = float(_quantity(name, value, f"--at {name}"))
    if not out:
        raise InputError(f"--at: expected NAME=VALUE,...; names: {', '.join(AXES)}")
    return out


class Condition:
    """One ``--where`` condition: ``name op value`` with ``value`` in SI."""

    _OPS = {"<=": np.less_equal, ">=": np.greater_equal, "<": np.less, ">": np.greater,
            "==": None, "=": None, "!=": None}
    _PATTERN = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*(<=|>=|==|!=|<|>|=)\s*(.+?)\s*$")

    def __init__(self, text: str):
        if str(text).strip() == "valid":  # issue 10: clean designs, validity == 0
            text = "validity == 0"
        m = self._PATTERN.match(str(text))
        if not m:
            raise InputError(f"--where: expected 'NAME OP VALUE [UNIT]' with OP one of "
                             f"<, <=, ==, !=, >=, >, got {text!r}")
        self.name, op, value = m.groups()
        if self.name not in COLUMNS + OPTIONAL:
            raise InputError(f"--where: unknown name {self.name!r}; accepted: {_FIELDS}")
        self.op = "==" if op == "=" else op
        self.value = float(_quantity(self.name, value, f"--where {self.name}"))
        self.text = str(text).strip()

    def mask(self, x: np.ndarray) -> np.ndarray:
        """True where ``x`` [SI] meets the condition (NaN never does)."""
        if self.op in ("==", "!="):
            # equality to a typed value up to its float noise (7.5 mm, 8 deg, 1)
            near = np.isclose(x, self.value, rtol=1e-9, atol=1e-12 * max(1.0, abs(self.value)))
            return near if self.op == "==" else ~near & ~np.isnan(x)
        return self._OPS[self.op](x, self.value)

    def __repr__(self):
        return f"Condition({self.text!r})"


def parse_where(texts) -> list[Condition]:
    """Parse ``--where`` strings (ANDed) into :class:`Condition` objects.

    ``model == NAME`` stays a string: :func:`query_cube` selects that model's slice.
    """
    return [t if _MODEL_WHERE.match(str(t)) else Condition(t) for t in texts or ()]


def _parse_sort(text):
    if not text:
        return None, False
    name = text.strip()
    descending = name.startswith("-")
    name = name.lstrip("-+").strip()
    # "NAME:desc" too: argparse reads "--sort -NAME" as an option (write --sort=-NAME)
    if ":" in name:
        name, order = (s.strip() for s in name.split(":", 1))
        if order not in ("asc", "desc"):
            raise InputError(f"--sort: order must be 'asc' or 'desc', got {order!r}")
        descending = order == "desc"
    if name not in COLUMNS + OPTIONAL:
        raise InputError(f"--sort: unknown name {name!r}; accepted: {_FIELDS} "
                         "(prefix '-' for descending)")
    return name, descending


def parse_columns(text):
    """Parse ``--columns "radius,tip_force_max"`` into a tuple of names (``"all"``: every
    column, returned as the string ``"all"``; None: the format's default).

    Raises
    ------
    InputError
        An unknown name, a name given twice, or nothing named.
    """
    if text is None:
        return None
    texts = [text] if isinstance(text, str) else list(text)
    names = [p.strip() for t in texts for p in str(t).split(",") if p.strip()]
    if names == ["all"]:
        return "all"
    if not names:
        raise InputError(f"--columns: expected NAME,... or 'all'; names: {_FIELDS}")
    for name in names:
        if name not in COLUMNS + OPTIONAL:
            raise InputError(f"--columns: unknown name {name!r}; accepted: {_FIELDS}, or all")
    if len(set(names)) != len(names):
        twice = next(n for n in names if names.count(n) > 1)
        raise InputError(f"--columns: {twice} given twice; name each column once")
    return tuple(names)


def default_columns(available, asked=()) -> tuple:
    """A table's columns: the axes, the ``asked`` names (tested by ``--where`` or sorted
    by), then :data:`HEADLINE`; only the ``available`` ones, each once, ``model`` first."""
    out = []
    for name in ("model", *AXES, *asked, *HEADLINE):
        if name in available and name not in out:
            out.append(name)
    return tuple(out)
