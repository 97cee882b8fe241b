"""The package version, read by setuptools at build time and by ``nylonflex --version``.

A plain assignment (no importlib.metadata at import time: that costs ~50 ms of every
command's start-up).
"""

__version__ = "0.1.0"
