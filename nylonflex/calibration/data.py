"""Reading bench data: the Soft Robotics Materials Database files and plain CSV.

Two layouts are read as they are:

- the database's files (Marechal et al., Soft Robotics 8(3), 2021): a block of
  ``PARAMETER;INFO`` lines, then a ``;``-separated table headed
  ``Time (s);True Strain;True Stress (MPa);Engineering Strain;Engineering Stress (MPa)``;
- plain CSV (``,``, ``;`` or tab) whose first line names the columns with their units in
  brackets or parentheses: ``stretch,stress [kPa]``, ``strain,stress (MPa)``,
  ``time [s],temperature [degC]``.

Every column is converted to SI once, here. A column name is snake_case of the header
without its unit (``Engineering Stress (MPa)`` -> ``engineering_stress``).

A file is bounded before it is parsed (:data:`MAX_BYTES`, :data:`MAX_ROWS`,
:data:`MAX_COLUMNS`, :data:`MAX_CELL`; docs/calibration.md): a bench recording is far
smaller, and a 20,000-column header took 47 s to refuse.
"""

from __future__ import annotations

import csv
import hashlib
import io
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..units import InputError, UNITS, to_si, unit_kind

__all__ = ["MAX_BYTES", "MAX_CELL", "MAX_COLUMNS", "MAX_ROWS", "Table", "file_sha256",
           "read_table"]

#: The largest data file read [bytes].
MAX_BYTES = 200_000_000
#: The most lines (header and rows) of a data file [-].
MAX_ROWS = 2_000_000
#: The most columns of a data file's header [-].
MAX_COLUMNS = 1_000
#: The longest cell [characters] (a header name or a number; the ``csv`` module's limit).
MAX_CELL = 10_000

_HEADER = re.compile(r"^\s*(?P<name>[^\[\(]*?)\s*(?:[\[\(]\s*(?P<unit>[^\]\)]*?)\s*[\]\)])?\s*$")


@dataclass(frozen=True)
class Table:
    """Columns of a data file in SI, with where they came from.

    Attributes
    ----------
    path : str
        The file as given.
    sha256 : str
        SHA-256 of the file's bytes.
    columns : dict of str to ndarray
        Column name -> values in SI (rows with a blank or non-numeric cell are dropped).
    units : dict of str to str
        Column name -> the unit the file gave ("" when none).
    metadata : dict of str to str
        The header block of a database file (``Specimen Thickness (mm)`` -> ``"3"``).
    """

    path: str
    sha256: str
    columns: dict
    units: dict
    metadata: dict = field(default_factory=dict)

    def __len__(self) -> int:
        return len(next(iter(self.columns.values()))) if self.columns else 0

    def has(self, *names) -> bool:
        """Whether every name is a column."""
        return all(n in self.columns for n in names)


