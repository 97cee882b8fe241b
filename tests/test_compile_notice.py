"""The compile notice (issue 25): said when Numba really compiles a kernel, never otherwise.

The signal is Numba's ``numba:compile`` event, raised only on a cache miss; a function
compiled here poses as a nylonflex kernel (its module is the control kernels'), so the
test compiles for real in well under a second.
"""

import json
import os
import signal
import sys
import threading
import warnings

import numba
import pytest

import nylonflex as nf
from nylonflex.engine.warmup import grid_families, warm_up_aside
from nylonflex.kernels import cache, compiling


@pytest.fixture
def fresh(monkeypatch, tmp_path):
    """No family noticed yet in this process, and the estimates and the marks of compiled
    families in temporary files."""
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setattr(compiling, "_NOTICED", set())
    monkeypatch.setattr(compiling, "_SECONDS", {})
    monkeypatch.setattr(compiling, "_record_path", lambda: str(tmp_path / "seconds.json"))
    return tmp_path / "seconds.json"


def _kernel():
    def posing(x):
        return x + 1

    posing.__module__ = "nylonflex.kernels.control"  # the family of the closed loop
    return numba.njit(cache=False)(posing)


def test_a_real_compile_notices_once_with_an_estimate_and_records_it(fresh):
    seen = []
    kernel = _kernel()
    with compiling.notices_to(seen.append):
        kernel(1)
        kernel(2)  # compiled already: no event
        _kernel()(3)  # another compile of the same family: no second line
    assert len(seen) == 1 and seen[0].startswith("compiling the closed-loop kernels")
    assert f"about {compiling.MEASURED['control']:.0f} s" in seen[0]  # nothing recorded yet
    recorded = json.loads(fresh.read_text())["control"]
    assert recorded >= 0 and compiling.compile_seconds()["control"] > 0
    assert cache.was_compiled("control") and not cache.was_compiled("grid")
    compiling._NOTICED.clear()
    with compiling.notices_to(seen.append):
        _kernel()(4)
    # this machine's figure ("0 s" read as no time at all: a short one is "under a second")
    took = "under a second" if recorded < 0.95 else f"{recorded:.0f} s"
    assert f"it took {took} here last time" in seen[1]


def test_the_python_api_gets_a_warning(fresh):
    with pytest.warns(nf.CompileWarning, match="compiling the closed-loop kernels"):
        _kernel()(1)


def test_no_notice_for_functions_that_are_not_nylonflex_kernels(fresh):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a notice would raise
        numba.njit(cache=False)(lambda x: x * 2)(3)
    assert compiling.compile_seconds() == {}


def test_the_cli_prints_the_warning_as_one_line(capsys, monkeypatch):
    from nylonflex import cli

    def run(args):
        warnings.warn("compiling the grid kernel (sweeps) ...", nf.CompileWarning)
        return 0

    monkeypatch.setattr(cli._module("info"), "run", run)
    assert cli.main(["info", "x.h5"]) == 0
    assert capsys.readouterr().err == "nylonflex info: compiling the grid kernel (sweeps) ...\n"


def test_each_kernel_family_is_known():
    from nylonflex.kernels import bytes as codec
    from nylonflex.kernels import control, design

    assert compiling.family(design.design_slab) == "grid_variants"
    assert compiling.family(design.design_slab_paper) == "grid"
    assert compiling.family(design.design_points) == "pointwise"
    assert compiling.family(control.closed_loop) == "control"
    assert compiling.family(codec._shuffle_bytes_jit) == "codec"
    assert set(compiling.MEASURED) == set(compiling.FAMILIES)


def test_warm_up_kernels_runs_each_kernel_once_and_reports_progress():
    # every engine kernel of warmup.KERNELS, in order, progress after each; a cached one
    # reports 0.0 s (the suite's cache is warm by now: the grid and pointwise tests ran)
    from nylonflex.engine.warmup import KERNELS, warm_up_kernels

    seen = []
    out = warm_up_kernels(["pointwise", "codec"], notice=lambda line: None,
                          progress=lambda done, total, name: seen.append((done, total, name)))
    assert seen == [(1, 2, "pointwise"), (2, 2, "codec")]
    assert set(out) == {"pointwise", "codec"} and all(v >= 0.0 for v in out.values())
    assert [k[0] for k in KERNELS] == ["grid", "grid_variants", "pointwise", "codec",
                                       "tracking"]


