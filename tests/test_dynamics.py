"""Per-design dynamics with a supply and the thermal constants per coil index and cooling
environment (issues 29 and 30; docs/model.md s. 9 and 19)."""

import math

import numpy as np
import pytest

import nylonflex as nf
from nylonflex.materials import cooling_parameters, nylon_parameters
from nylonflex.physics import nylon, thermal, wrap
from nylonflex.physics.limits import EFFICIENCY_BOUND, VALIDITY_FLAGS
from nylonflex.units import InputError

DEG = math.pi / 180.0
NY = nylon_parameters("silver_nylon66")
# the paper's two worked examples (section 4; docs/model.md s. 8)
EXAMPLE_1 = dict(radius=20e-3, wall_thickness=6e-3, length=90e-3, coil_index=1.1,
                 wrap_angle=8 * DEG)
EXAMPLE_2 = dict(radius=7.5e-3, wall_thickness=2e-3, length=70e-3, coil_index=1.7,
                 wrap_angle=8 * DEG)
DYNAMIC = ("cycle_time", "cycle_rate", "heating_energy", "mechanical_work", "efficiency")


def _ratio(c):
    return math.sqrt((math.pi * c) ** 2 + 1) / math.sqrt((math.pi * 1.7) ** 2 + 1)


def test_resistance_per_length_holds_the_papers_value_at_its_coil_index():
    # docs/model.md s. 9: 0.15 ohm/mm at C = 1.7 (the paper's 12 V, 160 mA on the 0.503 m
    # muscle of example 2: 75 ohm), scaled by the thread per length sqrt((pi C)^2 + 1)
    assert thermal.coil_resistance_per_length(1.7) == 150.0
    for c in (1.1, 1.3, 1.5):
        assert thermal.coil_resistance_per_length(c) == pytest.approx(150.0 * _ratio(c),
                                                                      rel=1e-15)
    assert thermal.coil_resistance_per_length(1.1) == pytest.approx(99.4, abs=0.1)
    # resistance_coil_index 0: one r' at every C
    flat = nylon_parameters("silver_nylon66", resistance_coil_index=0.0)
    assert thermal.coil_resistance_per_length(1.1, flat) == 150.0


def test_example_2_at_the_papers_supply_is_its_operating_point():
    # the paper drives example 2 at 12 V and 160 mA: R = 12 / 0.16 = 75 ohm; and lambda' =
    # 0.03 is the back-calculation 1.92 W / (0.503 m x 125 K) (docs/model.md s. 9)
    d = nf.evaluate(**EXAMPLE_2, supply_voltage=12.0)
    assert float(d["muscle_length"]) == pytest.approx(0.503, abs=5e-4)
    assert float(d["resistance"]) == pytest.approx(75.0, rel=0.01)
    lam = 12.0 ** 2 / float(d["resistance"]) / (float(d["muscle_length"]) * 125.0)
    assert lam == pytest.approx(NY.heat_loss_per_length, rel=0.02)


def test_still_air_is_churchill_chu_and_forced_air_churchill_bernstein():
    d = NY.fibre_diameter * (1.4 + 1.0)
    assert thermal.convection_loss_per_length(d, NY.t_max, NY.t_amb) == pytest.approx(
        thermal.free_convection_loss_per_length(d, NY.t_max, NY.t_amb), rel=1e-12)
    # Churchill & Bernstein 1977 by hand, air at T_f = 360.65 K (Incropera Table A.4
    # interpolated between 350 and 400 K), U = 2 m/s
    f = (360.65 - 350.0) / 50.0
    k = 30.0e-3 + f * (33.8e-3 - 30.0e-3)
    nu = 20.92e-6 + f * (26.41e-6 - 20.92e-6)
    pr = 0.700 + f * (0.690 - 0.700)
    re = 2.0 * d / nu
    nu_d = 0.3 + 0.62 * re ** 0.5 * pr ** (1 / 3) / (1 + (0.4 / pr) ** (2 / 3)) ** 0.25 * \
        (1 + (re / 282000) ** (5 / 8)) ** 0.8
    assert thermal.convection_loss_per_length(d, NY.t_max, NY.t_amb, "air", 2.0) == \
        pytest.approx(math.pi * k * nu_d, rel=1e-12)
    # ordering: still air < forced air < still water
    loss = [float(thermal.coil_heat_loss_per_length(1.4, NY, name))
            for name in ("still_air", "forced_air", "still_water")]
    assert loss[0] < loss[1] < loss[2]
    assert loss[0] == pytest.approx(0.0924, abs=5e-4)  # docs/model.md s. 9
    # without a cooling set: the set's own value at every C
    assert np.all(thermal.coil_heat_loss_per_length([1.1, 1.7]) == 0.03)


