"""The rows a query gives (:class:`QueryResult`): SI arrays by column, what picked them."""

from __future__ import annotations

from ..conditions import COLUMNS
from .format import rows_note, shown_columns
from .frames import html_table, rows_frame

__all__ = ["QueryResult"]


class QueryResult:
    """Rows of a query: ``data`` maps each column to an SI array.

    Attributes
    ----------
    data : dict of str to numpy.ndarray
        One array per column of :data:`COLUMNS`, SI; ``limit`` and ``validity`` hold
        whole numbers (NaN: unknown).
    point : str or None
        ``"grid point"``, ``"exact model"`` or ``"interpolated"`` for an ``--at`` query,
        else None.
    interpolated : list of str
        The ``--at`` axes that lie between grid points (evaluated exactly, or interpolated
        when ``point`` is ``"interpolated"``).
    matched : int or None
        Designs that met the conditions (every one is counted, shown or not).
    single : bool
        The query named one design (all five axes in ``--at``).
    """

    def __init__(self, data, point, interpolated, matched, single, at, columns=COLUMNS,
                 chosen=None, asked=(), flags=None, every=False):
        self.data, self.point, self.interpolated = data, point, interpolated
        self.matched, self.single, self.at = matched, single, at
        self.columns = tuple(columns)  # COLUMNS and the cube's OPTIONAL ones
        #: the columns ``--columns`` named (None: the format's default)
        self.chosen = None if chosen is None else tuple(chosen)
        #: ``--columns all``: every column (a table still leaves out the all-NaN ones)
        self.every = every
        #: the names ``--where`` tests and ``--sort`` orders by (a table shows them)
        self.asked = tuple(asked)
        #: with ``--interpolate``: where ``limit`` and ``validity`` came from, "exact
        #: model" or "unknown where the grid points disagree"; None otherwise
        self.flags = flags

    def __len__(self):
        return len(self.data[COLUMNS[0]])

    def to_dataframe(self):
        """The rows as a pandas DataFrame, every column in SI (``df.attrs["units"]``),
        ``limit`` and ``validity`` as numbers (NaN: unknown), as ``--format csv``."""
        extra = {"point": [self.point] * len(self)} if self.point else None
        return rows_frame(self.data, shown_columns(self, "csv"), extra)

    def _repr_html_(self) -> str:
        """The table ``nylonflex query`` prints, as HTML (display units, flags by name)."""
        caption = rows_note(self) if self.matched is not None else (self.point or "")
        return html_table(self.data, shown_columns(self), len(self), caption)
