"""The physical model of docs/model.md as plain, documented functions (SI in and out).

One module per domain: :mod:`.nylon` (stroke, coil-index table, eq. 1), :mod:`.thermal`
(eq. 3), :mod:`.chamber` (Boyle), :mod:`.silicone` (Ogden), :mod:`.wrap` (wrap geometry and
nylon force), :mod:`.bending` (moments, curvature, angle, tip force) and :mod:`.limits`
(design limits); :func:`check_input` and its two shorthands check an input against the
registry's range for callers above (the evaluator, the FE twin), :func:`float_in_range`
(with :func:`input_range`) is its test of one float, the evaluator's one-design path.
This package holds formulas and records, nothing about compilers (the kernels compile the
formulas, :mod:`nylonflex.kernels`), and imports neither Numba, xarray nor matplotlib.
"""

from .bending import (
    bend_angle,
    curvature,
    material_moment,
    pressure_moment,
    tip_force,
)
from ._formula import (check_input, check_section, check_wrap_angle, float_in_range,
                       input_range)
from .chamber import P_ATM, chamber_pressure, volume_ratio
from .limits import design_limits, stroke_limit
from .nylon import (
    free_strain,
    nylon_force_limit,
    stroke,
    stroke_max,
    temperature_for_stroke,
    tensile_strength,
    thermomechanical_force,
)
from .silicone import (
    bending_stress,
    cauchy_stress,
    hoop_stress,
    initial_shear_modulus,
    strain_energy,
)
from .thermal import (
    muscle_resistance,
    steady_temperature,
    temperature_rate,
    temperature_step,
    thermal_time_constant,
)
from .wrap import muscle_length, muscle_width, nylon_force, outer_perimeter, wrap_pitch, wrap_turns

__all__ = [
    "P_ATM",
    "bend_angle",
    "bending_stress",
    "cauchy_stress",
    "chamber_pressure",
    "check_input",
    "check_section",
    "check_wrap_angle",
    "curvature",
    "design_limits",
    "float_in_range",
    "free_strain",
    "hoop_stress",
    "initial_shear_modulus",
    "input_range",
    "material_moment",
    "muscle_length",
    "muscle_resistance",
    "muscle_width",
    "nylon_force",
    "nylon_force_limit",
    "outer_perimeter",
    "pressure_moment",
    "steady_temperature",
    "strain_energy",
    "stroke",
    "stroke_limit",
    "stroke_max",
    "temperature_for_stroke",
    "temperature_rate",
    "temperature_step",
    "tensile_strength",
    "thermal_time_constant",
    "thermomechanical_force",
    "tip_force",
    "volume_ratio",
    "wrap_pitch",
    "wrap_turns",
]
