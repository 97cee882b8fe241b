"""Design requirements in the query syntax: ``"tip_force_max >= 0.5 N"``.

A sweep config's ``requirements:`` list is parsed here, at the bottom layer, so that the
config refuses a bad requirement before any work and the engine can evaluate requirements on
sampled designs (the feasibility of docs/uncertainty.md). The syntax is ``nylonflex query
--where``'s: ``NAME OP VALUE [UNIT]``, OP one of <, <=, >, >=, a bare number in the name's
display unit (N, kPa, deg, ...).
"""

from __future__ import annotations

import re

import numpy as np

from .units import InputError, parse_quantity
from .variables import DESIGN, VARIABLES

__all__ = ["Requirement", "parse_requirements"]

_OPS = {"<=": np.less_equal, ">=": np.greater_equal, "<": np.less, ">": np.greater}
_PATTERN = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*(<=|>=|<|>)\s*(.+?)\s*$")
#: Names a requirement may constrain: the float design variables.
NAMES = tuple(n for n, v in DESIGN.items() if v.dtype != "int8")


class Requirement:
    """One requirement ``name op value`` on a design variable, ``value`` in SI.

    Parameters
    ----------
    text : str
        ``"tip_force_max >= 0.5 N"``; a bare number is in the name's display unit.
    field : str
        Where it came from, for messages (``requirements[0]``).

    Raises
    ------
    InputError
        Not ``NAME OP VALUE [UNIT]``, an unknown name, or a value of the wrong unit.
    """

    def __init__(self, text: str, field: str = "requirement"):
        m = _PATTERN.match(str(text))
        if not m:
            raise InputError(f"{field}: expected 'NAME OP VALUE [UNIT]' with OP one of "
                             f"<, <=, >=, >, got {text!r}")
        self.name, self.op, value = m.groups()
        if self.name not in NAMES:
            raise InputError(f"{field}: unknown name {self.name!r}; accepted: "
                             f"{', '.join(NAMES)}")
        v = VARIABLES[self.name]
        self.value = float(parse_quantity(value, field, v.kind, v.display))
        if not np.isfinite(self.value):
            raise InputError(f"{field}: the value must be finite, got {value!r}")
        self.text = str(text).strip()

    def holds(self, x) -> np.ndarray:
        """True where ``x`` [SI] meets the requirement (NaN never does)."""
        return _OPS[self.op](np.asarray(x), self.value)

    def __repr__(self):
        return f"Requirement({self.text!r})"


def parse_requirements(texts, field: str = "requirements") -> tuple[Requirement, ...]:
    """Parse a list of requirement strings (all must hold) into :class:`Requirement` objects.

    Raises
    ------
    InputError
        Not a list of strings, or a bad requirement (named by its index).
    """
    if texts is None:
        return ()
    if isinstance(texts, str) or not isinstance(texts, (list, tuple)):
        raise InputError(f"{field}: must be a list of strings like 'tip_force_max >= 0.5 N'")
    return tuple(Requirement(t, f"{field}[{i}]") for i, t in enumerate(texts))
