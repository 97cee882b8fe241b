"""The ``tracking:`` sweep: the figure-9 closed loop of every design (docs/model.md s. 19).

The reference is ``nylonflex simulate`` of the same design, computed live here (the
thermal constants may change under these tests): the sweep's tracking values equal its
metrics to 1e-9.
"""

import copy
import math

import numpy as np
import pytest
import yaml

import nylonflex as nf
from nylonflex.cli import main
from nylonflex.config import parse_config
from nylonflex.engine.grid import cube_variables, plan_slabs
from nylonflex.files.safe_yaml import read_yaml
from nylonflex.physics.thermal import coil_heat_loss_per_length
from nylonflex.sim import parse_sim_config, run_simulation
from nylonflex.units import InputError

CONTROL = "configs/control.yaml"

#: sweep variable -> simulate's metric of the same quantity
PAIRS = {"tracking_rms_error": "rms_error", "tracking_max_temperature": "temperature_max",
         "tracking_energy": "energy"}


def _sweep_of(sim: dict, designs=None) -> dict:
    """A sweep config whose grid is ``sim``'s design (or the ``designs`` axes' values) and
    whose tracking block is ``sim``'s loop."""
    d = sim["design"]
    one = lambda key: {"values": [d[key]]}  # noqa: E731 - quantities keep their units
    grid = {k: one(k) for k in ("radius", "wall_thickness", "length", "coil_index",
                                "wrap_angle")}
    grid.update(designs or {})
    tracking = {"duration": sim["time"]["duration"], "step": sim["time"]["step"],
                "reference": sim["reference"], "sensor": sim["sensor"],
                "estimator": sim["estimator"], "controller": sim["controller"],
                "rms_from": sim["metrics"]["rms_from"]}
    if "initial_temperature" in sim:
        tracking["initial_temperature"] = sim["initial_temperature"]
    out = {"name": "tracking_test", "silicone": sim["silicone"], "nylon": sim["nylon"],
           "grid": grid, "base_thickness": "wall",
           "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 3},
                      "pressure": {"start": 0, "stop": 25, "num": 3, "units": "kPa"}},
           "supply": {"voltage": float(str(sim["supply"]["voltage"]).split()[0]),
                      "units": "V"},
           "tracking": tracking}
    if "cooling" in sim:
        out["cooling"] = sim["cooling"]
    return out


def _control(**changes) -> dict:
    raw = read_yaml(CONTROL)
    for dotted, value in changes.items():
        node = raw
        *head, last = dotted.split("__")
        for part in head:
            node = node.setdefault(part, {})
        node[last] = value
    return raw


@pytest.mark.parametrize("changes", [
    {},  # the paper's control design, configs/control.yaml as it is
    {"controller__hysteresis": "3 deg", "sensor__noise": "0.2 kPa", "sensor__seed": 7,
     "estimator__filter_time_constant": "0.2 s"},
    {"controller__kind": "pi", "controller__proportional_band": "8 deg",
     "controller__integral_time": "15 s"},
    {"reference": {"kind": "step", "initial": "20 deg", "final": "90 deg", "at": "5 s"},
     "metrics__rms_from": "30 s", "time__duration": "60 s"},
], ids=["control_yaml", "hysteresis_noise_filter", "pi", "step"])
def test_sweep_tracking_equals_simulate(changes):
    sim_raw = _control(**changes)
    sim = run_simulation(parse_sim_config(sim_raw))
    ds = nf.run_sweep(parse_config(_sweep_of(sim_raw)))
    for name, metric in PAIRS.items():
        got = float(ds[name].values.reshape(-1)[0])
        assert got == pytest.approx(sim.attrs[metric], rel=1e-9, abs=1e-12), name
    assert ds["tracking_rms_error"].attrs["units"] == "rad"
    assert "tracking_bandwidth" not in ds  # only with tracking.bandwidth


