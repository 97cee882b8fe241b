"""The import-layering contract: imports point down, never back, and never in a circle.

Each top-level module and folder of the package is one layer of :data:`NAMED_LAYERS`,
lowest first: foundation (units) <- files <- examples <- registry (variables) <- variant
notes <- materials <- condition grammar <- physics <- config <- kernels <- engine <-
simulation <- outputs (storage, charts, query) <- sweep <- finite elements <- applications
(calibration, design, explore, uncertainty) <- cli. An import of another nylonflex module
must reach a lower layer (or its own folder). The physics imports neither numba, xarray
nor matplotlib. Imports sit at module top unless they are heavy (:data:`HEAVY_IMPORTS`,
docs/architecture.md); no private name crosses a package.
"""

import ast
import subprocess
import sys
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parents[1] / "nylonflex"

#: The layers, lowest first: a name, and the top-level modules and folders in it (one line
#: a layer, folders only: no module of a folder has a layer of its own). Same-layer imports
#: are allowed only inside one folder.
NAMED_LAYERS = (
    ("foundation", ("_version", "units")),
    ("files", ("files",)),
    ("examples", ("examples",)),
    ("registry", ("variables",)),
    ("variant notes", ("variants",)),
    ("materials", ("materials",)),
    ("condition grammar", ("conditions",)),
    ("physics", ("physics",)),
    ("config", ("config",)),
    ("kernels", ("kernels",)),
    ("engine", ("engine",)),
    ("simulation", ("sim",)),
    ("outputs", ("storage", "charts", "query")),
    ("sweep", ("sweep",)),
    ("finite elements", ("fe",)),
    ("applications", ("calibration", "design", "explore", "uncertainty")),
    ("cli", ("cli",)),
)

#: Rank of each top-level module or subpackage (its layer's place in NAMED_LAYERS).
LAYERS = {unit: rank for rank, (_, units) in enumerate(NAMED_LAYERS) for unit in units}

#: Name of each top-level module's or subpackage's layer.
LAYER_NAME = {unit: name for name, units in NAMED_LAYERS for unit in units}


def _modules():
    for path in sorted(PKG.rglob("*.py")):
        rel = path.relative_to(PKG.parent).with_suffix("")
        parts = rel.parts if rel.name != "__init__" else rel.parts[:-1]
        yield path, ".".join(parts)


def _imports(path: Path, module: str) -> set[str]:
    names = set()
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")
                anchor = anchor[:len(anchor) - (node.level - 1)]
                base = ".".join([*anchor, base] if base else anchor)
            names.add(base)
            names.update(f"{base}.{a.name}" for a in node.names)
    return {n for n in names if n.startswith("nylonflex")}


def _unit(name: str) -> str | None:
    """The top-level module or folder of a dotted nylonflex name (None: the root)."""
    parts = name.split(".")
    return parts[1] if len(parts) > 1 else None


def _resolve(name: str) -> str:
    """A dotted import target as a module of the package (``from x import y`` may name y)."""
    parts = name.split(".")
    while parts:
        candidate = PKG.parent.joinpath(*parts)
        if candidate.with_suffix(".py").is_file() or (candidate / "__init__.py").is_file():
            return ".".join(parts)
        parts = parts[:-1]
    return name


def _edges():
    for path, module in _modules():
        for target in _imports(path, module):
            yield path, module, _resolve(target)


def test_every_module_has_a_layer():
    missing = {_unit(m) for _, m in _modules()} - set(LAYERS) - {None, "__main__"}
    assert not missing, f"add these to NAMED_LAYERS: {sorted(missing)}"
    every = [unit for _, units in NAMED_LAYERS for unit in units]
    assert len(every) == len(set(every)), "a module or subpackage in two layers"


def test_imports_point_down():
    wrong = []
    for path, module, target in _edges():
        src, dst = _unit(module), _unit(target)
        if src in (None, "__main__") or dst is None or src == dst:
            continue  # the package root imports lazily; a subpackage imports itself
        if LAYERS[dst] >= LAYERS[src]:
            wrong.append(f"{module} -> {target} ({LAYER_NAME[src]} -> {LAYER_NAME[dst]})")
    assert not wrong, "imports that run back up or sideways: " + "; ".join(wrong)


