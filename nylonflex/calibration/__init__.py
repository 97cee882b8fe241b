"""Calibration: fit material and muscle sets to bench data, and check a design against it.

Domain functions only (they return values and never print): :func:`read_table` reads the
data, :func:`fit_silicone`, :func:`fit_stroke`, :func:`fit_thermal` and :func:`fit_muscle`
return a :class:`FitResult`, :func:`write_material_file` writes the YAML file that configs
use as ``silicone: {file: ...}`` or ``nylon: {file: ...}``, and :func:`validate_design`
compares one design's model with its measurements. docs/calibration.md has the formats.
"""

from .data import Table, read_table
from ..files.material_files import read_material_set, write_material_file
from .hyperelastic import MODELS, TESTS, fit_silicone, nominal_stress
from .muscle import fit_muscle, fit_stroke, fit_thermal
from .result import FitResult
from .validate import validate_design

__all__ = ["MODELS", "TESTS", "FitResult", "Table", "fit_muscle", "fit_silicone",
           "fit_stroke", "fit_thermal", "nominal_stress", "read_material_set", "read_table",
           "validate_design", "write_material_file"]
