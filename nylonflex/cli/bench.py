"""``nylonflex bench [--quick]``: the kernels against the references, side by side.

The benchmarks are not part of the package: they live in the repository's ``benchmarks/``
folder and come with a source checkout. The editable install the README uses (``pip
install -e .``) runs the checkout's own ``nylonflex/``, so the folder is found beside the
package (:func:`benchmarks_folder`) and its ``suite.py`` is run. An installed wheel has no
such folder: the command says so in one line and exits 2.
"""

from __future__ import annotations

import importlib
import importlib.util
import sys
from pathlib import Path

from . import EXIT_INPUT

HELP = "time the kernels against scipy"
DESCRIPTION = """Time the kernels against the scipy reference and a NumPy yardstick, side by
side in one run. The benchmarks come with a source checkout (its benchmarks/ folder, beside
nylonflex/; pip install -e . there): an installed wheel has none."""

#: The suite's module name once loaded (a name no installed package uses).
SUITE = "nylonflex_benchmarks"


def add_arguments(b):
    b.add_argument("--quick", action="store_true", help="a small smoke run")


def benchmarks_folder(root=None):
    """The ``benchmarks/`` folder of the source checkout at ``root`` (default: the folder
    above the running package, the checkout itself for an editable install), or None
    where there is none (an installed wheel: ``root`` is then site-packages).

    Only a checkout counts: the folder must hold ``suite.py`` and ``root`` the project's
    ``pyproject.toml``, so that another distribution's top-level ``benchmarks`` is never
    run."""
    if root is None:
        root = Path(__file__).resolve().parents[2]
    folder = Path(root) / "benchmarks"
    if (folder / "suite.py").is_file() and (Path(root) / "pyproject.toml").is_file():
        return folder
    return None


def load_suite(folder):
    """``folder``/suite.py (a :func:`benchmarks_folder`) as a module of the package
    ``folder`` under the name :data:`SUITE`, loaded once by its path."""
    if SUITE not in sys.modules:
        spec = importlib.util.spec_from_file_location(
            SUITE, folder / "__init__.py", submodule_search_locations=[str(folder)])
        package = importlib.util.module_from_spec(spec)
        sys.modules[SUITE] = package
        try:
            spec.loader.exec_module(package)
        except BaseException:
            del sys.modules[SUITE]
            raise
    return importlib.import_module(f"{SUITE}.suite")


def run(args) -> int:
    folder = benchmarks_folder()
    if folder is None:
        root = Path(__file__).resolve().parents[2]
        print("nylonflex bench: the benchmarks come with a source checkout of nylonflex (its "
              "benchmarks/ folder, beside nylonflex/; run 'pip install -e .' in a clone of "
              f"the repository); this install has none ({root / 'benchmarks'} is missing)",
              file=sys.stderr)
        return EXIT_INPUT
    load_suite(folder).run_bench(quick=args.quick, log=lambda msg: print(msg, flush=True))
    return 0
