"""Parsing of ``nylonflex query``'s ``--at``, ``--where`` and ``--sort`` (SI inside)."""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from .units import InputError, parse_quantity
from .variables import AXES, DESIGN, SPREAD, TRACKING, VARIABLES

#: Columns of every row: the five axes, then the design variables (registry order).
COLUMNS = (*AXES, *DESIGN)
#: Columns a cube has only when its sweep asked for them (``requirements``, ``tracking:``,
#: ``fidelity: spread``).
OPTIONAL = ("feasibility", *TRACKING, *SPREAD)
_FIELDS = ", ".join(COLUMNS + OPTIONAL)
#: What a table shows after the axes and the variables a query tests or sorts by (the
#: limit, the two headline performance numbers and the validity flags, by name).
HEADLINE = ("limit", "tip_force_max", "bend_angle_max", "validity")
#: How an ``--at`` design was found: on the grid, by the exact model, interpolated.
GRID, EXACT, INTERPOLATED = "grid point", "exact model", "interpolated"
_LIMIT_WORDS = {"stroke": 0, "stroke_limited": 0, "strength": 1, "strength_limited": 1,
                "supply": 2, "supply_limited": 2, "load": 3, "load_limited": 3}


#: ``--where "model == NAME"`` or ``"cooling == NAME"``: picks a model's (a cooling set's)
#: slice of a cube (not a Condition); a cooling set's name may carry its speed
#: (``forced_air 5 m/s``).
CATEGORY_WHERE = re.compile(r"^\s*(model|cooling)\s*(==|=)\s*([A-Za-z0-9_][A-Za-z0-9_ ./]*?)\s*$")


def missing_hint(name: str) -> str:
    """What sweep gives a cube the optional column ``name`` (for a refusal naming it)."""
    if name in TRACKING:
        return "sweep a config with 'tracking:' (docs/model.md s. 19)"
    if name in SPREAD:
        return "sweep a config with 'fidelity: spread' (docs/model.md s. 23)"
    return "sweep a config with 'requirements' (docs/uncertainty.md)"


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


