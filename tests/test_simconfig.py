"""The one config machinery: pydantic schemas and one range formatter for sweep and
simulate configs (issue 9). Parsing only; the simulation itself is tested in
test_simulate.py.

Expected values come from the configs' own text (``configs/*.yaml``), docs/model.md section 10's
defaults as written in :data:`nylonflex.config.simulate.DEFAULTS`, and the ranges of
``config.DESIGN_RANGES``.
"""

from __future__ import annotations

import ast
import copy
import math
import re
from pathlib import Path

import pytest
import yaml

from nylonflex.config import check_range, parse_config, range_error
from nylonflex.config.simulate import SimConfig, SimConfigModel, load_sim_config, parse_sim_config
from nylonflex.units import InputError

ROOT = Path(__file__).resolve().parent.parent
CONFIGS = ROOT / "configs"
DEG = math.pi / 180.0


def _base(**over):
    raw = {"name": "t", "time": {"duration": "20 s", "step": "10 ms"},
           "reference": {"kind": "step", "initial": 0, "final": 120, "at": "1 s"}}
    raw.update(over)
    return raw


def _message(raw) -> str:
    with pytest.raises(InputError) as info:
        parse_sim_config(raw)
    return str(info.value)


# --- the one range formatter ----------------------------------------------------------

@pytest.mark.parametrize("args, kwargs, expected", [
    (("grid.radius.stop", 0.5e-3, 0.2, "mm", 0.9), {},
     "grid.radius.stop: must be in [0.5, 200] mm, got 900 mm"),
    (("time.step", 0.0, 10.0, "ms", -1e-3), {"lo_open": True},
     "time.step: must be in (0, 10000] ms, got -1 ms"),
    (("x", 0.0, 1.0, "1", 1.0), {"hi_open": True}, "x: must be in [0, 1), got 1"),
    (("curves.stroke.stop", 0.0, 0.5, "1", 1.2), {}, "curves.stroke.stop: must be in [0, 0.5], got 1.2"),
    (("supply.voltage", 0.0, None, "V", -2.0), {"lo_open": True},
     "supply.voltage: must be > 0 V, got -2 V"),
    (("a", None, 5.0, "s", 6.0), {}, "a: must be <= 5 s, got 6 s"),
    (("initial_temperature", 298.15, 423.15, "degC", 283.15), {},
     "initial_temperature: must be in [25, 150] degC, got 10 degC"),
    (("sensor.seed", 0, 2**32 - 1, "1", 2**33), {},  # integers keep every digit
     "sensor.seed: must be in [0, 4294967295], got 8589934592"),
])
def test_range_error_wording(args, kwargs, expected):
    err = range_error(*args, **kwargs)
    assert isinstance(err, InputError)
    assert str(err) == expected


def test_check_range_parses_units_and_clamps_within_slack():
    assert check_range("7.5 mm", "r", "length", "mm", 0.5e-3, 0.2) == pytest.approx(7.5e-3)
    assert check_range(7.5, "r", "length", "mm", 0.5e-3, 0.2) == pytest.approx(7.5e-3)
    # 1e-13 m past the bound: inside the slack, clamped onto it
    assert check_range(0.2 + 1e-13, "r", "length", "m", 0.5e-3, 0.2, slack=1e-12) == 0.2
    with pytest.raises(InputError, match=r"^r: must be in \[0.5, 200\] mm, got 200.001 mm$"):
        check_range("200.001 mm", "r", "length", "mm", 0.5e-3, 0.2)
    with pytest.raises(InputError, match=r"^f: must be in \(0, 100\] Hz, got 0 Hz$"):
        check_range(0, "f", "frequency", "Hz", 0.0, 100.0, lo_open=True)
    with pytest.raises(InputError, match=r"^r: must be finite, got inf mm$"):
        check_range(math.inf, "r", "length", "mm")
    with pytest.raises(InputError, match=r"^r: unit 'kPa' is not a length"):
        check_range("3 kPa", "r", "length", "mm", 0.0, 1.0)


def test_sweep_and_simulate_word_a_range_alike():
    sweep = yaml.safe_load((CONFIGS / "fig12.yaml").read_text())
    sweep["grid"]["radius"] = {"values": [900], "units": "mm"}
    with pytest.raises(InputError) as a:
        parse_config(sweep)
    b = _message(_base(design={"radius": "900 mm"}))
    assert str(a.value) == "grid.radius.values[0]: must be in [0.5, 200] mm, got 900 mm"
    assert b == "design.radius: must be in [0.5, 200] mm, got 900 mm"


# --- the simulate config's schema and messages --------------------------------------------