def file_sha256(path) -> str:
    """SHA-256 of a file's bytes (hex)."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def _snake(name: str) -> str:
    return re.sub(r"[^0-9a-z]+", "_", name.strip().lower()).strip("_")


def _factor(unit: str, column: str, path) -> tuple[float, float]:
    """(factor, offset) to SI of a unit, compound units ``mm/s`` included."""
    parts = unit.split("/")
    try:
        if len(parts) == 2:
            return to_si(1.0, parts[0], column) / to_si(1.0, parts[1], column), 0.0
        if unit_kind(unit) == "temperature":
            return to_si(1.0, unit, column) - to_si(0.0, unit, column), to_si(0.0, unit, column)
        return to_si(1.0, unit, column), 0.0
    except InputError:
        raise InputError(f"{path}: column {column!r}: unknown unit {unit!r}; accepted: "
                         f"{', '.join(u for u in UNITS if u != '1')} (or A/B, e.g. mm/s)"
                         ) from None


def _number(text: str):
    try:
        return float(text)
    except ValueError:
        return None


def read_table(path) -> Table:
    """Read a database file or a plain CSV with units in its header, to SI.

    Parameters
    ----------
    path : str or Path
        The data file.

    Returns
    -------
    Table

    Raises
    ------
    InputError
        A missing or unreadable file, no header, an unknown unit, or no usable rows; the
        message names the file.
    """
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{path}: no such data file")
    size = p.stat().st_size
    if size > MAX_BYTES:
        raise InputError(f"{path}: {size:,} bytes, over the {MAX_BYTES:,} a data file may "
                         "hold; thin it (every n-th row) or fit a part of it")
    try:
        text = p.read_text(encoding="utf-8-sig")
    except (UnicodeDecodeError, OSError):
        raise InputError(f"{path}: not a text (CSV) file") from None
    lines = text.splitlines()
    if not lines:
        raise InputError(f"{path}: empty file")
    if len(lines) > MAX_ROWS:
        raise InputError(f"{path}: {len(lines):,} lines, over the {MAX_ROWS:,} a data file "
                         "may hold; thin it (every n-th row) or fit a part of it")
    delim = ";" if lines[0].count(";") > lines[0].count(",") else (
        "\t" if "\t" in lines[0] and "," not in lines[0] else ",")
    rows = _rows(path, text, delim)
    metadata = {}
    start = 0
    if rows and rows[0] and rows[0][0].strip().upper() == "PARAMETER":  # database header
        for i, row in enumerate(rows[1:-1], 1):
            cells = [c.strip() for c in row]
            nxt = rows[i + 1]
            if cells and cells[0] and nxt and _number(nxt[0].strip()) is not None:
                start = i
                break
            if cells and cells[0]:
                metadata[cells[0]] = cells[1] if len(cells) > 1 else ""
        else:
            raise InputError(f"{path}: no table header after the PARAMETER block")
    header = [c for c in rows[start]]
    while header and not header[-1].strip():
        header.pop()
    if len(header) > MAX_COLUMNS:
        raise InputError(f"{path}: {len(header):,} columns in the header, over the "
                         f"{MAX_COLUMNS:,} a data file may have")
    if not header or all(_number(c) is not None for c in header if c.strip()):
        raise InputError(f"{path}: the first line must name the columns, with units, e.g. "
                         "'stretch,stress [kPa]'")
    names, units, factors, seen = [], [], [], set()
    for cell in header:
        m = _HEADER.match(cell)
        name, unit = _snake(m.group("name")), (m.group("unit") or "").strip()
        if not name:
            raise InputError(f"{path}: a column has no name in the header line")
        if name in seen:
            raise InputError(f"{path}: column {name[:80]!r} appears twice")
        seen.add(name)
        names.append(name)
        units.append(unit)
        factors.append(_factor(unit, cell.strip(), path) if unit else (1.0, 0.0))
    values = []
    for row in rows[start + 1:]:
        cells = [c.strip() for c in row[:len(names)]]
        if len(cells) < len(names):
            continue
        nums = [_number(c) for c in cells]
        if any(v is None for v in nums) or not all(np.isfinite(nums)):
            continue
        values.append(nums)
    if not values:
        raise InputError(f"{path}: no usable rows (numbers under the header "
                         f"{', '.join(h.strip() for h in header)})")
    arr = np.asarray(values, dtype=float)
    cols = {n: arr[:, i] * f + o for i, (n, (f, o)) in enumerate(zip(names, factors))}
    return Table(path=str(path), sha256=file_sha256(p), columns=cols,
                 units=dict(zip(names, units)), metadata=metadata)


def _rows(path, text: str, delim: str) -> list:
    """The cells of every line; a cell over :data:`MAX_CELL` characters is refused with
    the file and line named (the ``csv`` module said only "field larger than field
    limit")."""
    reader = csv.reader(io.StringIO(text), delimiter=delim)
    limit = csv.field_size_limit()
    try:
        csv.field_size_limit(MAX_CELL)
        return list(reader)
    except csv.Error as exc:
        if "field limit" not in str(exc):
            raise InputError(f"{path}: line {reader.line_num}: not CSV ({exc})") from None
        raise InputError(f"{path}: line {reader.line_num}: a cell longer than "
                         f"{MAX_CELL:,} characters; not a data table") from None
    finally:
        csv.field_size_limit(limit)


def column(table: Table, names, what: str, kind: str, required_unit: bool = True):
    """The first of ``names`` present in the table, checked to be of ``kind`` [SI].

    Raises
    ------
    InputError
        None of the names is a column, or its unit is missing or of another kind.
    """
    for name in names:
        if name in table.columns:
            unit = table.units[name]
            if not unit:
                if required_unit and kind != "dimensionless":
                    raise InputError(f"{table.path}: column {name!r} needs a unit in the "
                                     f"header, e.g. '{name} [{_example(kind)}]'")
            else:
                got = "compound" if "/" in unit else unit_kind(unit)
                if kind != "compound" and got != kind:
                    raise InputError(f"{table.path}: column {name!r}: unit {unit!r} is not "
                                     f"a {kind}")
            return name, table.columns[name]
    raise InputError(f"{table.path}: needs a {what} column (one of: {', '.join(names)})")


def _example(kind):
    return {"pressure": "kPa", "temperature": "degC", "time": "s", "force": "N",
            "length": "mm", "angle": "deg", "resistance": "ohm"}.get(kind, "1")
