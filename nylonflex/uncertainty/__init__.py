"""Uncertainty and sensitivity: how sure is each design, and which parameter decides it.

Sampled sweeps (``uncertainty:`` and ``requirements:`` in a sweep config) run through the
engine's slab loop (:mod:`nylonflex.engine.sampled`, re-exported here); this package adds
the Python faces a designer scripts against and the Sobol' sensitivity indices (SALib) of
``nylonflex sensitivity``. docs/uncertainty.md describes the method and the cube's
variables.
"""

from __future__ import annotations

from ..engine.sampled import (
                              perturbed_inputs,
                              sample_statistics,
                              standard_samples,
                              uncertain_variables,
)
from .propagate import propagate
from .sensitivity import SensitivityResult, sobol_indices

__all__ = ["SensitivityResult", "perturbed_inputs", "propagate", "sample_statistics",
           "sobol_indices", "standard_samples", "uncertain_variables"]
