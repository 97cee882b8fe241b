"""The small grid every gallery example sweeps (config units: mm, deg, kPa)."""

GRID = {
    "radius": {"start": 5, "stop": 25, "num": 9, "units": "mm"},
    "wall_thickness": {"values": [1, 2, 4, 6], "units": "mm"},
    "length": {"values": [70, 90], "units": "mm"},
    "coil_index": {"values": [1.1, 1.3, 1.5, 1.7]},
    "wrap_angle": {"values": [5, 8, 12, 20], "units": "deg"},
}
CURVES = {"stroke": {"start": 0, "stop": 0.1, "num": 21},
          "pressure": {"start": 0, "stop": 25, "num": 21, "units": "kPa"}}
