"""The compiled kernels against the physics functions (rtol 1e-9, docs/model.md section 11)."""

import math
import platform
import re

import numba
import numpy as np
import pytest

from nylonflex import design_limits
from nylonflex.config import parse_config
from nylonflex.kernels import _compile  # noqa: F401  (registers the formulas with Numba)
from nylonflex.materials import SILICONE_PARAMETERS, silicone_parameters
from nylonflex.physics import bending, chamber, elementary, nylon, wrap
from nylonflex.physics.elementary import _exp, _log
from nylonflex.engine.grid import compute_slab
from nylonflex.sweep.conductor import run_sweep
from nylonflex.variables import SUPPLY_ONLY

IRREGULAR = {
    "name": "irregular",
    "silicone": "tc5005",
    "grid": {
        "radius": {"values": [5, 6.3, 11.7, 24.9], "units": "mm"},
        "wall_thickness": {"values": [1, 2.5, 6], "units": "mm"},
        "length": {"values": [40, 90, 151], "units": "mm"},
        "coil_index": {"values": [1.1, 1.25, 1.7]},
        "wrap_angle": {"values": [3, 8, 21, 29], "units": "deg"},
    },
    "curves": {"stroke": {"values": [0, 0.013, 0.05, 0.099]},
               "pressure": {"values": [0, 0.7, 9, 33, 60], "units": "kPa"}},
}


@pytest.fixture(scope="module", params=["wall", "fixed", "ecoflex_00_30"])
def cube(request):
    raw = dict(IRREGULAR)
    if request.param == "fixed":
        raw["base_thickness"] = {"value": 1.7, "units": "mm"}
    if request.param == "ecoflex_00_30":
        raw["silicone"] = "ecoflex_00_30"
    cfg = parse_config(raw)
    return cfg, run_sweep(cfg)


def test_design_variables_match_design_limits_everywhere(cube):
    cfg, ds = cube
    grids = np.meshgrid(*cfg.axes.values(), indexing="ij")
    exact = design_limits(*grids, base_thickness=cfg.base_thickness, silicone=cfg.silicone,
                          nylon=cfg.nylon)
    for name, expected in exact.items():
        if name not in ds:  # heating_time and the dynamics: only in a cube with a supply
            assert name in SUPPLY_ONLY and np.all(np.isnan(expected))
            continue
        got = ds[name].values
        if name in ("limit", "validity"):
            np.testing.assert_array_equal(got, expected)
        else:
            np.testing.assert_allclose(got, expected, rtol=1e-9, atol=0, err_msg=name)
    assert set(ds["limit"].values.ravel()) == {0, 1}  # the grid covers both regimes


def test_curves_match_physics(cube):
    cfg, ds = cube
    a, t, L, c, psi = cfg.axes.values()
    s, p = cfg.curves["stroke"], cfg.curves["pressure"]
    b = t if cfg.base_thickness is None else np.full_like(t, cfg.base_thickness)
    A, T, C, PSI, S = np.meshgrid(a, t, c, psi, s, indexing="ij")
    B = np.broadcast_to(b[None, :, None, None, None], A.shape)
    np.testing.assert_allclose(
        ds["nylon_force"].values,
        wrap.nylon_force(S, A, T, PSI, C, B, silicone=cfg.silicone), rtol=1e-12)
    A, T, LL, P = np.meshgrid(a, t, L, p, indexing="ij")
    B = np.broadcast_to(b[None, :, None, None], A.shape)
    np.testing.assert_allclose(ds["bend_angle"].values,
                               bending.bend_angle(P, A, T, LL, B, cfg.silicone), rtol=1e-9)
    np.testing.assert_allclose(ds["tip_force"].values, bending.tip_force(P, A, LL, B),
                               rtol=1e-14)
    np.testing.assert_allclose(ds["chamber_pressure"].values, chamber.chamber_pressure(s),
                               rtol=1e-15)
    np.testing.assert_allclose(ds["nylon_force_limit"].values, nylon.nylon_force_limit(c),
                               rtol=1e-15)


