"""The chart registry: every chart, once, with what it needs and how it is drawn.

A sweep config's ``charts:`` list is validated against it, ``nylonflex list charts`` prints
it, ``nylonflex chart --figure`` offers its names, and :func:`nylonflex.charts.draw_charts`
reads from it which cubes a chart can show, whether it is drawn once a model, and which to
start first. Each chart's function lives in :mod:`nylonflex.charts`; the registry names it
(``module:function``), so that the config, low in the layers, never imports matplotlib code.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass

__all__ = ["CHART_REGISTRY", "Chart"]


@dataclass(frozen=True)
class Chart:
    """One chart of a cube.

    Attributes
    ----------
    name : str
        The name a config and ``--figure`` use.
    function : str
        ``"module:function"`` in :mod:`nylonflex.charts`; the function is
        ``f(ds, **slice) -> matplotlib.figure.Figure``.
    needs : tuple of str
        Axes the chart draws along: a cube with a single value on one of them cannot show it.
    per_model : bool
        Drawn once a model of a cube of several (False: one figure holds every model).
    cost : float
        Drawing time relative to fig4's (the fig12 cube, a 2-core machine) [1]: the drawing
        processes take the longest first, so that none is left drawing alone at the end.
    variable : str, optional
        A cube variable the chart needs beyond the design variables (``feasibility``).
    absent : str
        Why a cube lacks ``variable`` (said when the chart is skipped).
    needs_text : str
        What else the chart needs, for ``nylonflex list charts``.
    """

    name: str
    function: str
    needs: tuple[str, ...]
    per_model: bool = True
    cost: float = 1.0
    variable: str | None = None
    absent: str = "no 'requirements'"
    needs_text: str = ""

    def load(self):
        """The chart's function (imports :mod:`nylonflex.charts`)."""
        module, func = self.function.split(":")
        return getattr(importlib.import_module(f"nylonflex.charts.{module}"), func)


#: name -> :class:`Chart`, in the order charts are listed and drawn.
CHART_REGISTRY = {c.name: c for c in (
    Chart("fig12a", "fig12:fig12a", ("stroke",), cost=1.9),
    Chart("fig12b", "fig12:fig12b", ("radius",), per_model=False, cost=2.3),
    Chart("fig12c", "fig12:fig12c", ("radius",), per_model=False, cost=3.2),
    Chart("fig4", "curves:fig4", ("stroke",), cost=1.0),
    Chart("fig6", "curves:fig6", ("pressure",), cost=1.5),
    Chart("fig7", "curves:fig7", ("pressure",), cost=1.5),
    Chart("design_map", "maps:design_map", ("radius", "wall_thickness"), cost=4.0),
    Chart("feasibility_map", "maps:feasibility_map", ("radius", "wall_thickness"), cost=4.0,
          variable="feasibility"),
    Chart("compare", "compare:compare", ("radius",), per_model=False, cost=1.2),
    # the per-design dynamics: only for a cube with a supply (docs/model.md s. 20)
    Chart("cycle_rate_map", "dynamics:cycle_rate_map", ("radius", "wrap_angle"), cost=2.0,
          variable="cycle_rate", absent="its sweep had no 'supply'", needs_text="a supply"),
    Chart("cycle_rate_lines", "dynamics:cycle_rate_lines", ("radius",), cost=1.2,
          variable="cycle_rate", absent="its sweep had no 'supply'", needs_text="a supply"),
    Chart("force_rate", "dynamics:force_rate", (), cost=2.0, variable="cycle_rate",
          absent="its sweep had no 'supply'", needs_text="a supply"),
    # the closed loop of every design: only for a cube swept with tracking: (s. 19)
    Chart("tracking_map", "dynamics:tracking_map", ("radius", "wall_thickness"), cost=2.0,
          variable="tracking_rms_error", absent="its sweep had no 'tracking'",
          needs_text="a sweep with tracking:"),
)}