def test_each_design_of_a_grid_is_its_own_simulation():
    # three designs of one slab share a (radius, wall) curvature table: each still equals
    # its own simulate run to 1e-9
    sim_raw = _control()
    lengths = ["60 mm", "70 mm", "90 mm"]
    ds = nf.run_sweep(parse_config(_sweep_of(sim_raw, {"length": {"values": lengths}})))
    for i, length in enumerate(lengths):
        sim = run_simulation(parse_sim_config(_control(design__length=length)))
        got = float(ds["tracking_rms_error"].values.reshape(-1)[i])
        assert got == pytest.approx(sim.attrs["rms_error"], rel=1e-9)


def test_each_coil_index_is_its_own_simulation():
    # r'(C) differs by coil index (docs/model.md s. 9): the sweep's loop of each C heats
    # with that C's resistance, as simulate of that design does
    sim_raw = _control()
    coils = [1.1, 1.7]
    ds = nf.run_sweep(parse_config(_sweep_of(sim_raw, {"coil_index": {"values": coils}})))
    for i, c in enumerate(coils):
        sim = run_simulation(parse_sim_config(_control(design__coil_index=c)))
        for var, key in (("tracking_rms_error", "rms_error"), ("tracking_energy", "energy")):
            got = float(ds[var].values.reshape(-1)[i])
            assert got == pytest.approx(sim.attrs[key], rel=1e-9)


@pytest.mark.parametrize("cooling, voltage", [("still_water", "200 V"), ("forced_air", "40 V")])
def test_each_coil_index_tracks_under_a_cooling_set_as_simulate_does(cooling, voltage):
    # a cooling set gives lambda'(C), different at every coil index (docs/model.md s. 9):
    # the sweep's loop of each C cools with that C's, as simulate of that design with the
    # same cooling: does. The supplies bring the cooled muscles near the paper's operating
    # temperatures (12 V barely warms them in water, docs/model.md s. 19); 50 s, two
    # periods, keep it short with the JIT off (.ci/run)
    changes = {"cooling": cooling, "supply__voltage": voltage, "time__duration": "50 s"}
    sim_raw = _control(**changes)
    coils = [1.1, 1.7]
    cfg = parse_config(_sweep_of(sim_raw, {"coil_index": {"values": coils}}))
    assert cfg.cooling.name == cooling and cfg.tracking is not None
    lam = coil_heat_loss_per_length(np.array(coils), cfg.nylon, cooling)
    assert lam[0] != lam[1] and min(lam) > 10 * cfg.nylon.heat_loss_per_length
    ds = nf.run_sweep(cfg)
    for i, c in enumerate(coils):
        sim = run_simulation(parse_sim_config(_control(**changes, design__coil_index=c)))
        assert sim.attrs["temperature_max"] > 350.0  # the loop heats: a real comparison
        for name, metric in PAIRS.items():
            got = float(ds[name].values.reshape(-1)[i])
            assert got == pytest.approx(sim.attrs[metric], rel=1e-9, abs=1e-12), (name, c)


def test_reference_relative_to_the_designs_range():
    # mean 0.6, amplitude 0.2 of theta*: the same as simulate with those angles in radians
    sim_raw = _control()
    raw = _sweep_of(sim_raw)
    raw["tracking"]["reference"] = {"kind": "sine", "relative_to": "bend_angle_max",
                                    "mean": 0.6, "amplitude": 0.2, "frequency": "0.04 Hz"}
    ds = nf.run_sweep(parse_config(raw))
    theta = float(ds["bend_angle_max"].values.reshape(-1)[0])
    ref = {"kind": "sine", "mean": f"{0.6 * theta} rad", "amplitude": f"{0.2 * theta} rad",
           "frequency": "0.04 Hz"}
    sim = run_simulation(parse_sim_config(_control(reference=ref)))
    got = float(ds["tracking_rms_error"].values.reshape(-1)[0])
    assert got == pytest.approx(sim.attrs["rms_error"], rel=1e-9)


def _sine_rms(sim_raw, f, periods):
    """simulate's RMS error of the sine at ``f`` [Hz] after its first period [rad]."""
    f = float(f)
    ref = {**sim_raw["reference"], "frequency": f"{f!r} Hz"}
    raw = _control(reference=ref, metrics__rms_from=f"{1.0 / f!r} s",
                   time__duration=f"{(1 + periods) / f!r} s")
    raw["design"] = sim_raw["design"]
    return run_simulation(parse_sim_config(raw)).attrs["rms_error"]