@pytest.mark.parametrize("patch, expected", [
    ({"design": {"colour": "red"}},
     "design.colour: unknown key; accepted: base_thickness, coil_index, length, radius, "
     "wall_thickness, wrap_angle"),
    ({"design": {"base_thickness": {"value": 3, "unit": "mm"}}},
     "design.base_thickness.unit: unknown key; accepted: units, value"),
    ({"design": {"radius": None}},
     "design.radius: expected a number with an optional unit, got None"),
    ({"design": 3}, "design: must be a mapping of keys, got 3"),
    ({"design": {"coil_index": 2.5}}, "design.coil_index: must be in [1.1, 1.7], got 2.5"),
    ({"reference": {"kind": "ramp"}},
     "reference.kind: must be one of sine, step, schedule, got 'ramp'"),
    ({"reference": {"final": 3}}, "reference.kind: missing key; accepted: sine, step, schedule"),
    ({"reference": None}, "reference: missing; give kind: sine, step or schedule"),
    ({"reference": {"kind": "sine", "mean": 40, "amplitude": 10, "frequency": 1, "at": 1}},
     "reference.at: unknown key; accepted: amplitude, frequency, kind, mean, phase"),
    ({"reference": {"kind": "sine", "mean": 40, "amplitude": 10}},
     "reference.frequency: missing key"),
    ({"reference": {"kind": "schedule", "times": [0, 1], "angles": [0, "400 deg"]}},
     "reference.angles[1]: must be in [0, 360] deg, got 400 deg"),
    ({"time": {"duration": "10 s", "step": "20 s"}},
     "time.step: must be in (0, 10000] ms, got 20000 ms"),
    ({"sensor": {"seed": 1.5}}, "sensor.seed: must be an integer, got 1.5"),
    ({"sensor": {"seed": -1}}, "sensor.seed: must be in [0, 4294967295], got -1"),
    ({"initial_temperature": "10 degC"},
     "initial_temperature: must be in [25, 150] degC, got 10 degC"),
    ({"actuators": [{"name": "a"}, {"name": "b", "design": {"radius": "900 mm"}}]},
     "actuators[1].design.radius: must be in [0.5, 200] mm, got 900 mm"),
    ({"actuators": [{"name": "a", "reference": {"kind": "step", "final": 10, "at": 1,
                                                 "times": [0]}}]},
     "actuators[0].reference.times: unknown key; accepted: at, final, initial, kind"),
    ({"actuators": [{"name": "a", "supply": {}}]},
     "actuators[0].supply: unknown key; accepted: controller, cooling, design, estimator, "
     "initial_temperature, metrics, name, nylon, reference, sensor, silicone"),
    ({"actuators": []}, "actuators: must be a list of 1 to 64 actuators, got 0"),
    ({"actuators": [{"name": "a"}, {"name": "a"}]},
     "actuators[1].name: a unique name of letters, digits and '_', got 'a'"),
    ({"name": "a/b"}, "name: letters, digits, '-', '_' and '.' only, got 'a/b'"),
])
def test_messages_name_the_dotted_field_and_what_it_accepts(patch, expected):
    msg = _message(_base(**patch))
    assert msg == expected
    assert "\n" not in msg


def test_missing_name_and_non_mapping():
    raw = _base()
    del raw["name"]
    assert _message(raw) == "name: missing key"
    with pytest.raises(InputError, match=r"^config: must be a YAML mapping"):
        parse_sim_config([1, 2])


def test_value_units_form_and_bare_numbers_resolve_like_strings():
    a = parse_sim_config(_base(design={"radius": {"value": 0.75, "units": "cm"},
                                       "base_thickness": {"value": 3}}))
    b = parse_sim_config(_base(design={"radius": "7.5 mm", "base_thickness": "3 mm"}))
    c = parse_sim_config(_base(design={"radius": 7.5, "base_thickness": 3}))  # bare: mm
    assert a == b == c
    assert a.actuators[0].radius == pytest.approx(7.5e-3)
    assert a.actuators[0].base_thickness == pytest.approx(3e-3)


def test_defaults_fill_an_almost_empty_config():
    # DEFAULTS: docs/model.md section 10's design at 12 V, 120 s at 10 ms
    cfg = parse_sim_config({"name": "d", "reference": {"kind": "step", "final": 90}})
    a = cfg.actuators[0]
    assert (cfg.supply_voltage, cfg.internal_resistance) == (12.0, 0.0)
    assert (cfg.duration, cfg.step) == pytest.approx((120.0, 0.01))
    assert (a.radius, a.wall_thickness, a.length) == pytest.approx((7.5e-3, 2e-3, 70e-3))
    assert a.coil_index == 1.7 and a.wrap_angle == pytest.approx(8 * DEG)
    assert a.base_thickness == a.wall_thickness  # "wall"
    assert a.initial_temperature == a.nylon.t_amb
    assert (a.noise, a.seed, a.table_points, a.hysteresis) == (0.0, 0, 65, 0.0)
    assert not cfg.gripper and a.name == "actuator"


