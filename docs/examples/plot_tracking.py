"""
Closed-loop tracking of every design: ``tracking_map``
======================================================

A ``tracking:`` block runs the closed loop of the paper's figure 9 for every design of the
sweep (docs/model.md s. 19): here the figure-9 sine, 50 s at a 20 ms step, on a smaller
grid still.
"""

import nylonflex as nf
from nylonflex.charts import CHARTS
from nylonflex.config import parse_config

from _grid import CURVES, GRID

grid = dict(GRID, length={"values": [90], "units": "mm"},
            coil_index={"values": [1.7]}, wrap_angle={"values": [8], "units": "deg"})
cfg = parse_config({
    "name": "tracking", "grid": grid, "curves": CURVES, "base_thickness": "wall",
    "supply": {"voltage": 12, "units": "V"},
    "tracking": {"duration": "50 s", "step": "20 ms", "initial_temperature": "25 degC",
                 "reference": {"kind": "sine", "mean": "85 deg", "amplitude": "30 deg",
                               "frequency": "0.04 Hz"},
                 "controller": {"kind": "bang_bang", "hysteresis": "0 deg"},
                 "rms_from": "25 s"},
})
ds = nf.run_sweep(cfg)

# %%
# The RMS tracking error over radius and wall thickness.
tracking_map = CHARTS["tracking_map"](ds)