@pytest.mark.parametrize("radius", ["7.5 mm", "12 mm"])
def test_bandwidth_search_against_a_brute_frequency_scan(radius):
    # the bisection in log frequency against simulate on a geometric scan: the bandwidth
    # lies between the scan's last passing frequency and its first failing one
    low, high, error, periods = 0.01, 0.4, math.radians(2.0), 3
    sim_raw = _control(design__radius=radius)
    raw = _sweep_of(sim_raw)
    raw["tracking"]["bandwidth"] = {"error": "2 deg", "low": f"{low} Hz",
                                    "high": f"{high} Hz", "iterations": 10,
                                    "periods": periods}
    bw = float(nf.run_sweep(parse_config(raw))["tracking_bandwidth"].values.reshape(-1)[0])
    scan = np.geomspace(low, high, 13)
    ok = [_sine_rms(sim_raw, f, periods) <= error for f in scan]
    assert ok[0] and not ok[-1], "the scan must bracket the bandwidth"
    first_fail = ok.index(False)
    assert scan[first_fail - 1] * (1 - 1e-9) <= bw < scan[first_fail]
    # and the bandwidth itself tracks, by simulate
    assert _sine_rms(sim_raw, bw, periods) <= error


def test_bandwidth_ends_of_the_bracket():
    # a design that cannot reach the sine at all tracks nothing: 0 Hz; one that tracks the
    # bracket's top gets the top (a lower bound, documented)
    sim_raw = _control()
    raw = _sweep_of(sim_raw)
    raw["tracking"]["reference"] = {"kind": "sine", "mean": "300 deg",
                                    "amplitude": "30 deg", "frequency": "0.04 Hz"}
    raw["tracking"]["bandwidth"] = {"error": "2 deg", "low": "0.01 Hz", "high": "0.02 Hz"}
    assert float(nf.run_sweep(parse_config(raw))["tracking_bandwidth"].values.item()) == 0.0
    raw["tracking"]["reference"]["mean"] = "40 deg"
    raw["tracking"]["reference"]["amplitude"] = "1 deg"
    raw["tracking"]["bandwidth"] = {"error": "20 deg", "low": "0.01 Hz", "high": "0.02 Hz"}
    assert float(nf.run_sweep(parse_config(raw))["tracking_bandwidth"].values.item()) == 0.02


def test_without_tracking_the_cube_is_unchanged():
    # no tracking: none of its variables, and the config's canonical text (its hash) has
    # no tracking key; with it, the hash changes
    plain = nf.load_config("configs/fig12.yaml")
    assert not any(n.startswith("tracking") for n in cube_variables(plain))
    assert "tracking" not in plain.text
    tracked = nf.load_config("configs/fig12_tracking.yaml")
    assert {"tracking_rms_error", "tracking_energy"} <= set(cube_variables(tracked))
    assert tracked.sha256 != plain.sha256


def test_info_config_gives_back_the_tracking_block():
    # nylonflex info CUBE --config: the rebuilt config resolves to the same hash, with a PI,
    # a relative reference and a bandwidth search
    from nylonflex.engine.provenance import provenance, runnable_config

    raw = _sweep_of(_control(controller={"kind": "pi", "proportional_band": "8 deg",
                                         "integral_time": "15 s"}))
    raw["tracking"]["reference"] = {"kind": "sine", "relative_to": "bend_angle_max",
                                    "mean": 0.6, "amplitude": 0.2, "frequency": "0.04 Hz"}
    raw["tracking"]["bandwidth"] = {"error": "2 deg"}
    cfg = parse_config(raw)
    back = parse_config(yaml.safe_load(runnable_config(provenance(cfg))))
    assert back.tracking == cfg.tracking and back.sha256 == cfg.sha256