def test_serial_and_threaded_kernels_agree_bitwise():
    cfg = parse_config(IRREGULAR)
    par = compute_slab(cfg, 1, 4, parallel=True)
    ser = compute_slab(cfg, 1, 4, parallel=False)
    for name in par:
        np.testing.assert_array_equal(par[name], ser[name], err_msg=name)


def test_slabs_do_not_change_results():
    cfg = parse_config(IRREGULAR)
    whole = compute_slab(cfg, 0, 4)
    parts = [compute_slab(cfg, i, i + 1) for i in range(4)]
    for name in whole:
        np.testing.assert_array_equal(whole[name], np.concatenate([p[name] for p in parts]))


# --- the section moment's SIMD-friendly log and exp, and the Halley solve (docs/model.md
# s. 12) ---------------------------------------------------------------------------------


@numba.njit(error_model="numpy")
def _logs_and_exps(x, out_log, y, out_exp):
    for i in range(x.shape[0]):
        out_log[i] = _log(x[i])
    for i in range(y.shape[0]):
        out_exp[i] = _exp(y[i])


def test_log_and_exp_are_within_an_ulp_of_the_c_library_compiled_or_not():
    rng = np.random.default_rng(3)
    x = np.concatenate([np.exp(rng.uniform(-700.0, 700.0, 200_000)),
                        1.0 + rng.uniform(0.0, 4.0, 200_000), 1.0 + rng.uniform(0, 1e-6, 10_000),
                        [1.0, 2.0, math.sqrt(2.0), 5e-308, 1.7e308]])
    y = np.concatenate([rng.uniform(-745.0, 709.7, 200_000), rng.uniform(-40.0, 40.0, 200_000),
                        [0.0, -0.0, 1e-300, -1e-300, 709.78]])
    out_log, out_exp = np.empty_like(x), np.empty_like(y)
    _logs_and_exps(x, out_log, y, out_exp)
    libm_log = np.array([math.log(v) for v in x])
    libm_exp = np.array([math.exp(v) for v in y])
    assert np.all(np.abs(out_log - libm_log) <= np.spacing(np.abs(libm_log))), "log"
    assert out_log[x == 1.0][0] == 0.0
    normal = libm_exp > 2.2250738585072014e-308  # below it the C library's is subnormal too
    assert np.all(np.abs(out_exp - libm_exp)[normal] <= np.spacing(libm_exp[normal])), "exp"
    # the same bits uncompiled (the physics layer's reference runs them as Python)
    for i in rng.choice(x.size, 300):
        assert elementary._log(float(x[i])) == out_log[i]
    for i in rng.choice(y.size, 300):
        assert elementary._exp(float(y[i])) == out_exp[i]
    specials = np.array([800.0, 710.0, -746.0, -800.0, math.inf, -math.inf, math.nan])
    got = np.empty_like(specials)
    _logs_and_exps(np.array([math.nan]), np.empty(1), specials, got)
    np.testing.assert_array_equal(got, [math.inf, math.inf, 0.0, 0.0, math.inf, 0.0, math.nan])
    assert math.isnan(elementary._log(math.nan)) and math.isnan(elementary._exp(math.nan))


