"""The sweep's charts drawn by a process forked before the sweep (nylonflex.charts_ahead):
the same files as drawing here, errors and skips reported in the caller, and a process
that never outlives the sweep."""

import os
import signal
import sys
import time

import pytest
from conftest import write_cube

from nylonflex.charts_ahead import ChartsAhead
from nylonflex.cli import main
from nylonflex.units import InputError

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"),
                                reason="the process ahead is forked (Linux)")

SMALL = {
    "name": "ahead",
    "grid": {
        "radius": {"start": 5, "stop": 25, "num": 7, "units": "mm"},
        "wall_thickness": {"values": [2], "units": "mm"},
        "length": {"values": [90], "units": "mm"},
        "coil_index": {"values": [1.1, 1.7]},
        "wrap_angle": {"values": [5, 8], "units": "deg"},
    },
    "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 6},
               "pressure": {"start": 0, "stop": 25, "num": 6, "units": "kPa"}},
}


@pytest.fixture(scope="module")
def cube(tmp_path_factory):
    return write_cube(tmp_path_factory.mktemp("ahead"), SMALL)


def _no_children_left():
    with pytest.raises(ChildProcessError):
        os.waitpid(-1, os.WNOHANG)


def test_the_process_ahead_draws_the_same_files_as_this_process(cube, tmp_path):
    names = ["fig12b", "fig7", "fig4"]
    done = []
    with ChartsAhead() as ahead:
        assert ahead._pid is not None  # it really forked
        forked = ahead.draw(cube, names, tmp_path / "ahead",
                            progress=lambda k, n: done.append((k, n)))
    here = ChartsAhead(fork=False).draw(cube, names, tmp_path / "here")
    assert [p.name for p in forked] == [p.name for p in here] == \
        ["fig12b.png", "fig7.png", "fig4.png"]
    for a, b in zip(forked, here):
        assert a.read_bytes() == b.read_bytes()
    assert sorted(done) == [(1, 3), (2, 3), (3, 3)]  # progress reached this process
    _no_children_left()


def test_an_error_in_the_process_ahead_is_raised_here(cube, tmp_path):
    with ChartsAhead() as ahead, pytest.raises(InputError, match="unknown chart 'fig99'"):
        ahead.draw(cube, ["fig99"], tmp_path)
    _no_children_left()


def test_skipped_charts_are_reported_here(cube, tmp_path):
    # one wall thickness only: design_map plots over it, so it is skipped with a reason
    skipped = []
    with ChartsAhead() as ahead:
        paths = ahead.draw(cube, ["design_map", "fig4"], tmp_path, on_skip=skipped.append)
    assert [p.name for p in paths] == ["fig4.png"]
    assert len(skipped) == 1 and "design_map skipped" in skipped[0]


def test_a_process_ahead_that_died_is_replaced_by_drawing_here(cube, tmp_path):
    with ChartsAhead() as ahead:
        os.kill(ahead._pid, signal.SIGKILL)
        time.sleep(0.2)
        paths = ahead.draw(cube, ["fig4"], tmp_path)
    assert [p.name for p in paths] == ["fig4.png"] and paths[0].stat().st_size > 10_000
    _no_children_left()


def test_closing_without_drawing_ends_the_process_at_once():
    t0 = time.perf_counter()
    with ChartsAhead() as ahead:
        pid = ahead._pid
    # it was still importing matplotlib and xarray: close() did not wait for that
    assert time.perf_counter() - t0 < 0.5
    with pytest.raises(ChildProcessError):
        os.waitpid(pid, os.WNOHANG)


def test_a_bad_config_leaves_no_process_behind(tmp_path, capsys):
    bad = tmp_path / "bad.yaml"
    import yaml

    grid = {**SMALL["grid"], "radius": {"values": [5], "units": "furlong"}}
    bad.write_text(yaml.safe_dump({**SMALL, "grid": grid, "charts": ["fig4"]}))
    assert main(["sweep", str(bad), "--quiet"]) == 2
    assert "furlong" in capsys.readouterr().err
    _no_children_left()


def test_sweep_charts_through_the_process_ahead(tmp_path, capsys):
    import yaml

    cfg = tmp_path / "c.yaml"
    cfg.write_text(yaml.safe_dump({**SMALL, "charts": ["fig4", "design_map"]}))
    out = tmp_path / "run" / "cube.h5"
    assert main(["sweep", str(cfg), "--out", str(out), "--quiet"]) == 0
    captured = capsys.readouterr()
    assert str(out.parent / "fig4.png") in captured.out
    assert "design_map skipped" in captured.err  # printed by the command itself
    assert (out.parent / "fig4.png").stat().st_size > 10_000
    _no_children_left()


def test_the_sweep_command_leaves_the_garbage_collector_running(tmp_path):
    # it pauses the collector while it starts (imports) and freezes what that made
    import gc

    import yaml

    cfg = tmp_path / "c.yaml"
    cfg.write_text(yaml.safe_dump(SMALL))
    assert main(["sweep", str(cfg), "--out", str(tmp_path / "cube.h5"), "--quiet",
                 "--no-charts"]) == 0
    assert gc.isenabled() and gc.get_freeze_count() > 0
    gc.unfreeze()