def test_no_import_circles():
    graph: dict[str, set[str]] = {}
    for _, module, target in _edges():
        if target != module and _unit(target) is not None:
            graph.setdefault(module, set()).add(target)
    state: dict[str, int] = {}

    def visit(node, stack):
        state[node] = 1
        for nxt in graph.get(node, ()):
            if state.get(nxt) == 1:
                pytest.fail("import circle: " + " -> ".join(stack[stack.index(nxt):] + [nxt]))
            if nxt not in state:
                visit(nxt, stack + [nxt])
        state[node] = 2

    for node in list(graph):
        if node not in state:
            visit(node, [node])


def test_physics_imports_no_numba_xarray_matplotlib():
    for path in (PKG / "physics").glob("*.py"):
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else \
                [node.module or ""] if isinstance(node, ast.ImportFrom) and not node.level \
                else []
            for name in names:
                assert name.split(".")[0] not in ("numba", "xarray", "matplotlib", "h5py",
                                                  "h5netcdf"), (path, name)


def test_physics_holds_no_compiler_machinery():
    # physics/ holds formulas and records (issue 47): a copy of a formula with its globals
    # fixed for Numba (kernels.specialise) or the kernels' scratch (kernels.scratch) lives in
    # kernels/, so every function of a physics module runs in its own module's globals
    import importlib
    import pkgutil
    import types

    from nylonflex import physics

    found = []
    for info in pkgutil.iter_modules(physics.__path__):
        module = importlib.import_module(f"{physics.__name__}.{info.name}")
        found += [f"{module.__name__}.{name}" for name, f in vars(module).items()
                  if isinstance(f, types.FunctionType) and f.__module__ == module.__name__
                  and f.__globals__ is not vars(module)]
        found += [f"{module.__name__}.{name}" for name in ("specialised", "node_scratch")
                  if name in vars(module)]
    assert not found, "compiler machinery in physics/: " + "; ".join(found)


#: Modules outside kernels/ that import Numba, each with its reason (none).
NUMBA_OUTSIDE_KERNELS = set()


def test_numba_is_imported_in_kernels_only():
    """All of Numba sits behind kernels/ (the performance fence, docs/architecture.md):
    a module elsewhere that imports it, even lazily inside a function, is listed here."""
    found = set()
    for path in PKG.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else \
                [node.module or ""] if isinstance(node, ast.ImportFrom) and not node.level \
                else []
            if any(n.split(".")[0] in ("numba", "llvmlite") for n in names):
                found.add(path.relative_to(PKG.parent).as_posix())
    outside = {p for p in found if not p.startswith("nylonflex/kernels/")}
    assert outside == NUMBA_OUTSIDE_KERNELS


def test_importing_the_package_changes_nothing_in_the_process():
    """``import nylonflex`` (and reading its version) loads no Numba, registers no Numba
    event listener and patches no module: a notebook that imports nylonflex beside its own
    Numba code sees Numba as it was."""
    code = ("import sys, nylonflex; nylonflex.__version__; dir(nylonflex); "
            "print(sorted(m for m in sys.modules if m.split('.')[0] in "
            "('numba', 'llvmlite', 'scipy', 'xarray', 'matplotlib', 'h5py')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.strip()
    assert out == "[]"


#: The most positional parameters a function of the package may take: past it, a record
#: (kernels/records.py, physics/records.py) carries the group. No function is past it.
MAX_POSITIONAL = 12


def test_no_function_takes_more_than_twelve_positional_arguments():
    found = set()
    for path in PKG.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and \
                    len(node.args.posonlyargs) + len(node.args.args) > MAX_POSITIONAL:
                found.add(f"{path.relative_to(PKG.parent).as_posix()}:{node.name}")
    assert found == set(), f"give these records: {sorted(found)}"


#: The longest body (docstring not counted) a function may have [lines].
MAX_BODY_LINES = 120
#: Compiled kernel bodies past it: each is one pass over its data (a slab's designs, a
#: cell's quadrature points) with every intermediate a local, kept whole until a split is
#: measured against ``nylonflex bench`` to cost nothing.
LONG_KERNEL_BODIES = {"nylonflex/kernels/design.py:_design_slab",
                      "nylonflex/kernels/ogden.py:ogden_points"}


def test_no_function_body_is_longer_than_the_line():
    found = set()
    for path in PKG.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                continue
            lines = node.end_lineno - node.lineno + 1
            first = node.body[0]
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant) and \
                    isinstance(first.value.value, str):
                lines -= first.end_lineno - first.lineno + 1
            if lines > MAX_BODY_LINES:
                found.add(f"{path.relative_to(PKG.parent).as_posix()}:{node.name}")
    assert found == LONG_KERNEL_BODIES