def test_cooling_sets_are_named_and_checked():
    assert cooling_parameters({"set": "forced_air", "speed": 5}).speed == 5.0
    with pytest.raises(ValueError, match="cooling: must be one of still_air"):
        cooling_parameters("fan")
    with pytest.raises(ValueError, match=r"cooling.speed: must be a number in \[0, 100\]"):
        cooling_parameters({"set": "forced_air", "speed": -1})


def test_cooling_changes_only_the_thermal_values_through_lambda():
    still = nf.design_limits(**EXAMPLE_1, cooling="still_air")
    default = nf.design_limits(**EXAMPLE_1)
    lam = float(thermal.coil_heat_loss_per_length(1.1, NY, "still_air"))
    assert still["heating_power"] == pytest.approx(default["heating_power"] * lam / 0.03,
                                                   rel=1e-12)
    assert still["tip_force_max"] == default["tip_force_max"]  # no supply: no change


def _closed_form(design, voltage, cooling=None):
    """The dynamics of docs/model.md s. 20 from eq. (2)-(3) written out here."""
    c = design["coil_index"]
    l_m = float(wrap.muscle_length(design["radius"], design["wall_thickness"],
                                   design["length"], design["wrap_angle"], c))
    r = float(thermal.coil_resistance_per_length(c)) * l_m
    lam = float(thermal.coil_heat_loss_per_length(c, NY, cooling))
    tau = NY.heat_capacity_per_length / lam
    t_ss = NY.t_amb + voltage ** 2 / (r * lam * l_m)
    d = nf.design_limits(**design, supply_voltage=voltage, cooling=cooling)
    s_work = float(nylon.stroke(nylon.temperature_for_stroke(d["usable_stroke"], c), c))
    t_hot = nylon.temperature_for_stroke(0.95 * s_work, c)
    t_cool = nylon.temperature_for_stroke(0.05 * s_work, c)
    heat = -tau * math.log(1 - (t_hot - NY.t_amb) / (t_ss - NY.t_amb))
    cool = tau * math.log((t_hot - NY.t_amb) / (t_cool - NY.t_amb))
    energy = voltage ** 2 / r * heat
    return d, dict(cycle_time=heat + cool, cycle_rate=1 / (heat + cool), heating_energy=energy,
                   heat=heat, tau=tau, t_ss=t_ss, t_hot=t_hot, r=r, lam=lam, l_m=l_m)


@pytest.mark.parametrize("design", [EXAMPLE_1, EXAMPLE_2])
@pytest.mark.parametrize("cooling", [None, "forced_air"])
def test_cycle_time_rate_and_energy_are_their_closed_forms(design, cooling):
    voltage = 12.0 if cooling is None else 40.0
    d, ref = _closed_form(design, voltage, cooling)
    for name in ("cycle_time", "cycle_rate", "heating_energy"):
        assert d[name] == pytest.approx(ref[name], rel=1e-9), name
    assert d["heating_time"] == pytest.approx(ref["heat"], rel=1e-9)