#: Every comparison the grammar knows, and the inequalities alone (``requirements:``).
OPS = ("<", "<=", "==", "!=", ">=", ">")
INEQUALITIES = ("<", "<=", ">=", ">")
_COMPARE = {"<=": np.less_equal, ">=": np.greater_equal, "<": np.less, ">": np.greater}
CONDITION_PATTERN = re.compile(
    r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*(<=|>=|==|!=|<|>|=)\s*(.+?)\s*$")
#: Names a ``requirements:`` entry may constrain: the float design variables.
REQUIREMENT_NAMES = tuple(n for n, v in DESIGN.items() if v.dtype != "int8")


@dataclass(frozen=True)
class Condition:
    """One condition ``name op value`` of the query grammar, ``value`` in SI.

    The one grammar of ``--where``, a sweep's ``requirements:`` and a design's
    ``constraints:``; build one from text with :func:`parse_condition`.

    Attributes
    ----------
    name : str
        An axis or design variable (registry name).
    op : str
        One of :data:`OPS`.
    value : float
        The bound, in the variable's SI unit (attrs["units"] of its cube variable).
    text : str
        The condition as typed (for messages and provenance); not compared.
    """

    name: str
    op: str
    value: float
    text: str = field(default="", compare=False)

    def mask(self, x) -> np.ndarray:
        """True where ``x`` [SI] meets the condition (NaN never does)."""
        x = np.asarray(x)
        if self.op in ("==", "!="):
            # equality to a typed value up to its float noise (7.5 mm, 8 deg, 1)
            near = np.isclose(x, self.value, rtol=1e-9, atol=1e-12 * max(1.0, abs(self.value)))
            return near if self.op == "==" else ~near & ~np.isnan(x)
        return _COMPARE[self.op](x, self.value)


    def __repr__(self):
        return f"Condition({self.text or f'{self.name} {self.op} {self.value!r}'!r})"


def parse_condition(text, field: str = "--where", names=None, ops=OPS,
                    finite: bool = False) -> Condition:
    """Parse ``"tip_force_max >= 0.5 N"`` into a :class:`Condition` (``value`` in SI).

    A bare number is in the name's display unit (N, kPa, mm, deg, ...); ``limit`` also takes
    its flag words (``stroke``, ``supply``, ...); the text ``valid`` means ``validity == 0``.

    Parameters
    ----------
    text : str
        The condition as typed.
    field : str
        Where it came from, named in every message (``--where``, ``requirements[0]``,
        ``constraints[2]``).
    names : sequence of str, optional
        The names accepted (default: every query column, :data:`COLUMNS` and
        :data:`OPTIONAL`).
    ops : sequence of str
        The comparisons accepted (default: all of :data:`OPS`; ``=`` is read as ``==``).
    finite : bool
        Refuse an infinite or NaN value.

    Raises
    ------
    InputError
        Not ``NAME OP VALUE [UNIT]``, an operator or name not accepted, or a bad value.
    """
    names = tuple(COLUMNS + OPTIONAL if names is None else names)
    if str(text).strip() == "valid" and "validity" in names:  # issue 10: validity == 0
        text = "validity == 0"
    m = CONDITION_PATTERN.match(str(text))
    op = None if not m else "==" if m.group(2) == "=" else m.group(2)
    if op not in ops:
        raise InputError(f"{field}: expected 'NAME OP VALUE [UNIT]' with OP one of "
                         f"{', '.join(ops)}, got {text!r}")
    name, _, value = m.groups()
    if name not in names:
        accepted = _FIELDS if names == COLUMNS + OPTIONAL else ", ".join(names)
        raise InputError(f"{field}: unknown name {name!r}; accepted: {accepted}")
    number = float(_quantity(name, value, f"{field} {name}"))
    if finite and not np.isfinite(number):
        raise InputError(f"{field}: the value must be finite, got {value!r}")
    return Condition(name, op, number, str(text).strip())


def parse_where(texts) -> list[Condition]:
    """Parse ``--where`` strings (ANDed) into :class:`Condition` objects.

    ``model == NAME`` and ``cooling == NAME`` stay strings: :func:`query_cube` selects that
    model's (cooling set's) slice.
    """
    return [t if CATEGORY_WHERE.match(str(t)) else parse_condition(t) for t in texts or ()]


def parse_requirements(texts, field: str = "requirements") -> tuple[Condition, ...]:
    """Parse a sweep's ``requirements:`` (all must hold) into :class:`Condition` objects:
    inequalities on the float design variables, finite values.

    Raises
    ------
    InputError
        Not a list of strings, or a bad requirement (named by its index).
    """
    if texts is None:
        return ()
    if isinstance(texts, str) or not isinstance(texts, (list, tuple)):
        raise InputError(f"{field}: must be a list of strings like 'tip_force_max >= 0.5 N'")
    return tuple(parse_condition(t, f"{field}[{i}]", REQUIREMENT_NAMES, INEQUALITIES,
                                 finite=True) for i, t in enumerate(texts))


def parse_constraint(text, i: int) -> Condition:
    """Parse a design's ``constraints[i]``: any query column, any comparison.

    Raises
    ------
    InputError
        Not a string, or a bad condition (named ``constraints[i]``).
    """
    if not isinstance(text, str):
        raise InputError(f"constraints[{i}]: expected a string like \"radius <= 20 mm\", "
                         f"got {text!r}")
    return parse_condition(text, f"constraints[{i}]")


def parse_sort(text):
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
    by), then :data:`HEADLINE` (each with its range over a model spread, where the cube has
    one); only the ``available`` ones, each once, ``model`` and ``cooling`` first."""
    out = []
    # a headline value's range over a model spread follows it (docs/model.md s. 23)
    headline = [m for n in HEADLINE for m in (n, f"{n}_model_lo", f"{n}_model_hi")] + \
        ["validity_model_any"]
    for name in ("model", "cooling", *AXES, *asked, *headline):
        if name in available and name not in out:
            out.append(name)
    return tuple(out)