@pytest.mark.parametrize("name", list(SILICONE_PARAMETERS))
@pytest.mark.parametrize("cauchy", [False, True])
def test_section_moment_and_its_two_derivatives(name, cauchy):
    mu, alpha = silicone_parameters(name).arrays()
    y, wy, wyy, work = bending._node_table(12e-3, 3e-3, 3e-3, *bending.quadrature_nodes())

    def numpy_moment(kappa):  # the sums of docs/model.md s. 12 with NumPy's powers
        lam = 1.0 + kappa * y
        s = sum(m * (lam ** (a - 1) - lam ** (-a - 1)) for m, a in zip(mu, alpha))
        ds = sum(m * ((a - 1) * lam ** (a - 2) + (a + 1) * lam ** (-a - 2))
                 for m, a in zip(mu, alpha))
        d2s = sum(m * ((a - 1) * (a - 2) * lam ** (a - 3) - (a + 1) * (a + 2) * lam ** (-a - 3))
                  for m, a in zip(mu, alpha))
        if cauchy:
            s, ds, d2s = lam * s, s + lam * ds, 2 * ds + lam * d2s
        return np.sum(wy * s), np.sum(wyy * ds), np.sum(wyy * y * d2s)

    for kappa in (0.5, 20.0, 120.0):
        got = bending._section_moment(kappa, y, wy, wyy, work, mu, alpha, cauchy)
        np.testing.assert_allclose(got, numpy_moment(kappa), rtol=1e-12)
        h = 1e-4 * kappa  # and the derivatives are M_S's: central differences, O(h^2)
        up = bending._section_moment(kappa + h, y, wy, wyy, work, mu, alpha, cauchy)
        down = bending._section_moment(kappa - h, y, wy, wyy, work, mu, alpha, cauchy)
        assert got[1] == pytest.approx((up[0] - down[0]) / (2 * h), rel=1e-6)
        assert got[2] == pytest.approx((up[1] - down[1]) / (2 * h), rel=1e-6)


def test_curvature_solve_stops_after_one_evaluation_from_a_close_start(monkeypatch):
    # Halley's error after a step delta is ~C delta^3 / kappa^2 with C <= 3.4: a step below
    # 1e-6 kappa is accepted without evaluating again (docs/model.md s. 12)
    mu, alpha = silicone_parameters("ecoflex_00_30").arrays()
    y, wy, wyy, work = bending._node_table(9e-3, 1.2e-3, 1.2e-3, *bending.quadrature_nodes())
    moment = bending._pressure_moment(12e3, 9e-3, 1.2e-3)
    args = (y, wy, wyy, work, mu, alpha)
    exact = bending._curvature_solve(moment, *args, 0.0, 1e-13, False)[0]
    evaluations = []
    moment_of = bending._section_moment
    monkeypatch.setattr(bending, "_section_moment",
                        lambda *a: evaluations.append(a[0]) or moment_of(*a))
    for start, count in ((1 + 5e-7, 1), (1 - 5e-7, 1), (1 + 3e-5, 2), (1.3, 3)):
        evaluations.clear()
        kappa, dm, d2m = bending._curvature_solve(moment, *args, exact * start,
                                                  bending.NEWTON_RTOL, False)
        assert len(evaluations) == count, start
        assert kappa == pytest.approx(exact, rel=3e-15, abs=0.0), start
    # a step below an ulp of kappa stays in the bracket (it used to start doubling)
    evaluations.clear()
    assert bending._curvature_solve(moment, *args, exact, bending.NEWTON_RTOL, False)[0] \
        == pytest.approx(exact, rel=3e-15, abs=0.0)
    assert len(evaluations) == 1


@pytest.mark.skipif(numba.config.DISABLE_JIT, reason="reads the compiled code "
                    "(.ci/run runs this file with NUMBA_DISABLE_JIT=1 to measure the "
                    "kernels' Python bodies)")
def test_section_moment_compiles_to_a_loop_without_calls_to_log_or_exp():
    # the condition for LLVM to vectorise it: this llvmlite has no vector log or exp (SVML)
    @numba.njit(error_model="numpy")
    def moment(kappa, y, wy, wyy, work, mu, alpha):
        return bending._section_moment(kappa, y, wy, wyy, work, mu, alpha, False)

    mu, alpha = silicone_parameters("tc5005").arrays()
    moment(10.0, *bending._node_table(8e-3, 2e-3, 2e-3, *bending.quadrature_nodes()), mu, alpha)
    asm = next(iter(moment.inspect_asm().values()))
    assert not re.search(r"\$_*(log|exp)\b", asm)
    if platform.machine().lower() in ("x86_64", "amd64"):
        assert re.search(r"\bv?mulpd\b", asm)  # packed: the node loops are vectorised