#: What charts may import from the engine: its core count (how many charts to draw at once,
#: ``charts/_parallel.py``), which computes no physics (issue 47: one ``cores()``).
CHARTS_FROM_ENGINE = {"nylonflex.engine.threads"}


def test_charts_compute_no_physics():
    for path, module, target in _edges():
        if _unit(module) == "charts" and target not in CHARTS_FROM_ENGINE:
            assert _unit(target) not in ("physics", "kernels", "engine"), (module, target)


def test_the_contract_fails_when_an_arrow_runs_back(tmp_path, monkeypatch):
    # a physics module that imports the engine must be caught
    bad = PKG / "physics" / "_layering_probe.py"
    bad.write_text("from ..engine import evaluate\n")
    try:
        with pytest.raises(AssertionError, match="physics._layering_probe -> nylonflex.engine"):
            test_imports_point_down()
    finally:
        bad.unlink()


# ------------------------------------------------------------- the commands that stay light
#: What each light command may not import, run as a user runs it (its own process, the
#: console script): no Numba anywhere; no dask; ``info`` no xarray either (it reads the
#: cube through h5py), ``chart --help`` nothing that draws or reads; none the shell
#: completion's shtab (70 ms here), which only ``nylonflex completion`` needs.
_HEAVY = {
    "info": ("numba", "dask", "xarray", "pandas", "nylonflex.engine", "shtab"),
    # issue 49: a --where scan on the grid reads the cube through h5py alone
    "query": ("numba", "dask", "nylonflex.kernels", "shtab", "xarray", "pandas", "h5netcdf"),
    "chart": ("numba", "dask", "xarray", "matplotlib", "h5py", "shtab"),
    "list": ("numba", "dask", "xarray", "h5py", "shtab"),
    "init": ("numba", "dask", "xarray", "h5py", "shtab"),
}

_PROBE = """
import atexit, json, sys
heavy = json.loads(sys.argv[1])
atexit.register(lambda: print("LOADED", json.dumps(
    [m for m in heavy if sys.modules.get(m) is not None])))  # None: blocked, not loaded
sys.argv = ["nylonflex", *sys.argv[2:]]
from nylonflex.cli import run
run()
"""


def _loaded(argv, heavy, tmp_path):
    import json
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-c", _PROBE, json.dumps(heavy), *argv],
                          capture_output=True, text=True, cwd=tmp_path, timeout=600)
    assert done.returncode == 0, done.stderr
    line = next(x for x in done.stdout.splitlines() if x.startswith("LOADED "))
    return json.loads(line[len("LOADED "):])


@pytest.fixture(scope="module")
def small_cube(tmp_path_factory):
    import yaml

    import nylonflex as nf
    from nylonflex.config import parse_config

    raw = yaml.safe_load((Path(__file__).parent / "data" / "reference_cube.yaml").read_text())
    path = tmp_path_factory.mktemp("light") / "cube.h5"
    nf.run_sweep(parse_config(raw), path).close()
    return path


@pytest.mark.parametrize("command", sorted(_HEAVY))
def test_the_light_commands_import_no_numba_nor_dask(command, small_cube, tmp_path):
    from nylonflex.cli import LIGHT_COMMANDS

    argv = {"info": ["info", str(small_cube)],
            "query": ["query", str(small_cube), "--where", "tip_force_max > 0", "--limit", "3"],
            "chart": ["chart", "--help"],
            "list": ["list", "materials"],
            "init": ["init", str(tmp_path / "examples")]}[command]
    assert command in LIGHT_COMMANDS
    assert _loaded(argv, list(_HEAVY[command]), tmp_path) == []


