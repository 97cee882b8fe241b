"""Imports point down only (STYLE.md): physics <- kernels <- sweep <- storage/charts <- cli."""

import ast
from pathlib import Path

PKG = Path(__file__).resolve().parents[1] / "nylonflex"


def _imports(path: Path) -> set[str]:
    names = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = path.relative_to(PKG.parent).with_suffix("").parts[:-node.level]
                base = ".".join([*parts, base] if base else parts)
            names.add(base)
            names.update(f"{base}.{a.name}" for a in node.names)
    return names


def test_physics_imports_no_numba_xarray_matplotlib_or_upper_layers():
    for path in (PKG / "physics").glob("*.py"):
        for name in _imports(path):
            root = name.split(".")[0]
            assert root not in ("numba", "xarray", "matplotlib", "h5py", "h5netcdf"), (path, name)
            assert not name.startswith(("nylonflex.kernels", "nylonflex.sweep",
                                        "nylonflex.storage", "nylonflex.charts",
                                        "nylonflex.cli", "nylonflex.config")), (path, name)


def test_kernels_do_not_import_the_sweep_storage_charts_or_cli():
    for path in (PKG / "kernels").glob("*.py"):
        for name in _imports(path):
            assert not name.startswith(("nylonflex.sweep", "nylonflex.storage",
                                        "nylonflex.charts", "nylonflex.cli", "xarray",
                                        "matplotlib")), (path, name)


def test_charts_compute_no_physics():
    for path in PKG.glob("chart*.py"):
        for name in _imports(path):
            assert not name.startswith(("nylonflex.physics", "nylonflex.kernels")), (path, name)


def test_only_the_sweep_and_simulator_call_the_design_kernels():
    for path in PKG.rglob("*.py"):
        if path.parent.name == "kernels" or path.name in ("sweep.py", "simulate.py",
                                                          "distributed.py"):
            continue
        for name in _imports(path):
            assert not name.startswith("nylonflex.kernels.design"), (path, name)


def test_cli_holds_no_science():
    for path in (PKG / "cli").glob("*.py"):
        for name in _imports(path):
            assert not name.startswith(("nylonflex.physics", "nylonflex.kernels", "numba")), \
                (path, name)