def test_loading_the_kernels_skips_numbas_scipy_linalg_probe():
    # Numba's arraymath imports scipy.linalg only to set _HAVE_BLAS; the kernels' module
    # has that probe look for scipy's BLAS module on disk instead. Run in a fresh
    # interpreter: this test process has scipy.linalg already.
    import subprocess
    import sys

    code = (
        "import sys, importlib.util\n"
        "from nylonflex.kernels import _compile\n"
        "from numba.np import arraymath\n"
        "assert 'scipy.linalg' not in sys.modules, 'scipy.linalg was imported'\n"
        "assert arraymath._HAVE_BLAS is (importlib.util.find_spec('scipy') is not None)\n"
        "from numba.np import linalg\n"  # Numba's own probe is back, in both modules
        "assert linalg.ensure_blas.__module__ == 'numba.np.linalg'\n"
        "assert arraymath.ensure_blas is linalg.ensure_blas\n"
        "import scipy.linalg.cython_blas\n"  # still importable afterwards
        "from scipy import linalg\n"
        "assert abs(linalg.det([[2.0, 0.0], [0.0, 3.0]]) - 6.0) < 1e-12\n"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert _compile._scipy_blas_installed() is True  # scipy is a dependency


def test_the_kernels_output_rows_are_the_registrys_order():
    # issue 28: the row of every kernel output comes from one table (kernels/rows.py),
    # derived from the registry: each float design variable, flag and tracking variable
    # has exactly one ROW_ constant, each table's rows are 0..n-1 in the registry's order,
    # and no ROW_ constant names anything else
    from nylonflex.engine import grid
    from nylonflex.kernels import rows
    from nylonflex.variables import DESIGN, TRACKING

    tables = [([n for n, v in DESIGN.items() if v.dtype == "float64"], rows.DESIGN_ROWS),
              ([n for n, v in DESIGN.items() if v.dtype == "int8"], rows.FLAG_ROWS),
              (list(TRACKING), rows.TRACKING_ROWS)]
    assert sorted(tables[0][0] + tables[1][0]) == sorted(DESIGN)
    expected = {}
    for names, table in tables:
        assert list(table) == names
        assert list(table.values()) == list(range(len(names)))
        expected.update({f"ROW_{n.upper()}": row for row, n in enumerate(names)})
    assert len(expected) == sum(len(names) for names, _ in tables)  # no name in two tables
    assert {n: getattr(rows, n) for n in dir(rows) if n.startswith("ROW_")} == expected
    assert (rows.N_FLOAT_DESIGN, rows.N_FLAGS, rows.N_TRACKING) == \
        tuple(len(names) for names, _ in tables)
    assert list(rows.FLOAT_DESIGN) == tables[0][0] and grid.FLOAT_DESIGN is rows.FLOAT_DESIGN


@pytest.mark.parametrize("module, function, arrays", [
    ("design", "_design_slab", {"out_design": "DESIGN_ROWS", "out_flags": "FLAG_ROWS"}),
    ("design", "_design_points", {"out_design": "DESIGN_ROWS", "out_flags": "FLAG_ROWS"}),
    ("tracking", "_track_slab", {"out": "TRACKING_ROWS"})])
def test_each_kernel_writes_every_row_once_by_its_constant(module, function, arrays):
    # every write into a kernel's output array indexes it by a ROW_ constant, each row of
    # the table is written exactly once, and (but for the validity bits, computed in the
    # write) from the local named after its variable
    import ast
    from pathlib import Path

    from nylonflex.kernels import rows

    path = Path(rows.__file__).with_name(f"{module}.py")
    body = next(node for node in ast.parse(path.read_text()).body
                if isinstance(node, ast.FunctionDef) and node.name == function)
    written = {name: [] for name in arrays}
    for node in ast.walk(body):
        if not isinstance(node, ast.Assign):
            continue
        for target in node.targets:
            if isinstance(target, ast.Subscript) and isinstance(target.value, ast.Name) \
                    and target.value.id in arrays:
                first = target.slice.elts[0]
                assert isinstance(first, ast.Name) and first.id.startswith("ROW_"), \
                    f"{function}: {ast.unparse(target)} is not indexed by a ROW_ constant"
                written[target.value.id].append(first.id)
                if isinstance(node.value, ast.Name):
                    assert f"ROW_{node.value.id.upper()}" == first.id, ast.unparse(node)
                else:
                    assert first.id == "ROW_VALIDITY", ast.unparse(node)
    for array, table in arrays.items():
        assert sorted(written[array]) == sorted(f"ROW_{n.upper()}"
                                                for n in getattr(rows, table))


def _twice(x):
    return 2.0 * x


def _twice_plus_one(x):
    return _twice(x) + 1.0


def _calls_both(x, out):
    out[0] = _twice(x) + _twice_plus_one(x)


@pytest.mark.skipif(numba.config.DISABLE_JIT, reason="counts Numba's compiles")
@pytest.mark.parametrize("callee_body, compiles", [(False, 2), (True, 1)])
def test_a_callee_body_kernel_compiles_each_formula_once(callee_body, compiles, monkeypatch):
    # a formula called by the kernel itself and through another formula: Numba keys a
    # callee on its caller's flags, so it compiles twice unless the kernel's body is a
    # callee too (jit_kernel(callee_body=True))
    from numba.core import event
    from numba.extending import register_jitable

    monkeypatch.setitem(_compile.JIT_OPTIONS, "cache", False)
    for f in (_twice, _twice_plus_one):
        # fresh copies: Numba's overload cache belongs to the function object
        globals()[f.__name__] = type(f)(f.__code__, globals(), f.__name__)
        register_jitable(**_compile.CALLEE_OPTIONS)(globals()[f.__name__])
    body = type(_calls_both)(_calls_both.__code__, globals(), "_calls_both")
    kernel = _compile.jit_kernel(body, callee_body=callee_body)
    assert kernel.py_func.__name__ == "_calls_both"
    assert kernel.py_func.__code__.co_varnames[:2] == ("x", "out")
    names = []

    class Count(event.Listener):
        def on_start(self, ev):
            names.append(ev.data["dispatcher"].py_func.__name__)

        def on_end(self, ev):
            pass

    out = np.zeros(1)
    with event.install_listener("numba:compile", Count()):
        kernel(3.0, out)
    assert out[0] == 6.0 + 7.0
    assert names.count("_twice") == compiles


def test_a_callee_body_kernel_takes_plain_positional_parameters():
    def with_default(x, y=1.0):
        return x + y

    with pytest.raises(TypeError, match="plain positional parameters"):
        _compile.jit_kernel(with_default, callee_body=True)

    def keyword_only(x, *, y):
        return x + y

    with pytest.raises(TypeError, match="plain positional parameters"):
        _compile.jit_kernel(keyword_only, callee_body=True)


def _fill_and_sum(kappa, y, work, mu):
    # loops over an array argument that Numba's reference-count pruning cannot see through
    for i in range(y.shape[0]):
        work[0, i] = 1.0 + kappa * y[i]
    for j in range(mu.shape[0]):
        for i in range(y.shape[0]):
            work[0, i] += mu[j]
    total = 0.0
    for i in range(y.shape[0]):
        total += work[0, i]
    return total


def _sums(kappas, y, work, mu, out):
    for k in range(kappas.shape[0]):
        out[k] = _fill_and_sum(kappas[k], y, work, mu)


def _makes_an_array(n):
    return np.empty(n).shape[0]


def _calls_maker(n, out):
    out[0] = _makes_an_array(n)


def _reference_counts(kernel) -> int:
    """Calls of NRT_incref and NRT_decref in what ``kernel`` calls: its body (a callee,
    jit_kernel(callee_body=True)) and the formulas, not the Python-facing wrapper, which
    counts the arrays it is given once a call."""
    ir = kernel.inspect_llvm(kernel.signatures[0])
    callees = [f for f in re.split(r"\n(?=define )", ir)
               if f.startswith("define linkonce_odr") and "@NRT_" not in f.split("\n")[0]]
    assert callees  # the body, and the formula where LLVM did not inline it
    return sum(len(re.findall(r"call void @NRT_(?:incref|decref)\(", f)) for f in callees)


@pytest.mark.skipif(numba.config.DISABLE_JIT, reason="reads Numba's compiled code")
@pytest.mark.parametrize("borrows", [False, True])
def test_a_borrowing_kernel_counts_no_references_in_its_formulas(borrows, monkeypatch):
    # each call of a formula that takes arrays counted them up and down, atomically (a
    # fifth of the grid kernel's time); a borrowing kernel's formulas count nothing
    from numba.extending import register_jitable

    monkeypatch.setitem(_compile.JIT_OPTIONS, "cache", False)
    globals()["_fill_and_sum"] = type(_fill_and_sum)(_fill_and_sum.__code__, globals(),
                                                     "_fill_and_sum")
    register_jitable(**_compile.CALLEE_OPTIONS)(globals()["_fill_and_sum"])
    body = type(_sums)(_sums.__code__, globals(), "_sums")
    kernel = _compile.jit_kernel(body, callee_body=True, borrows=borrows)
    y, mu, out = np.linspace(0.0, 1e-2, 16), np.array([1.0, 2.0]), np.zeros(3)
    kernel(np.array([0.0, 1.0, 2.0]), y, np.zeros((1, 16)), mu, out)
    np.testing.assert_array_equal(out, [_fill_and_sum(k, y, np.zeros((1, 16)), mu)
                                        for k in (0.0, 1.0, 2.0)])
    counts = _reference_counts(kernel)
    assert (counts == 0) if borrows else (counts > 0)


@pytest.mark.skipif(numba.config.DISABLE_JIT, reason="compiles with Numba")
def test_a_borrowing_kernel_cannot_call_a_formula_that_makes_an_array(monkeypatch):
    # without the runtime nothing could free the array: Numba refuses to compile it
    from numba.extending import register_jitable

    monkeypatch.setitem(_compile.JIT_OPTIONS, "cache", False)
    register_jitable(**_compile.CALLEE_OPTIONS)(_makes_an_array)
    body = type(_calls_maker)(_calls_maker.__code__, globals(), "_calls_maker")
    kernel = _compile.jit_kernel(body, callee_body=True, borrows=True)
    with pytest.raises(numba.core.errors.TypingError):
        kernel(3, np.zeros(1))
    with pytest.raises(TypeError, match="borrows needs callee_body"):
        _compile.jit_kernel(_calls_maker, borrows=True)


@pytest.mark.parametrize("base", ["wall", "fixed"])
def test_the_paper_kernel_gives_the_general_kernels_bits(base):
    # design_slab_paper is design_slab's source with the variants' and the supply's
    # branches pruned at compile time (a shorter first compile): on the paper's model
    # without a supply both write the same bits into every output
    from nylonflex.engine.model_slab import grid_axes, grid_out, kernel_inputs
    from nylonflex.kernels import design

    raw = dict(IRREGULAR)
    if base == "fixed":
        raw["base_thickness"] = {"value": 1.7, "units": "mm"}
    cfg = parse_config(raw)
    n = len(cfg.axes["radius"])
    grid, inputs = grid_axes(cfg, 0, n), kernel_inputs(cfg, 0)
    assert design.grid_kernel(inputs[-1].model, inputs[-1].voltage) is \
        design.design_slab_paper
    outs = []
    for kernel in (design.design_slab, design.design_slab_paper):
        out = grid_out(cfg, n)
        for array in out:
            array.fill(-7)  # every output is written
        kernel(grid, *inputs, out, design.grid_scratch(grid, inputs[2]), 0,
               n * len(cfg.axes["wall_thickness"]))
        outs.append(out)
    for a, b, name in zip(*outs, type(outs[0])._fields):
        assert not np.any(b == -7), name
        np.testing.assert_array_equal(a.view(np.uint8), b.view(np.uint8), err_msg=name)
    # a variant or a supply runs the general kernel
    assert design.grid_kernel(1, -1.0) is design.design_slab
    assert design.grid_kernel(0, 12.0) is design.design_slab