def test_the_light_command_probe_sees_what_a_command_imports(small_cube, tmp_path):
    # the same probe sees info's reader (h5py) and query's xarray: a module imported while
    # the command runs is reported, so an empty list above means not imported
    assert _loaded(["info", str(small_cube)], ["h5py", "numba"], tmp_path) == ["h5py"]
    assert _loaded(["query", str(small_cube), "--limit", "1"], ["xarray"], tmp_path) \
        == ["xarray"]


def test_an_off_grid_query_of_a_few_designs_imports_no_numba(small_cube, tmp_path):
    # issue 27: query's exact model of up to PYTHON_LOOP_UP_TO designs is the physics
    # layer's Python loop, so a first query --at on a new install compiles nothing; a
    # slice above it runs the compiled kernel (the probe sees Numba there)
    from nylonflex.query.scan import PYTHON_LOOP_UP_TO

    one = "radius=7.3mm,wall_thickness=2.2mm,length=80mm,coil_index=1.37,wrap_angle=9deg"
    assert _loaded(["query", str(small_cube), "--at", one], ["numba"], tmp_path) == []
    slice_ = "radius=7.3mm"  # 3 x 2 x 3 x 3 = 54 designs: still the Python loop
    assert _loaded(["query", str(small_cube), "--at", slice_], ["numba"], tmp_path) == []
    assert 54 <= PYTHON_LOOP_UP_TO < 5 * 54
    assert _loaded(["query", str(small_cube), "--at", "wrap_angle=9deg"], ["numba"],
                   tmp_path) == ["numba"]  # 5 x 3 x 2 x 3 = 90 designs: the kernel


def test_no_pyplot_and_no_backend_switch_in_the_package():
    # figures are matplotlib.figure.Figure objects: a notebook user's backend and pyplot
    # state are left alone (no matplotlib.use, no pyplot import)
    found = []
    for path, module in _modules():
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                names = [a.name for a in node.names] + [getattr(node, "module", None) or ""]
                if any(n == "matplotlib.pyplot" or n == "pyplot" for n in names):
                    found.append(f"{module} imports pyplot")
            elif isinstance(node, ast.Attribute) and node.attr == "use" and \
                    isinstance(node.value, ast.Name) and node.value.id == "matplotlib":
                found.append(f"{module} calls matplotlib.use")
    assert not found, "; ".join(found)


def _private_imports():
    """``"a.b -> c.d._name"`` for each private name one package imports from another."""
    out = set()
    for path, module in _modules():
        package = module if path.name == "__init__.py" else module.rpartition(".")[0]
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):  # ``import nylonflex.pkg._module``
                for alias in node.names:
                    parts = alias.name.split(".")
                    if parts[0] == "nylonflex" and len(parts) > 2 and \
                            module.split(".")[1:2] != parts[1:2] and \
                            any(n.startswith("_") and not n.startswith("__") for n in parts[2:]):
                        out.add(f"{'.'.join(module.split('.')[1:])} -> {'.'.join(parts[1:])}")
                continue
            if not isinstance(node, ast.ImportFrom):
                continue
            base = node.module or ""
            if node.level:
                anchor = package.split(".")
                anchor = anchor[:len(anchor) - (node.level - 1)]
                base = ".".join([*anchor, base] if base else anchor)
            parts = base.split(".")
            if parts[0] != "nylonflex" or len(parts) < 2 or parts[1] == "_version":
                continue
            if len(module.split(".")) > 1 and module.split(".")[1] == parts[1]:
                continue  # inside one package
            for alias in node.names:
                names = parts[1:] + [alias.name]
                if any(n.startswith("_") and not n.startswith("__") for n in names):
                    src = ".".join(module.split(".")[1:])
                    out.add(f"{src} -> {'.'.join(names)}")
    return out


def test_no_private_name_is_imported_across_packages():
    # the kernels compile the physics' private Numba formulas by name (their one exception;
    # kernels.scratch sizes the node table with the formula the kernels compile)
    found = {f for f in _private_imports()
             if not f.startswith(("kernels.design -> physics.", "kernels.control -> physics.",
                                  "kernels.tracking -> physics.",
                                  "kernels.scratch -> physics.bending._node_count"))}
    assert not found, "private names imported across packages: " + "; ".join(sorted(found))


