"""nylonflex: design-space sweeps of nylon-muscle-driven soft bending actuators."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("nylonflex")
except PackageNotFoundError:  # pragma: no cover - running from a source tree
    __version__ = "0+unknown"

from .materials import NYLON_PARAMETERS, SILICONE_PARAMETERS, nylon_parameters, silicone_parameters
from .physics import design_limits

__all__ = [
    "NYLON_PARAMETERS",
    "SILICONE_PARAMETERS",
    "__version__",
    "design_limits",
    "nylon_parameters",
    "silicone_parameters",
]