def test_info_config_gives_back_the_cooling_set():
    # a cube swept with tracking: and cooling: rebuilds with the same cooling set (its
    # speed too), so the rebuilt config hashes as the cube's
    from nylonflex.engine.provenance import provenance, runnable_config

    cfg = parse_config(_sweep_of(_control(cooling={"set": "forced_air", "speed": 5})))
    back = parse_config(yaml.safe_load(runnable_config(provenance(cfg))))
    assert back.cooling == cfg.cooling and back.cooling.speed == 5.0
    assert back.tracking == cfg.tracking and back.sha256 == cfg.sha256


@pytest.mark.parametrize("edit, match", [
    (lambda r: r.pop("supply"), r"^tracking: needs a supply"),
    (lambda r: r.update(model=["paper", "paper_eq10"]), r"^tracking: the closed loop is the "
     r"paper model's"),
    (lambda r: r["tracking"].update(controller={"kind": "pi"}),
     r"^tracking\.controller\.proportional_band: missing"),
    (lambda r: r["tracking"]["controller"].update(integral_time="5 s"),
     r"^tracking\.controller: proportional_band and integral_time are for kind: pi"),
    (lambda r: r["tracking"].update(reference={"kind": "step", "final": "1 deg"},
                                    bandwidth={"error": "2 deg"}),
     r"^tracking\.bandwidth: needs a sine reference"),
    (lambda r: r["tracking"]["reference"].update(amplitude="90 deg"),
     r"^tracking\.reference\.amplitude: must be <= mean"),
    (lambda r: r["tracking"]["reference"].update(frequency="0 Hz"),
     r"^tracking\.reference\.frequency: must be in \(0, 100\] Hz"),
    (lambda r: r["tracking"].update(step="1 kPa"), r"^tracking\.step: "),
    (lambda r: r["tracking"].update(rate=3), r"^tracking\.rate: "),
    (lambda r: r["tracking"]["reference"].pop("frequency"),
     r"^tracking\.reference\.frequency: missing"),
    (lambda r: r["tracking"].update(bandwidth={"error": "2 deg", "low": "1e-5 Hz"}),
     r"^tracking\.bandwidth\.low: a run of 4 periods"),
])
def test_bad_tracking_blocks_are_refused_naming_the_field(edit, match):
    raw = _sweep_of(_control())
    raw = copy.deepcopy(raw)
    edit(raw)
    with pytest.raises(InputError, match=match):
        parse_config(raw)


def test_tracking_sweep_on_the_command_line(tmp_path, capsys):
    # a user's run: the cube holds the variables with their units, query reads them
    raw = _sweep_of(_control(), {"coil_index": {"values": [1.3, 1.7]}})
    path = tmp_path / "t.yaml"
    path.write_text(yaml.safe_dump(raw))
    out = tmp_path / "cube.h5"
    assert main(["sweep", str(path), "--out", str(out), "--no-charts", "--quiet"]) == 0
    with nf.open_cube(out) as ds:
        assert ds["tracking_max_temperature"].attrs["units"] == "K"
        assert ds["tracking_rms_error"].shape == (1, 1, 1, 2, 1)
    capsys.readouterr()
    assert main(["query", str(out), "--where", "tracking_rms_error <= 2 deg", "--format",
                 "json"]) == 0
    assert '"tracking_rms_error"' in capsys.readouterr().out