#: The modules the package root holds (issue 28); everything else lives in a subpackage.
ROOT = {"__init__", "__main__", "_version", "errors", "materials", "units", "variables",
        "variants", "conditions"}  # variants: the model variants' records beside MODELS (issue 46)

#: The subpackages the package root holds (issue 28). The benchmarks and the slow reference
#: are not among them: they live in the repository's benchmarks/ and tests/naive.py.
SUBPACKAGES = {"physics", "kernels", "engine", "storage", "config", "query", "sim",
               "calibration", "uncertainty", "design", "charts", "explore", "fe", "cli",
               "examples", "files", "sweep"}


def _root_contents(pkg: Path):
    """The package root's modules (stems) and folders, build outputs left out: a folder
    that holds nothing but ``__pycache__`` (what git leaves of a removed subpackage) does
    not count."""
    modules = {p.stem for p in pkg.glob("*.py")}
    folders = {p.name for p in pkg.iterdir() if p.is_dir() and p.name != "__pycache__"
               and any(q.name != "__pycache__" for q in p.iterdir())}
    return modules, folders


def test_the_package_root_holds_only_its_listed_modules_and_folders():
    modules, folders = _root_contents(PKG)
    assert not modules - ROOT, f"move these into a subpackage: {sorted(modules - ROOT)}"
    assert not folders - SUBPACKAGES, \
        f"folders the package root may not hold (issue 28): {sorted(folders - SUBPACKAGES)}"
    assert SUBPACKAGES <= folders  # the list is the package's, not a wish list


def test_the_root_contents_check_sees_a_stray_module_and_folder(tmp_path):
    for name in SUBPACKAGES:
        (tmp_path / name).mkdir()
        (tmp_path / name / "__init__.py").write_text("")
    (tmp_path / "__init__.py").write_text("")
    (tmp_path / "__pycache__").mkdir()
    (tmp_path / "bench" / "__pycache__").mkdir(parents=True)  # left behind by a checkout
    assert _root_contents(tmp_path) == ({"__init__"}, SUBPACKAGES)
    (tmp_path / "bench" / "__init__.py").write_text("")
    (tmp_path / "helpers.py").write_text("")
    modules, folders = _root_contents(tmp_path)
    assert modules - ROOT == {"helpers"} and folders - SUBPACKAGES == {"bench"}


def test_nothing_imports_the_old_bench_subpackage():
    # the benchmarks moved to the repository's benchmarks/, the reference to tests/naive.py
    old = lambda name: name == "nylonflex.bench" or name.startswith("nylonflex.bench.")  # noqa
    found = [f"{m} -> {n}" for path, m in _modules() for n in _imports(path, m) if old(n)]
    repo = PKG.parent
    for path in sorted([*(repo / "tests").glob("*.py"), *(repo / "benchmarks").glob("*.py")]):
        for node in ast.walk(ast.parse(path.read_text())):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else \
                [node.module or ""] if isinstance(node, ast.ImportFrom) else []
            found += [f"{path.relative_to(repo)} -> {n}" for n in names if old(n)]
    assert not found, "; ".join(found)


