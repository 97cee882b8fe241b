"""The import-layering contract: imports point down, never back, and never in a circle.

Each module of the package sits in one of the named layers of :data:`NAMED_LAYERS`, lowest
first: foundation (units) <- files <- registry (variables) <- material files <- materials
<- condition grammar <- config <- physics <- simulate config <- kernels <- engine <-
simulation <- outputs (storage, charts, query) <- finite elements <- applications
(calibration, design, explore, uncertainty, the JSON Schema) <- cli. An import of another
nylonflex module must reach a lower layer (or its own package). The physics imports
neither numba, xarray nor matplotlib.
"""

import ast
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parents[1] / "nylonflex"

#: The layers, lowest first: a name, and the top-level modules and subpackages in it.
#: Same-layer imports are allowed only inside one subpackage. A module of a subpackage may
#: have a layer of its own: lower than its package (``query.parse``, the condition grammar
#: the config reads, needs only units and variables; ``config.safe_yaml``,
#: ``config.material_files`` and ``storage.files``, which the materials and the config read
#: and write through; the simulate config ``config.simulate``, which checks a supply
#: against the physics) or higher (``config.schema``, the JSON Schema of every config).
NAMED_LAYERS = (
    ("foundation", ("_version", "units")),
    ("files", ("config.safe_yaml", "storage.files", "examples")),
    ("registry", ("variables",)),
    ("material files", ("config.material_files",)),
    ("materials", ("materials",)),
    ("condition grammar", ("query.parse",)),
    ("config", ("config",)),
    ("physics", ("physics",)),
    ("simulate config", ("config.simulate",)),
    ("kernels", ("kernels",)),
    ("engine", ("engine",)),
    ("simulation", ("sim",)),
    ("outputs", ("storage", "charts", "query")),
    ("finite elements", ("fe",)),
    ("applications", ("calibration", "design", "explore", "uncertainty", "config.schema")),
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
    """The top-level module or subpackage of a dotted nylonflex name (None: the root), or
    the module of a subpackage that has a layer of its own (``query.parse``)."""
    parts = name.split(".")
    if len(parts) > 2 and ".".join(parts[1:3]) in LAYERS:
        return ".".join(parts[1:3])
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


def test_charts_compute_no_physics():
    for path, module, target in _edges():
        if _unit(module) == "charts":
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
#: cube through h5py), ``chart --help`` nothing that draws or reads.
_HEAVY = {
    "info": ("numba", "dask", "xarray", "pandas", "nylonflex.engine"),
    "query": ("numba", "dask", "nylonflex.kernels"),
    "chart": ("numba", "dask", "xarray", "matplotlib", "h5py"),
    "list": ("numba", "dask", "xarray", "h5py"),
    "init": ("numba", "dask", "xarray", "h5py"),
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
    # the kernels compile the physics' private Numba formulas by name (their one exception)
    found = {f for f in _private_imports()
             if not f.startswith(("kernels.design -> physics.", "kernels.control -> physics.",
                                  "kernels.tracking -> physics."))}
    assert not found, "private names imported across packages: " + "; ".join(sorted(found))


#: The modules the package root holds (issue 28); everything else lives in a subpackage.
ROOT = {"__init__", "__main__", "_version", "errors", "materials", "units", "variables"}

#: The subpackages the package root holds (issue 28). The benchmarks and the slow reference
#: are not among them: they live in the repository's benchmarks/ and tests/naive.py.
SUBPACKAGES = {"physics", "kernels", "engine", "storage", "config", "query", "sim",
               "calibration", "uncertainty", "design", "charts", "explore", "fe", "cli",
               "examples"}


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