def test_gripper_merges_defaults_top_level_and_own_key_by_key():
    cfg = load_sim_config(CONFIGS / "gripper.yaml")
    assert isinstance(cfg, SimConfig) and cfg.gripper
    f1, f2, thumb = cfg.actuators
    assert [a.name for a in cfg.actuators] == ["finger_1", "finger_2", "thumb"]
    # top-level design (length 60 mm) with each actuator's own override on top
    assert [a.length for a in cfg.actuators] == pytest.approx([60e-3] * 3)
    assert (f1.radius, f2.radius, thumb.radius) == pytest.approx((7.5e-3, 7e-3, 7.5e-3))
    assert (f1.coil_index, thumb.coil_index) == (1.7, 1.5)
    # the top-level controller section, and the seed offset by the actuator's index
    assert all(a.hysteresis == pytest.approx(1 * DEG) for a in cfg.actuators)
    assert [a.seed for a in cfg.actuators] == [0, 1, 2]
    assert thumb.reference.params["angles"] == pytest.approx([0, 30 * DEG, 0])
    assert (cfg.supply_voltage, cfg.internal_resistance) == (9.0, 1.5)


def test_actuator_inherits_the_top_level_reference_and_materials():
    raw = _base(silicone="ecoflex_00_30",
                actuators=[{"name": "a"}, {"name": "b", "silicone": "tc5005",
                                           "sensor": {"seed": 7}}])
    a, b = parse_sim_config(raw).actuators
    assert a.reference == b.reference
    assert a.reference.params == pytest.approx({"initial": 0.0, "final": 120 * DEG, "at": 1.0})
    assert a.silicone != b.silicone
    assert (a.seed, b.seed) == (0, 8)


def test_cooling_at_the_top_and_per_actuator_sets_each_muscles_heat_loss():
    # docs/model.md s. 9: a cooling set's lambda'(C) at the actuator's own coil index takes
    # the place of the set's heat_loss_per_length; the actuator's own cooling: wins, and
    # the resolved config records each set
    from nylonflex.materials import nylon_parameters
    from nylonflex.physics.thermal import coil_heat_loss_per_length

    own = nylon_parameters("silver_nylon66")
    raw = _base(cooling="still_water",
                actuators=[{"name": "a", "design": {"coil_index": 1.2}},
                           {"name": "b", "cooling": {"set": "forced_air", "speed": 5}},
                           {"name": "c", "cooling": None}])
    cfg = parse_sim_config(raw)
    a, b, c = cfg.actuators
    assert (a.cooling.name, b.cooling.name, c.cooling) == ("still_water", "forced_air", None)
    assert a.nylon.heat_loss_per_length == coil_heat_loss_per_length(1.2, own, "still_water")
    assert b.nylon.heat_loss_per_length == coil_heat_loss_per_length(
        1.7, own, {"set": "forced_air", "speed": 5})
    assert c.nylon == own  # no cooling: the set as it is
    assert "still_water" in a.nylon.sources["heat_loss_per_length"]
    # only lambda' changes
    assert a.nylon.heat_capacity_per_length == own.heat_capacity_per_length
    assert a.nylon.name == own.name
    doc = yaml.safe_load(cfg.text)["actuators"]
    assert doc[0]["cooling"] == {"name": "still_water", "fluid": "water", "speed": 0.0}
    assert doc[1]["cooling"] == {"name": "forced_air", "fluid": "air", "speed": 5.0}
    assert "cooling" not in doc[2]
    assert doc[0]["nylon"]["heat_loss_per_length"] == a.nylon.heat_loss_per_length
    plain = parse_sim_config(_base())
    assert plain.actuators[0].cooling is None and plain.actuators[0].nylon == own
    assert "cooling" not in yaml.safe_load(plain.text)["actuators"][0]


def test_sine_rms_from_defaults_to_the_first_period():
    raw = _base(reference={"kind": "sine", "mean": 40, "amplitude": 10, "frequency": "0.1 Hz"})
    assert parse_sim_config(raw).actuators[0].rms_from == pytest.approx(10.0)


def test_the_shipped_configs_resolve():
    for name in ("control", "step", "gripper"):
        raw = yaml.safe_load((CONFIGS / f"{name}.yaml").read_text())
        SimConfigModel.model_validate(raw)  # the schema alone
        cfg = load_sim_config(CONFIGS / f"{name}.yaml")
        assert cfg == parse_sim_config(copy.deepcopy(raw))
        assert yaml.safe_load(cfg.text)["name"] == name


def test_simulate_reexports_the_config_layer():
    import nylonflex.config.simulate as sc
    import nylonflex.sim as sim

    for name in ("SimConfig", "ActuatorSpec", "Reference", "parse_sim_config",
                 "load_sim_config"):
        assert getattr(sim, name) is getattr(sc, name)


def test_simconfig_is_the_config_layer():
    # what config/simulate.py imports from outside the config package (``..x``): never the
    # layers above it
    tree = ast.parse((ROOT / "nylonflex" / "config" / "simulate.py").read_text())
    mods = {n.module for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) and n.level == 2}
    mods |= {a.name.removeprefix("nylonflex.") for n in ast.walk(tree)
             if isinstance(n, ast.Import) for a in n.names}
    assert {"materials", "physics.nylon"} <= mods
    for mod in mods:
        assert not re.match(r"(kernels|engine|sim|storage|charts|cli)\b", mod or ""), mod
        assert (mod or "").split(".")[0] not in ("numba", "xarray", "matplotlib"), mod
