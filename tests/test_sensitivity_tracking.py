"""``nylonflex sensitivity`` of the closed-loop tracking variables (issue 29).

Each Saltelli sample runs the sweep's own closed loop under that sample's materials
(nylonflex.engine.tracking.sampled_tracking): the nominal materials give the cube's value,
and a material field the loop never reads has a total index of exactly 0.
"""

import copy

import numpy as np
import pytest
import yaml

import nylonflex as nf
from nylonflex.cli import main
from nylonflex.config import parse_config
from nylonflex.engine.sampled import perturbed_configs
from nylonflex.engine.tracking import sampled_tracking
from nylonflex.uncertainty import sobol_indices
from nylonflex.uncertainty.sensitivity import MAX_LOOP_RUNS
from nylonflex.units import InputError
from nylonflex.variables import AXES

#: Two radii, two walls and two coil indices of figure 12's grid; figure 9's sine, 30 s.
RAW = {
    "name": "uq_tracking",
    "grid": {"radius": {"values": [10, 15], "units": "mm"},
             "wall_thickness": {"values": [3, 4], "units": "mm"},
             "length": {"values": [90], "units": "mm"},
             "coil_index": {"values": [1.3, 1.5]},
             "wrap_angle": {"values": [12], "units": "deg"}},
    "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 3},
               "pressure": {"start": 0, "stop": 25, "num": 3, "units": "kPa"}},
    "supply": {"voltage": 12, "units": "V"},
    "tracking": {"duration": "30 s", "step": "10 ms", "initial_temperature": "25 degC",
                 "reference": {"kind": "sine", "mean": "85 deg", "amplitude": "30 deg",
                               "frequency": "0.04 Hz"},
                 "rms_from": "5 s"},
    "uncertainty": {"seed": 1, "parameters": {
        "wall_thickness": {"sd": 0.1, "units": "mm"},
        "silicone.mu": {"rel_sd": 0.1},
        "nylon.stroke_max": {"rel_sd": 0.05},
        "nylon.heat_loss_per_length": {"rel_sd": 0.1}}},
}
AT = {"radius": 15e-3, "wall_thickness": 4e-3, "length": 90e-3, "coil_index": 1.5,
      "wrap_angle": np.deg2rad(12)}
AT_TEXT = "radius=15mm,wall_thickness=4mm,length=90mm,coil_index=1.5,wrap_angle=12deg"
NAMES = ("tracking_rms_error", "tracking_max_temperature", "tracking_energy")


def _raw(**changes):
    raw = copy.deepcopy(RAW)
    for dotted, value in changes.items():
        node = raw
        *head, last = dotted.split("__")
        for part in head:
            node = node[part]
        if value is None:
            node.pop(last)
        else:
            node[last] = value
    return raw


@pytest.mark.parametrize("changes, names", [
    ({}, NAMES),
    ({"tracking__reference": {"kind": "sine", "relative_to": "bend_angle_max", "mean": 0.6,
                              "amplitude": 0.2, "frequency": "0.04 Hz"}}, NAMES),
    # the bandwidth search left out when not asked for: the main run's noise is the same
    ({"tracking__sensor": {"noise": "0.2 kPa", "seed": 7},
      "tracking__bandwidth": {"error": "2 deg", "iterations": 3, "periods": 1,
                              "low": "0.02 Hz", "high": "0.2 Hz"}}, NAMES),
    ({"tracking__bandwidth": {"error": "2 deg", "iterations": 3, "periods": 1,
                              "low": "0.02 Hz", "high": "0.2 Hz"}},
     NAMES + ("tracking_bandwidth",)),
], ids=["absolute", "relative_to_theta", "noise_bandwidth_not_asked", "bandwidth"])
def test_nominal_sample_gives_the_cubes_value(changes, names):
    cfg = parse_config(_raw(**changes))
    ds = nf.run_sweep(cfg)
    dims = sum(p.dims for p in cfg.uncertainty.parameters)
    z = np.zeros((2, dims))  # the nominal materials, twice
    (_, c0), _ = perturbed_configs(cfg, AT, z)
    assert (c0.silicone, c0.nylon) == (cfg.silicone, cfg.nylon)
    for idx in np.ndindex(*cfg.shape):
        design = {a: float(cfg.axes[a][i]) for a, i in zip(AXES, idx)}
        got = sampled_tracking(cfg, design, z, names)
        for n in names:
            want = float(ds[n].values[idx])
            assert np.isfinite(want), (n, idx)
            np.testing.assert_allclose(got[n], want, rtol=1e-9, atol=0, err_msg=n)


