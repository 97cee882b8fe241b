"""
Three models side by side: ``compare``
======================================

A cube swept with several models (``model: [paper, lateral_pressure, fe_calibrated]``)
gains a ``model`` dimension; ``compare`` draws one design variable against radius for
every model, at the paper's first worked example's slice.
"""

import nylonflex as nf
from nylonflex.charts import CHARTS
from nylonflex.config import parse_config

from _grid import CURVES, GRID

cfg = parse_config({"name": "models", "grid": GRID, "curves": CURVES,
                    "base_thickness": "wall",
                    "model": ["paper", "lateral_pressure", "fe_calibrated"]})
ds = nf.run_sweep(cfg)

# %%
# The largest bend angle of each model (``variable`` picks any design variable).
compare = CHARTS["compare"](ds, variable="bend_angle_max")