def test_mechanical_work_is_the_integral_of_the_nylon_force():
    from scipy.integrate import quad

    for design in (EXAMPLE_1, EXAMPLE_2):
        d = nf.design_limits(**design, supply_voltage=12.0)
        f = lambda s: float(wrap.nylon_force(s, design["radius"], design["wall_thickness"],  # noqa: E731
                                             design["wrap_angle"], design["coil_index"]))
        integral = quad(f, 0.0, d["usable_stroke"], epsabs=0, epsrel=1e-13)[0]
        assert d["mechanical_work"] == pytest.approx(d["muscle_length"] * integral, rel=1e-10)
        assert d["efficiency"] == pytest.approx(d["mechanical_work"] / d["heating_energy"],
                                                rel=1e-15)
        assert 0 < d["efficiency"] < EFFICIENCY_BOUND


def test_heating_energy_balances_stored_and_lost_heat():
    # eq. (3) integrated over the heating phase: int V^2/R dt = C (T_95 - T_amb) +
    # Lambda int (T - T_amb) dt, with T(t) from solve_ivp (not the closed form)
    from scipy.integrate import solve_ivp

    d, ref = _closed_form(EXAMPLE_1, 12.0)
    l_m, r = ref["l_m"], ref["r"]
    cap, loss = NY.heat_capacity_per_length * l_m, ref["lam"] * l_m

    def rhs(t, y):
        return [(144.0 / r - loss * (y[0] - NY.t_amb)) / cap, y[0] - NY.t_amb]

    sol = solve_ivp(rhs, (0, d["heating_time"]), [NY.t_amb, 0.0], rtol=1e-11, atol=1e-11)
    t_end, excess = sol.y[0, -1], sol.y[1, -1]
    assert t_end == pytest.approx(ref["t_hot"], rel=1e-8)
    stored_and_lost = cap * (t_end - NY.t_amb) + loss * excess
    assert d["heating_energy"] == pytest.approx(stored_and_lost, rel=1e-7)


def test_without_a_supply_the_dynamics_are_nan_and_the_flag_clear():
    d = nf.design_limits(**EXAMPLE_1)
    assert all(math.isnan(d[n]) for n in DYNAMIC)
    assert not d["validity"] & VALIDITY_FLAGS["efficiency_beyond_bound"]


def test_every_fig12_design_at_12_volts_has_a_positive_efficiency_within_the_bound():
    cfg = nf.load_config("configs/fig12.yaml")
    grid = np.meshgrid(*cfg.axes.values(), indexing="ij")
    d = nf.evaluate(*grid, supply_voltage=12.0)
    eff = d["efficiency"]
    assert eff.size == 11808
    assert np.all(eff > 0)
    flagged = (d["validity"] & VALIDITY_FLAGS["efficiency_beyond_bound"]) != 0
    assert np.all((eff <= EFFICIENCY_BOUND) | flagged)
    np.testing.assert_array_equal(flagged, eff > EFFICIENCY_BOUND)
    assert np.all(np.isfinite(d["cycle_rate"])) and np.all(d["cycle_rate"] > 0)


def test_a_sweep_with_a_supply_stores_the_dynamics_and_one_without_does_not(tmp_path):
    from nylonflex.config import parse_config

    raw = {"name": "dyn", "grid": {"radius": {"values": [7.5, 20], "units": "mm"},
                                   "wall_thickness": {"values": [2, 6], "units": "mm"},
                                   "length": {"values": [70, 90], "units": "mm"},
                                   "coil_index": {"values": [1.1, 1.7]},
                                   "wrap_angle": {"values": [8], "units": "deg"}},
           "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 3},
                      "pressure": {"start": 0, "stop": 40, "num": 3, "units": "kPa"}}}
    plain = nf.run_sweep(parse_config(raw))
    assert not set(DYNAMIC) & set(plain.data_vars)
    ds = nf.run_sweep(parse_config({**raw, "supply": {"voltage": 12},
                                    "cooling": {"set": "forced_air", "speed": 1}}))
    grid = np.meshgrid(*(ds[a].values for a in ("radius", "wall_thickness", "length",
                                                 "coil_index", "wrap_angle")), indexing="ij")
    ev = nf.evaluate(*grid, supply_voltage=12.0, cooling={"set": "forced_air", "speed": 1})
    for name in DYNAMIC:
        assert ds[name].attrs["units"] == {"cycle_time": "s", "cycle_rate": "Hz",
                                           "heating_energy": "J", "mechanical_work": "J",
                                           "efficiency": "1"}[name]
        np.testing.assert_allclose(ds[name].values, ev[name], rtol=1e-12, err_msg=name)
    with pytest.raises(InputError, match="cooling: must be one of"):
        parse_config({**raw, "cooling": "breeze"})