# -------------------------------------------------------------- imports at module top
#: The modules whose import a light command would feel (docs/architecture.md, "Imports at
#: module top"), in ms: ``python -X importtime -c "import X"``, the cumulative times of the
#: entries Python's own start lacks, median of 6 fresh processes (two sets of 3) on this
#: 2-core machine, shared (single runs move by up to a factor of 2). The bar is 2 ms, 2 %
#: of ``nylonflex --help`` (0.09 CPU-s, 55 ms of imports). A key names a module and all
#: under it, unless a longer key names a submodule that costs more. Not here (under 2 ms):
#: threading 1.9, copy 1.6, signal 1.4, weakref 1.2, isal 1.1, csv 1.1, zlib 0.8, math 0.6,
#: fcntl 0.5, and the modules Python's start loads (os, re, pathlib, functools, ...).
HEAVY_IMPORTS = {
    "numpy": 174,
    "numba": 675,
    "numba.np.linalg": 89,  # beyond numba
    "numba.np.arraymath": 855,  # beyond numba, with its BLAS probe's scipy.linalg
    "llvmlite.ir": 8,
    "scipy": 198,
    "scipy.integrate": 942,
    "scipy.optimize": 1220,
    "scipy.sparse": 622,  # scipy.sparse.linalg 860
    "scipy.special": 619,
    "scipy.stats": 2269,
    "matplotlib": 614,  # matplotlib.figure 1306, backends.backend_agg 1160, tri 884
    "bokeh": 119,  # bokeh.plotting 1319, server.server 1464
    "dask": 318,  # dask.array 1879
    "distributed": 944,
    "SALib": 761,  # SALib.sample 844
    "felupe": 1213,
    "pypardiso": 621,
    "h5py": 289,
    "h5netcdf": 311,
    "hdf5plugin": 345,
    "xarray": 1038,
    "pandas": 582,
    "netCDF4": 221,  # the tests' reader; the package writes netCDF-4 through h5py
    "yaml": 26,
    "pydantic": 102,
    "tqdm": 128,
    "psutil": 40,
    "shtab": 70,  # the shell completion alone (cli/completion.py)
    "zstandard": 13,
    "isal.isal_zlib": 5,
    # the standard library's
    "asyncio": 94,
    "importlib.metadata": 82,
    "importlib.resources": 23,
    "inspect": 16,
    "multiprocessing": 15,
    "dataclasses": 14,
    "concurrent.futures": 14,
    "concurrent.futures.process": 34,  # beyond concurrent.futures: multiprocessing's queues
    "logging": 12,
    "secrets": 12,
    "subprocess": 10,
    "tempfile": 9,
    "socket": 8,
    "pkgutil": 7,
    "fractions": 6,
    "hashlib": 6,
    "uuid": 6,
    "shutil": 5,
    "typing": 5,
    "platform": 4,
    "json": 4,
    "argparse": 3,
    "html": 3,
    "datetime": 3,
    "difflib": 2,
}


#: Modules some platforms lack, imported where they are used: ``fcntl`` (POSIX) locks a
#: cube being written; reading one (``nylonflex info``, which loads the journal) needs none.
PLATFORM_IMPORTS = ("fcntl",)


def _heavy_key(name: str) -> str | None:
    """The key of :data:`HEAVY_IMPORTS` a dotted module name falls under (the longest)."""
    parts = name.split(".")
    return next((".".join(parts[:i]) for i in range(len(parts), 0, -1)
                 if ".".join(parts[:i]) in HEAVY_IMPORTS), None)


def _lazy_names(path: Path, module: str) -> dict[str, str]:
    """A package's names imported on first use (PEP 562: ``_LAZY``, ``_WHERE``): name ->
    the nylonflex module that defines it."""
    out = {}
    tree = ast.parse(path.read_text())
    if path.name != "__init__.py" or not any(
            isinstance(n, ast.FunctionDef) and n.name == "__getattr__" for n in tree.body):
        return out
    for node in tree.body:
        if isinstance(node, ast.Assign) and isinstance(node.value, ast.Dict):
            for key, value in zip(node.value.keys, node.value.values):
                if isinstance(key, ast.Constant) and isinstance(value, ast.Constant) \
                        and isinstance(value.value, str):
                    level = len(value.value) - len(value.value.lstrip("."))
                    anchor = module.split(".")[:len(module.split(".")) - max(level - 1, 0)]
                    out[key.value] = _resolve(".".join([*anchor, value.value.lstrip(".")]))
    return out


def _import_statements(path: Path):
    """``(node, in_function)`` for each import statement of a module."""
    out = []

    def visit(node, in_function):
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.Import, ast.ImportFrom)):
                out.append((child, in_function))
            visit(child, in_function or isinstance(child, (ast.FunctionDef,
                                                           ast.AsyncFunctionDef, ast.Lambda)))

    visit(ast.parse(path.read_text()), False)
    return out