def test_a_tracking_sweep_after_the_warm_up_compiles_nothing():
    # what `nylonflex warmup` compiles for tracking is what a tracking sweep runs: after
    # it, another tracking config (a PI controller, a relative reference, the bandwidth
    # search) on another grid gets no compile notice (Numba's own signal)
    from pathlib import Path

    import yaml

    from nylonflex.config import parse_config
    from nylonflex.engine.warmup import warm_up_grid, warm_up_kernels

    warm_up_kernels(["tracking"], notice=lambda line: None)
    raw = yaml.safe_load((Path(__file__).parents[1] / "configs" /
                          "fig12_tracking.yaml").read_text())
    raw["tracking"].update(
        duration="0.3 s", rms_from="0 s",
        controller={"kind": "pi", "proportional_band": "10 deg", "integral_time": "20 s"},
        reference={"kind": "sine", "relative_to": "bend_angle_max", "mean": 0.5,
                   "amplitude": 0.2, "frequency": "1 Hz"},
        bandwidth={"error": "2 deg"})
    seen = []
    warm_up_grid(parse_config(raw), notice=seen.append)
    assert seen == []


def test_after_the_grid_warm_ups_no_sweep_compiles_its_grid_kernel():
    # a sweep of the paper's model alone without a supply runs design_slab_paper, any other
    # sweep design_slab: 'grid' and 'grid_variants' warm the two, and no sweep of either
    # kind compiles after them (Numba's own signal)
    from nylonflex.config import parse_config
    from nylonflex.engine.warmup import _TINY, warm_up_grid, warm_up_kernels

    warm_up_kernels(["grid", "grid_variants"], notice=lambda line: None)
    seen = []
    for extra in ({}, {"model": ["paper", "lateral_pressure"]},
                  {"supply": {"voltage": 9, "units": "V"}},
                  {"base_thickness": {"value": 3, "units": "mm"}}):
        warm_up_grid(parse_config({**_TINY, **extra}), notice=seen.append)
    assert seen == []


def test_the_warmup_command_names_every_kernel(capsys):
    from nylonflex.cli import main

    assert main(["warmup"]) == 0
    out = capsys.readouterr().out
    for name in ("grid", "grid_variants", "pointwise", "codec", "tracking", "control"):
        assert f" {name} " in out
    assert out.splitlines()[-1].startswith("warm: every kernel")


# --- a kernel compiled in a second process while this one goes on (warm_up_aside)

linux_only = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="fork: Linux")


@pytest.fixture
def empty_cache(monkeypatch, tmp_path):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.delenv("NYLONFLEX_NO_CACHE", raising=False)
    return tmp_path


def _child_compiles(folder, mark=True):
    """A stand-in for a kernel's compile: what the child did, in a file, and the family's
    mark, as a compile leaves it."""
    def warm():
        (folder / "child.txt").write_text(str(os.getpid()))
        if mark:
            cache.mark_compiled("grid")
    return warm


@linux_only
def test_an_uncompiled_kernel_compiles_in_a_child_while_this_process_goes_on(empty_cache):
    here = []
    seconds = warm_up_aside(_child_compiles(empty_cache), {"grid"},
                            lambda: here.append(os.getpid()))
    child = int((empty_cache / "child.txt").read_text())
    assert here == [os.getpid()] and child != os.getpid()
    assert seconds > 0 and cache.was_compiled("grid")


@linux_only
def test_a_compiled_kernel_forks_nothing(empty_cache):
    cache.mark_compiled("grid")
    here = []
    assert warm_up_aside(_child_compiles(empty_cache), {"grid"}, lambda: here.append(1)) == 0.0
    assert here == [1] and not (empty_cache / "child.txt").exists()


