"""
How fast it moves: cycle rate charts
====================================

With a supply (``supply: {voltage: 12, units: V}``) every design also gets its heating and
cooling times, cycle rate, energy and efficiency (docs/model.md s. 20).
"""

import nylonflex as nf
from nylonflex.charts import CHARTS
from nylonflex.config import parse_config

from _grid import CURVES, GRID

cfg = parse_config({"name": "supply", "grid": GRID, "curves": CURVES,
                    "base_thickness": "wall", "supply": {"voltage": 12, "units": "V"}})
ds = nf.run_sweep(cfg)

# %%
# ``cycle_rate_map``: the cycle rate over two design axes, the others fixed.
cycle_rate_map = CHARTS["cycle_rate_map"](ds)

# %%
# ``cycle_rate_lines``: the cycle rate against radius, one line per coil index.
cycle_rate_lines = CHARTS["cycle_rate_lines"](ds)

# %%
# ``force_rate``: tip force against cycle rate for every design, with the front of the
# largest force at each rate.
force_rate = CHARTS["force_rate"](ds)