def _small_supply_cube():
    from nylonflex.config import parse_config

    return nf.run_sweep(parse_config({
        "name": "dyn_charts", "supply": {"voltage": 12},
        "grid": {"radius": {"values": [5, 10, 15], "units": "mm"},
                 "wall_thickness": {"values": [1, 2], "units": "mm"},
                 "length": {"values": [90], "units": "mm"},
                 "coil_index": {"values": [1.1, 1.7]},
                 "wrap_angle": {"values": [5, 8, 20], "units": "deg"}},
        "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 3},
                   "pressure": {"start": 0, "stop": 40, "num": 3, "units": "kPa"}}}))


def test_dynamic_charts_draw_into_a_given_axes_or_their_own_figure():
    from matplotlib.figure import Figure

    from nylonflex.charts import CHARTS, cycle_rate_lines, cycle_rate_map, force_rate

    ds = _small_supply_cube()
    for f in (cycle_rate_map, cycle_rate_lines, force_rate):
        assert CHARTS[f.__name__] is f
        fig = f(ds)
        assert isinstance(fig, Figure)
        host = Figure()
        ax = host.add_subplot()
        assert f(ds, ax=ax) is host
        assert ax.get_ylabel() in ("wrap angle [deg]", "cycle rate [Hz]",
                                   "maximum tip force [N]")
    # the front of force_rate: the largest force among designs at least as fast
    fig = force_rate(ds)
    line = [ln for ln in fig.axes[0].get_lines() if ln.get_label().startswith("largest")][0]
    assert max(line.get_ydata()) == pytest.approx(float(ds["tip_force_max"].max()))
    plain = ds.drop_vars(list(DYNAMIC))
    with pytest.raises(InputError, match="cycle_rate: the cube has none"):
        cycle_rate_map(plain)


def test_a_fit_thermal_file_replaces_both_constants_and_refuses_a_cooling_set(tmp_path):
    # docs/model.md s. 9: a fitted lambda' and a measured r' replace the set's, r' then the
    # same at every coil index (resistance_coil_index 0); cooling: beside it is refused
    from helpers import fitted_thermal_file
    from nylonflex.config import parse_config

    lam, lm, r_meas = 0.05, 0.3, 40.0
    ny = nylon_parameters({"file": str(fitted_thermal_file(tmp_path, lam=lam, lm=lm,
                                                            r_meas=r_meas))})
    assert ny.heat_loss_per_length == pytest.approx(lam, rel=1e-6)
    assert ny.resistance_coil_index == 0.0
    for c in (1.1, 1.7):
        assert float(thermal.coil_resistance_per_length(c, ny)) == pytest.approx(
            r_meas / lm, rel=1e-12)
    raw = {"name": "fitted", "nylon": {"file": str(tmp_path / "n.yaml")},
           "grid": {"radius": {"values": [10], "units": "mm"},
                    "wall_thickness": {"values": [2], "units": "mm"},
                    "length": {"values": [90], "units": "mm"},
                    "coil_index": {"values": [1.3]},
                    "wrap_angle": {"values": [8], "units": "deg"}},
           "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 3},
                      "pressure": {"start": 0, "stop": 40, "num": 3, "units": "kPa"}}}
    assert parse_config(raw).cooling is None
    with pytest.raises(InputError, match="cooling: the nylon set's heat_loss_per_length is "
                                         "fitted"):
        parse_config({**raw, "cooling": "still_air"})
