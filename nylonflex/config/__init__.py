"""Configs: YAML -> validated, frozen objects in SI, with units parsed at this edge.

- :mod:`.base`: strict pydantic models, the one range-error formatter, one-line messages;
- :mod:`.sweep`: sweep configs (``nylonflex sweep``), :class:`ResolvedConfig`;
- :mod:`.uncertainty`: their ``uncertainty:`` section;
- :mod:`.simulate`: simulate configs (``nylonflex simulate``), the same machinery.
"""

from .base import (
                   Count,
                   Number,
                   check_range,
                   check_run_name,
                   range_error,
                   valid_name,
)
from .sweep import (
                   CHARTS,
                   DESIGN_RANGES,
                   LIMITS,
                   ResolvedConfig,
                   SweepConfig,
                   apply_overrides,
                   canonical_yaml,
                   cube_bytes,
                   load_config,
                   load_yaml,
                   parse_config,
                   read_yaml,
)
from .uncertainty import UncertainParameter, UncertaintySpec

__all__ = ["CHARTS", "Count", "Number", "DESIGN_RANGES", "LIMITS", "ResolvedConfig", "SweepConfig",
           "UncertainParameter", "UncertaintySpec", "apply_overrides", "canonical_yaml",
           "check_range", "check_run_name", "cube_bytes", "load_config", "load_yaml",
           "parse_config", "range_error", "read_yaml", "valid_name"]
