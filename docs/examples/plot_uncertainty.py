"""
Under uncertainty: ``feasibility_map``
======================================

An ``uncertainty:`` block samples the wall thickness and the materials; ``requirements:``
then gives every design the probability that all of them hold (docs/uncertainty.md).
"""

import nylonflex as nf
from nylonflex.charts import CHARTS
from nylonflex.config import parse_config

from _grid import CURVES, GRID

cfg = parse_config({
    "name": "uncertain", "grid": GRID, "curves": CURVES, "base_thickness": "wall",
    "uncertainty": {"samples": 32, "seed": 0, "parameters": {
        "wall_thickness": {"sd": 0.1, "units": "mm"},
        "silicone.mu": {"rel_sd": 0.1},
        "nylon.stroke_max": {"rel_sd": 0.05}}},
    "requirements": ["tip_force_max >= 0.5 N", "range_fraction >= 1"],
})
ds = nf.run_sweep(cfg)

# %%
# The probability that a design gives 0.5 N with its full range of motion.
feasibility_map = CHARTS["feasibility_map"](ds)

# %%
# Figure 12(b) of an uncertain cube gains its 5-95 % bands.
fig12b = CHARTS["fig12b"](ds)
