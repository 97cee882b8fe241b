"""Query and design results in notebooks (issue 50): ``to_dataframe()`` (SI, one row per
design, the units in ``df.attrs["units"]``) and ``_repr_html_`` (the table ``nylonflex
query`` prints: display units, flags by name)."""

from __future__ import annotations

import html

import numpy as np

from ..variables import CATEGORIES, VARIABLES
from .format import cell_text


def _unit(name: str, display: bool) -> str:
    var = VARIABLES.get(name)
    if var is None:
        return ""
    return var.display if display else var.units


def rows_frame(columns: dict, names, extra: dict | None = None):
    """A pandas DataFrame of ``columns`` (name -> SI array) restricted to ``names``, with
    ``extra`` columns (name -> list) in front; ``attrs["units"]`` maps each column to its
    SI unit ("" for text)."""
    import pandas as pd

    data = dict(extra or {})
    data.update({n: np.asarray(columns[n]) for n in names})
    df = pd.DataFrame(data)
    df.attrs["units"] = {n: _unit(n, display=False) for n in df.columns}
    return df


def html_table(columns: dict, names, n: int, caption: str = "",
               extra: dict | None = None) -> str:
    """An HTML table of ``n`` rows: each column's title with its display unit, each cell as
    the query table writes it (:func:`~nylonflex.query.format.cell_text`)."""
    extra = extra or {}
    head = [f"<th>{html.escape(k)}</th>" for k in extra]
    for name in names:
        unit = _unit(name, display=True)
        label = name if not unit or unit == "1" or name in CATEGORIES else f"{name} [{unit}]"
        head.append(f"<th>{html.escape(label)}</th>")
    body = []
    for i in range(n):
        cells = [f"<td>{html.escape(str(v[i]))}</td>" for v in extra.values()]
        cells += [f"<td>{html.escape(cell_text(name, columns[name][i]))}</td>"
                  for name in names]
        body.append("<tr>" + "".join(cells) + "</tr>")
    cap = f"<caption>{html.escape(caption)}</caption>" if caption else ""
    return (f"<table class='nylonflex'>{cap}<thead><tr>{''.join(head)}</tr></thead>"
            f"<tbody>{''.join(body)}</tbody></table>")