def test_a_perturbed_sample_is_a_sweep_of_its_materials():
    # a sample's value is that of a sweep of a config with the sample's materials and wall
    cfg = parse_config(_raw())
    z = np.array([[0.7, -1.2, 0.5, 1.1]])  # heat loss, stroke_max, mu, wall (sorted names)
    (design, c), = perturbed_configs(cfg, AT, z)
    ny = cfg.nylon
    assert c.nylon.heat_loss_per_length == pytest.approx(ny.heat_loss_per_length * 1.07)
    assert c.nylon.stroke_max_table == pytest.approx([s * 0.94 for s in ny.stroke_max_table])
    assert c.silicone.mu == pytest.approx([m * 1.05 for m in cfg.silicone.mu])
    assert design["wall_thickness"] == pytest.approx(AT["wall_thickness"] + 0.11e-3)
    raw = _raw(uncertainty=None)
    raw["nylon"] = {"set": "silver_nylon66", "heat_loss_per_length":
                    c.nylon.heat_loss_per_length,
                    "stroke_max_table": list(c.nylon.stroke_max_table)}
    raw["silicone"] = {"set": "tc5005", "mu": list(c.silicone.mu)}
    raw["grid"]["wall_thickness"] = {"values": [design["wall_thickness"]], "units": "m"}
    ds = nf.run_sweep(parse_config(raw))
    got = sampled_tracking(cfg, AT, z, NAMES)
    i = list(cfg.axes["radius"]).index(AT["radius"])
    j = list(cfg.axes["coil_index"]).index(AT["coil_index"])
    for n in NAMES:
        np.testing.assert_allclose(got[n], ds[n].values[i, 0, 0, j, 0], rtol=1e-9,
                                   err_msg=n)
    # the samples' threads change nothing: the same values as one thread
    z3 = np.vstack([z, -z, 0.5 * z])
    threaded, serial = (sampled_tracking(cfg, AT, z3, NAMES, parallel=p) for p in (True, False))
    for n in NAMES:
        np.testing.assert_array_equal(threaded[n], serial[n])


def test_tracking_outputs_are_accepted_only_with_a_tracking_block():
    plain = parse_config(_raw(tracking=None))
    with pytest.raises(InputError, match=r"^--output: tracking_rms_error needs a tracking: "
                                         r"block in the config"):
        sobol_indices(plain, ("tracking_rms_error",), at=AT, base_samples=8)
    cfg = parse_config(_raw())
    with pytest.raises(InputError, match=r"^--output: tracking_bandwidth needs "
                                         r"tracking\.bandwidth"):
        sobol_indices(cfg, ("tracking_bandwidth",), at=AT, base_samples=8)
    with pytest.raises(InputError, match=r"^--output: unknown tracking_rms; accepted: .*"
                                         r"tip_force_max.*tracking_energy$"):
        sobol_indices(cfg, ("tracking_rms",), at=AT, base_samples=8)


def test_closed_loop_runs_are_bounded_before_any_work():
    cfg = parse_config(_raw())
    # 4096 x (4 factors + 2) = 24,576 runs of one design, over the bound
    with pytest.raises(InputError, match=r"^--samples: 4,096 x 6 \(factors \+ 2\) x 1 "
                                         r"design = 24,576 closed-loop runs, over the "
                                         r"16,384 .*; lower --samples or --designs"):
        sobol_indices(cfg, ("tracking_energy",), at=AT, base_samples=4096)
    assert 4096 * 6 > MAX_LOOP_RUNS
    with pytest.raises(InputError, match=r"x 4 designs = 24,576 closed-loop runs"):
        sobol_indices(cfg, ("tip_force_max", "tracking_energy"), at={"coil_index": 1.5},
                      base_samples=1024, max_designs=4)
    # the design variables alone keep their own, higher bound
    res = sobol_indices(cfg, ("tip_force_max",), at=AT, base_samples=4096)
    assert res.samples == 4096 * 6


def test_a_field_the_loop_never_reads_has_no_index():
    # the muscle's stiffness is not in the loop (docs/model.md s. 19): total index exactly 0;
    # its heat loss decides the energy (the loss is what the supply pays for) and the highest
    # temperature
    raw = _raw(uncertainty__parameters={"nylon.stiffness": {"rel_sd": 0.2},
                                        "nylon.heat_loss_per_length": {"rel_sd": 0.1}})
    res = sobol_indices(parse_config(raw), ("tracking_energy", "tracking_max_temperature"),
                        at=AT, base_samples=16)
    for out in ("tracking_energy", "tracking_max_temperature"):
        d = res.indices[out]
        assert d["total"]["nylon.stiffness"] == 0.0, out
        assert d["first"]["nylon.stiffness"] == pytest.approx(0, abs=1e-12), out
        assert d["total"]["nylon.heat_loss_per_length"] > 0.5, out


def test_mixed_request_keeps_the_design_variables_as_they_were():
    cfg = parse_config(_raw())
    alone = sobol_indices(cfg, ("tip_force_max",), at=AT, base_samples=8)
    mixed = sobol_indices(cfg, ("tip_force_max", "tracking_rms_error"), at=AT,
                          base_samples=8)
    assert mixed.indices["tip_force_max"] == alone.indices["tip_force_max"]
    assert set(mixed.indices["tracking_rms_error"]["total"]) == set(alone.parameters)


def test_sensitivity_of_tracking_on_the_command_line(tmp_path, capsys):
    path = tmp_path / "t.yaml"
    path.write_text(yaml.safe_dump(_raw(uncertainty=None)))
    unc = ("uncertainty={parameters: {silicone.mu: {rel_sd: 0.1}, "
           "nylon.heat_loss_per_length: {rel_sd: 0.1}}}")
    assert main(["sensitivity", str(path), "--output", "tracking_rms_error", "--at", AT_TEXT,
                 "--samples", "8", "--set", unc]) == 0
    out = capsys.readouterr().out
    assert "tracking_rms_error:" in out and "nylon.heat_loss_per_length" in out
    assert main(["sensitivity", str(path), "--output", "tracking_rms_error", "--at", AT_TEXT,
                 "--samples", "8", "--set", "tracking=null", "--set", unc]) == 2
    assert "needs a tracking: block" in capsys.readouterr().err