@pytest.mark.slow
def test_killed_tracking_sweep_resumes_bit_for_bit(tmp_path):
    # a tracking sweep stopped after its first slab and resumed holds the uninterrupted
    # run's bits; a Dask run (serial kernels in the workers) too
    import signal

    from killing import kill_after_slabs

    raw = _sweep_of(_control(), {"radius": {"start": 5, "stop": 20, "num": 16,
                                            "units": "mm"},
                                 "coil_index": {"values": [1.3, 1.7]},
                                 "wall_thickness": {"values": [1.5, 2, 2.5, 3], "units": "mm"},
                                 "length": {"values": [60, 70, 80, 90], "units": "mm"}})
    # a long pressure curve makes the slabs of 1 MB hold two radii each
    raw["curves"] = {"stroke": {"start": 0, "stop": 0.1, "num": 51},
                     "pressure": {"start": 0, "stop": 25, "num": 2001, "units": "kPa"}}
    raw["slab_megabytes"] = 1.0
    raw["tracking"]["duration"] = "50 s"
    cfg = parse_config(raw)
    assert len(plan_slabs(cfg)[0]) > 2
    want = nf.run_sweep(cfg)
    path = tmp_path / "t.yaml"
    path.write_text(yaml.safe_dump(raw))
    out = tmp_path / "resumed.h5"
    argv = ["sweep", str(path), "--out", str(out), "--no-charts", "--quiet"]
    assert kill_after_slabs(argv, 1, signal.SIGTERM) != 0  # stopped after its first slab
    assert main([*argv, "--resume"]) == 0
    cubes = {"resumed": nf.open_cube(out)}
    assert cubes["resumed"].attrs["resumed_slabs"] != 0
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  host="127.0.0.1", dashboard_address="127.0.0.1:0") as c:
        cubes["dask"] = nf.run_sweep(cfg, tmp_path / "dask.h5", scheduler=c.scheduler_address)
    for which, ds in cubes.items():
        for name in PAIRS:
            np.testing.assert_array_equal(ds[name].values, want[name].values,
                                          err_msg=f"{which} {name}")
        ds.close()


@pytest.mark.slow
def test_design_answers_the_tracking_question_and_simulate_agrees():
    # "the largest tip force with a full range of motion that tracks a 0.04 Hz, 30 deg sine
    # within 2 deg at 12 V" over the figure-12 grid (configs/design_tracking.yaml), and
    # nylonflex simulate of the answer (configs/control.yaml with its design) agrees
    from nylonflex.design import load_spec, run_design

    ds = nf.run_sweep(nf.load_config("configs/fig12_tracking.yaml"))
    res = run_design(load_spec("configs/design_tracking.yaml"), cube=ds)
    best = res.designs[0]
    assert best["range_fraction"] >= 1.0 and best["tracking_rms_error"] <= math.radians(2.0)
    feasible = (ds["range_fraction"] >= 1) & (ds["tracking_rms_error"] <= math.radians(2.0)) \
        & (ds["validity"] == 0)
    assert best["tip_force_max"] == pytest.approx(
        float(ds["tip_force_max"].where(feasible).max()), rel=1e-12)
    design = {k: f"{best[k]!r} {'rad' if k == 'wrap_angle' else 'm'}" for k in
              ("radius", "wall_thickness", "length", "wrap_angle")}
    design.update(coil_index=best["coil_index"], base_thickness="wall")
    sim = run_simulation(parse_sim_config(_control(design=design)))
    assert sim.attrs["rms_error"] <= math.radians(2.0)
    assert sim.attrs["rms_error"] == pytest.approx(best["tracking_rms_error"], rel=1e-9)


def test_tracking_map_shows_the_cubes_own_values():
    from matplotlib.figure import Figure

    from nylonflex.charts import CHARTS, tracking_map
    from nylonflex.units import InputError

    grid = {"radius": {"values": ["10 mm", "15 mm", "20 mm"]},
            "wall_thickness": {"values": ["2 mm", "3 mm"]}}
    ds = nf.run_sweep(parse_config(_sweep_of(_control(), grid)))
    assert CHARTS["tracking_map"] is tracking_map
    host = Figure()
    ax = host.add_subplot()
    assert tracking_map(ds, ax=ax) is host
    assert ax.get_ylabel() == "wall thickness [mm]"
    assert "RMS tracking error" in ax.get_title()
    # the filled contours span the cube's RMS errors [deg] of that slice
    want = np.degrees(ds["tracking_rms_error"].isel(length=0, coil_index=0, wrap_angle=0)
                      .values)
    filled = [c for c in ax.collections if hasattr(c, "levels")][0]
    assert filled.levels.min() <= want.min() and filled.levels.max() >= want.max()
    assert filled.levels.max() - filled.levels.min() < 2 * (want.max() - want.min())
    with pytest.raises(InputError, match="tracking_rms_error: the cube has none"):
        tracking_map(ds.drop_vars([v for v in ds.data_vars if v.startswith("tracking_")]))
