"""``nylonflex query``: ask a saved cube about designs, with units, in bounded memory.

A query picks designs three ways, which combine:

* ``--at radius=7.5mm,coil_index=1.7``: fixes the named axes. A value on the grid (within a
  tiny tolerance) is read as is ("grid point"); between grid points the model is evaluated
  exactly at that design with the cube's own materials and settings from its provenance
  ("exact model", :func:`nylonflex.evaluate`, milliseconds), or, with ``interpolate=True``
  (``--interpolate``), the design variables are interpolated linearly in each axis
  ("interpolated"; up to tens of per cent off where the response bends). Axes not named
  keep all their grid values, so a partial ``--at`` lists a slice of the cube (one row per
  design); naming all five axes gives one design. Outside the grid is refused.
* ``--where "tip_force_max >= 0.5 N"``: conditions on axes or design variables, with units;
  several are ANDed.
* ``--sort NAME`` (``--sort=-NAME`` or ``--sort NAME:desc`` descending; ties keep grid
  order) and ``--limit N``.

``--columns NAME,...`` picks the columns; by default a table shows the axes, the variables
``--where`` tests and ``--sort`` orders by, then :data:`HEADLINE` (``limit``,
``tip_force_max``, ``bend_angle_max``, ``validity`` by flag name), leaving out any column
no row has a value in; JSON and CSV carry every column.

The cube is read in slabs of radii, so memory stays bounded on a cube of any size; only the
matching rows (at most ``--limit``) are kept, and every match is counted, so that the
output can say how many rows it held back.
"""

from __future__ import annotations

from ..variables import AXES, DESIGN, VARIABLES  # noqa: F401  (names the tests use)
from .format import (cell_text, flag_names, format_csv, format_json, format_table, held_back,
                     rows_note, shown_columns)
from ..conditions import (COLUMNS, EXACT, GRID, HEADLINE, INTERPOLATED, OPS, OPTIONAL,
                    Condition, default_columns, parse_at, parse_columns, parse_condition,
                    parse_constraint, parse_requirements, parse_where)
from .grid import at_value, locate
from .result import QueryResult
from .scan import query_cube, slab_rows
from .where import by_variable

__all__ = ["COLUMNS", "EXACT", "GRID", "HEADLINE", "INTERPOLATED", "OPS", "OPTIONAL",
           "Condition", "QueryResult", "at_value", "by_variable",
           "cell_text", "default_columns", "flag_names", "format_csv", "format_json",
           "format_table", "held_back", "locate", "parse_at", "parse_columns",
           "parse_condition", "parse_constraint", "parse_requirements", "parse_where",
           "query_cube", "rows_note", "shown_columns", "slab_rows"]
