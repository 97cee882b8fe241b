"""The row of every kernel output, derived once from the registry (issue 28).

The kernels write each variable into a row of an output array: the float design variables
into ``design`` of :class:`~.records.GridOut` and :class:`~.records.PointOut`, ``limit``
and ``validity`` into their int8 ``flags``, the closed loop's metrics into the tracking
kernel's ``out``; the engine reads the rows back by name. Both read the tables here, made
from the registry's order (:data:`nylonflex.variables.DESIGN`,
:data:`nylonflex.variables.TRACKING`), so a reordered registry moves the rows with it,
and an added variable without a row fails ``tests/test_kernels.py``. The ``ROW_*``
constants are plain ints: read as globals in a jitted kernel, Numba compiles them in as
constants. This module imports no Numba.
"""

from __future__ import annotations

from ..variables import DESIGN, TRACKING

__all__ = ["DESIGN_ROWS", "FLAG_DESIGN", "FLAG_ROWS", "FLOAT_DESIGN", "N_FLAGS",
           "N_FLOAT_DESIGN", "N_TRACKING", "TRACKING_ROWS"]

#: The float design variables in the registry's order: the rows of ``out.design``.
FLOAT_DESIGN = tuple(n for n, v in DESIGN.items() if v.dtype == "float64")
#: The int8 design variables in the registry's order (``limit``, ``validity``): the rows of
#: ``out.flags``.
FLAG_DESIGN = tuple(n for n, v in DESIGN.items() if v.dtype == "int8")

#: Name -> row of ``out.design``, of ``out.flags``, and of the tracking kernel's ``out``.
DESIGN_ROWS = {n: row for row, n in enumerate(FLOAT_DESIGN)}
FLAG_ROWS = {n: row for row, n in enumerate(FLAG_DESIGN)}
TRACKING_ROWS = {n: row for row, n in enumerate(TRACKING)}

#: The number of rows of each output.
N_FLOAT_DESIGN = len(DESIGN_ROWS)
N_FLAGS = len(FLAG_ROWS)
N_TRACKING = len(TRACKING_ROWS)

# ``ROW_<NAME>``: the row of the variable ``<name>`` (each table's names are distinct
# across the three tables: the tracking ones begin with ``tracking_``)
ROW_USABLE_STROKE = DESIGN_ROWS["usable_stroke"]
ROW_PRESSURE_MAX = DESIGN_ROWS["pressure_max"]
ROW_TORQUE_MAX = DESIGN_ROWS["torque_max"]
ROW_TIP_FORCE_MAX = DESIGN_ROWS["tip_force_max"]
ROW_BEND_ANGLE_MAX = DESIGN_ROWS["bend_angle_max"]
ROW_RANGE_FRACTION = DESIGN_ROWS["range_fraction"]
ROW_NYLON_FORCE_MAX = DESIGN_ROWS["nylon_force_max"]
ROW_NYLON_USE = DESIGN_ROWS["nylon_use"]
ROW_MUSCLE_LENGTH = DESIGN_ROWS["muscle_length"]
ROW_RESISTANCE = DESIGN_ROWS["resistance"]
ROW_HEATING_POWER = DESIGN_ROWS["heating_power"]
ROW_HEATING_VOLTAGE = DESIGN_ROWS["heating_voltage"]
ROW_COOLING_TIME = DESIGN_ROWS["cooling_time"]
ROW_HEATING_TIME = DESIGN_ROWS["heating_time"]
ROW_CYCLE_TIME = DESIGN_ROWS["cycle_time"]
ROW_CYCLE_RATE = DESIGN_ROWS["cycle_rate"]
ROW_HEATING_ENERGY = DESIGN_ROWS["heating_energy"]
ROW_MECHANICAL_WORK = DESIGN_ROWS["mechanical_work"]
ROW_EFFICIENCY = DESIGN_ROWS["efficiency"]

ROW_LIMIT = FLAG_ROWS["limit"]
ROW_VALIDITY = FLAG_ROWS["validity"]

ROW_TRACKING_RMS_ERROR = TRACKING_ROWS["tracking_rms_error"]
ROW_TRACKING_MAX_TEMPERATURE = TRACKING_ROWS["tracking_max_temperature"]
ROW_TRACKING_ENERGY = TRACKING_ROWS["tracking_energy"]
ROW_TRACKING_BANDWIDTH = TRACKING_ROWS["tracking_bandwidth"]

__all__ += sorted(n for n in tuple(globals()) if n.startswith("ROW_"))