def _loads(node, path: Path, module: str, lazy: dict) -> tuple[set[str], set[str]]:
    """The nylonflex modules (with the packages above them) and the heavy keys one import
    statement loads."""
    if isinstance(node, ast.Import):
        names = [a.name for a in node.names]
    else:
        package = module if path.name == "__init__.py" else module.rpartition(".")[0]
        base = node.module or ""
        if node.level:
            anchor = package.split(".")
            anchor = anchor[:len(anchor) - (node.level - 1)]
            base = ".".join([*anchor, base] if base else anchor)
        names = [f"{base}.{a.name}" for a in node.names]
    ours, heavy = set(), set()
    for name in names:
        if name.split(".")[0] in PLATFORM_IMPORTS:
            heavy.add(name.split(".")[0])
        elif name.split(".")[0] != "nylonflex":
            if _heavy_key(name):
                heavy.add(_heavy_key(name))
            continue
        target = _resolve(name)
        owner, _, attr = name.rpartition(".")
        if target == owner and attr in lazy.get(owner, {}):
            target = lazy[owner][attr]  # ``from package import name``: its module, lazily
        parts = target.split(".")
        ours.update(".".join(parts[:i]) for i in range(1, len(parts) + 1))
    return ours, heavy


def _function_level_imports():
    """``(where, statement, heavy keys it would add at module top)`` for each import inside
    a function, with what each module's module-top imports load (transitively)."""
    modules = dict((m, p) for p, m in _modules())
    lazy = {m: _lazy_names(p, m) for m, p in modules.items()}
    top, inner = {}, []
    for module, path in modules.items():
        parts = module.split(".")
        ours = {".".join(parts[:i]) for i in range(1, len(parts))}  # its packages load first
        heavy = set()
        for node, in_function in _import_statements(path):
            loaded = _loads(node, path, module, lazy)
            if in_function:
                inner.append((module, path, node, loaded))
            else:
                ours |= loaded[0]
                heavy |= loaded[1]
        top[module] = (ours - {module}, heavy)
    reach: dict[str, set[str]] = {}

    def reaches(module):  # the heavy keys a module's import loads (no circles: tested above)
        if module not in reach:
            reach[module] = set()
            ours, heavy = top.get(module, ((), ()))
            reach[module] = set(heavy).union(*(reaches(m) for m in ours))
        return reach[module]

    for module, path, node, (ours, heavy) in inner:
        adds = set(heavy).union(*(reaches(m) for m in ours)) - reaches(module)
        yield (f"{path.relative_to(PKG.parent)}:{node.lineno}", ast.unparse(node), adds)


def test_imports_sit_at_module_top_unless_they_are_heavy():
    # a function imports only what would cost a light command (or `import nylonflex`)
    # time at module top: a heavy module, or a nylonflex module that loads one, that the
    # module's own top does not load already. Everything else is imported at module top.
    wrong = [f"{where}: {statement} (loads nothing slow that the module does not)"
             for where, statement, adds in _function_level_imports() if not adds]
    assert not wrong, "move to module top: " + "; ".join(wrong)


def test_the_import_rule_fails_on_a_cheap_function_level_import():
    # a probe module (outside the physics and kernels, whose sources name the model): numpy
    # at its top; in a function a cheap module, numpy again, a module its own package
    # loads already, and two heavy ones
    bad = PKG / "query" / "_import_probe.py"
    bad.write_text("import numpy\n\n\ndef f():\n    import json\n    import numpy as np\n"
                   "    from . import scan\n    import scipy.optimize\n"
                   "    from ..kernels import design\n")
    try:
        adds = {statement: heavy for where, statement, heavy in _function_level_imports()
                if where.startswith("nylonflex/query/_import_probe.py")}
        assert adds["import json"] == adds["import numpy as np"] == set()
        assert adds["from . import scan"] == set()
        assert adds["import scipy.optimize"] == {"scipy.optimize"}
        assert "numba" in adds["from ..kernels import design"]
        with pytest.raises(AssertionError, match=r"_import_probe.py:5: import json .*"
                           r"_import_probe.py:6: import numpy as np .*"
                           r"_import_probe.py:7: from . import scan \("):
            test_imports_sit_at_module_top_unless_they_are_heavy()
    finally:
        bad.unlink()


def test_the_private_name_check_fails_on_a_private_import():
    bad = PKG / "cli" / "_private_probe.py"
    bad.write_text("import nylonflex.charts._common\n\n\ndef f():\n"
                   "    from ..storage.cube import _chunks\n    from . import _common\n")
    try:
        found = {f for f in _private_imports() if f.startswith("cli._private_probe")}
        assert found == {"cli._private_probe -> charts._common",
                         "cli._private_probe -> storage.cube._chunks"}
    finally:
        bad.unlink()
