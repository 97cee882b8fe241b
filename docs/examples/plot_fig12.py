"""
The paper's figures 4, 6, 7 and 12, and the design map
=======================================================

The charts of a plain sweep (``nylonflex sweep configs/fig12.yaml`` draws them beside the
cube it writes): here from a small grid swept in memory.
"""

# %%
# A small figure-12 grid, in the config's units (mm, deg, kPa), swept in memory.
import numpy as np

import nylonflex as nf
from nylonflex.charts import CHARTS
from nylonflex.config import parse_config

GRID = {
    "radius": {"start": 5, "stop": 25, "num": 9, "units": "mm"},
    "wall_thickness": {"values": [1, 2, 4, 6], "units": "mm"},
    "length": {"values": [70, 90], "units": "mm"},
    "coil_index": {"values": [1.1, 1.3, 1.5, 1.7]},
    "wrap_angle": {"values": [5, 8, 12, 20], "units": "deg"},
}
CURVES = {"stroke": {"start": 0, "stop": 0.1, "num": 21},
          "pressure": {"start": 0, "stop": 25, "num": 21, "units": "kPa"}}
cfg = parse_config({"name": "gallery", "grid": GRID, "curves": CURVES,
                    "base_thickness": "wall"})
ds = nf.run_sweep(cfg)
print(f"{ds.sizes['radius'] * ds.sizes['wall_thickness'] * ds.sizes['length'] * ds.sizes['coil_index'] * ds.sizes['wrap_angle']:,} designs;"
      f" largest tip force {float(np.nanmax(ds['tip_force_max'])):.2f} N")

# %%
# ``fig12a``: the nylon's force against its stroke, with each coil index's strength limit.
fig12a = CHARTS["fig12a"](ds)

# %%
# ``fig12b``: the largest torque against chamber radius, one line per coil index.
fig12b = CHARTS["fig12b"](ds)

# %%
# ``fig12c``: the largest bend angle and the range of motion against radius.
fig12c = CHARTS["fig12c"](ds)

# %%
# ``fig4``: the chamber pressure against the muscle's stroke (Boyle's law).
fig4 = CHARTS["fig4"](ds)

# %%
# ``fig6``: the bend angle against pressure, varying radius and wall thickness.
fig6 = CHARTS["fig6"](ds)

# %%
# ``fig7``: the blocked tip force against pressure.
fig7 = CHARTS["fig7"](ds)

# %%
# ``design_map``: the largest tip force over radius and wall thickness, the
# strength-limited region hatched.
design_map = CHARTS["design_map"](ds)