@linux_only
def test_a_family_left_uncompiled_forks(empty_cache):
    cache.mark_compiled("grid")
    warm_up_aside(_child_compiles(empty_cache), {"grid", "tracking"}, lambda: None)
    assert (empty_cache / "child.txt").exists()


@linux_only
def test_a_failed_child_leaves_the_compile_to_this_process(empty_cache):
    def fails():
        raise RuntimeError("no compiler")

    here = []
    assert warm_up_aside(fails, {"grid"}, lambda: here.append(1)) == 0.0
    assert here == [1] and not cache.was_compiled("grid")
    # a child that exits without the compile having left its mark: the same
    assert warm_up_aside(_child_compiles(empty_cache, mark=False), {"grid"}, lambda: None) == 0.0


@linux_only
def test_ctrl_c_stopping_the_child_stops_this_process(empty_cache):
    with pytest.raises(KeyboardInterrupt):
        warm_up_aside(lambda: os.kill(os.getpid(), signal.SIGINT), {"grid"}, lambda: None)


def test_no_fork_without_a_cache_or_beside_other_threads(empty_cache, monkeypatch):
    here = []

    def aside():
        return warm_up_aside(_child_compiles(empty_cache), {"grid"},
                             lambda: here.append(len(here)))

    monkeypatch.setenv("NYLONFLEX_NO_CACHE", "1")
    assert aside() == 0.0
    monkeypatch.delenv("NYLONFLEX_NO_CACHE")
    # a cache folder that cannot be made: the parent would compile again after the child
    (empty_cache / "a_file").write_text("")
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(empty_cache / "a_file" / "cache"))
    assert not cache.writable() and aside() == 0.0
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(empty_cache / "cache"))
    stop = threading.Event()
    other = threading.Thread(target=stop.wait)
    other.start()
    try:
        assert aside() == 0.0
    finally:
        stop.set()
        other.join()
    # meanwhile ran each time, here; no child ever ran
    assert here == [0, 1, 2] and not (empty_cache / "child.txt").exists()


def test_a_meanwhile_that_fails_still_reaps_the_child(empty_cache):
    def broken():
        raise ImportError("no matplotlib")

    def slow(folder=empty_cache):
        import time
        time.sleep(30)  # stopped long before: the caller stops, so does the child
        (folder / "child.txt").write_text("finished")

    with pytest.raises(ImportError):
        warm_up_aside(slow, {"grid"}, broken)
    with pytest.raises(ChildProcessError):
        os.waitpid(-1, os.WNOHANG)  # no child left behind
    assert not (empty_cache / "child.txt").exists()


def test_the_families_a_sweep_warms_up():
    from nylonflex.config import parse_config

    one = {"values": [1.3]}
    raw = {"name": "a", "grid": {"radius": {"values": [10], "units": "mm"},
                                 "wall_thickness": {"values": [2], "units": "mm"},
                                 "length": {"values": [90], "units": "mm"},
                                 "coil_index": one, "wrap_angle": {"values": [8], "units": "deg"}},
           "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 2},
                      "pressure": {"start": 0, "stop": 25, "num": 2, "units": "kPa"}}}
    assert grid_families(parse_config(raw)) == {"grid"}
    supplied = {**raw, "supply": {"voltage": 12, "units": "V"}}
    assert grid_families(parse_config(supplied)) == {"grid_variants"}
    tracked = {**supplied, "tracking": {
        "duration": "0.5 s", "step": "10 ms", "controller": {"kind": "bang_bang"},
        "reference": {"kind": "sine", "mean": "20 deg", "amplitude": "5 deg",
                      "frequency": "1 Hz"}}}
    assert grid_families(parse_config(tracked)) == {"grid_variants", "tracking"}


def test_a_mark_is_never_written_through_a_link(empty_cache):
    target = empty_cache / "someone_elses"
    os.makedirs(cache.cache_dir())
    os.symlink(target, os.path.join(cache.cache_dir(), "grid.compiled"))
    cache.mark_compiled("grid")
    assert not target.exists()
