"""Issue 10: heating and supply, model variants and validity flags (docs/model.md s. 15-17).

Each variant is pinned on a closed form or a limit case; each flag on a design that must
carry it. Expected numbers say where they come from.
"""

import math

import numpy as np
import pytest

import nylonflex as nf
from conftest import DEG, EXAMPLE_1, EXAMPLE_2
from nylonflex.config import parse_config
from nylonflex.physics import nylon, thermal, wrap
from nylonflex.physics.bending import _material_moment_of, quadrature_nodes
from nylonflex.physics.chamber import P_ATM, _gauge_pressure, _gauge_pressure_wall, _solid_fraction
from nylonflex.physics.limits import MODELS, design_limits as python_loop
from nylonflex.variables import SUPPLY_ONLY
from nylonflex.physics.nylon import _temperature_for_stroke
from nylonflex.physics.silicone import _equibiaxial_stress_and_slope, _stress_and_slope
from nylonflex.materials import nylon_parameters, silicone_parameters
from nylonflex.sweep.conductor import run_sweep
from nylonflex.units import InputError

NY = nylon_parameters("silver_nylon66")
MU, ALPHA = silicone_parameters("tc5005").arrays()


def test_inverse_of_eq2_matches_brentq():
    # the Numba-compilable safeguarded Newton against scipy's brentq (physics.nylon)
    k = nylon.stroke_max(1.3) / nylon._stroke_shape(NY.t_max, NY.t_amb, NY.gamma, NY.beta,
                                                     NY.t_g, NY.sigma_g)
    for s in (1e-5, 0.01, 0.034, 0.0679):
        t = _temperature_for_stroke(s, k, NY.t_amb, NY.t_max, NY.gamma, NY.beta, NY.t_g,
                                    NY.sigma_g)
        assert t == pytest.approx(nylon.temperature_for_stroke(s, 1.3), rel=1e-12)


def test_heating_closed_forms_for_the_first_example():
    # issue 10: 0.65 m of muscle; R = r' l_m, P = lambda' l_m (T* - T_amb), V = sqrt(R P);
    # a stroke-limited design works at T_max. Issue 30: r' = 0.15 ohm/mm at C = 1.7 scaled
    # by sqrt((pi C)^2 + 1) (docs/model.md s. 9): 99.3 ohm/m at C = 1.1, so 64.2 ohm (it
    # was 97 ohm with one r' for every C)
    d = nf.design_limits(**EXAMPLE_1)
    l_m = wrap.muscle_length(20e-3, 6e-3, 90e-3, 8 * DEG, 1.1)
    assert d["muscle_length"] == pytest.approx(l_m, rel=1e-12)
    assert d["muscle_length"] == pytest.approx(0.65, abs=0.01)
    r_per_len = 150.0 * math.sqrt((math.pi * 1.1) ** 2 + 1) / math.sqrt((math.pi * 1.7) ** 2 + 1)
    assert d["resistance"] == pytest.approx(r_per_len * l_m, rel=1e-12)
    assert d["resistance"] == pytest.approx(64.2, abs=0.05)
    power = NY.heat_loss_per_length * l_m * (NY.t_max - NY.t_amb)
    assert d["heating_power"] == pytest.approx(power, rel=1e-9)
    assert d["heating_voltage"] == pytest.approx(math.sqrt(r_per_len * l_m * power), rel=1e-9)
    # cooling: T(t) = T_amb + (T* - T_amb) exp(-t/tau) down to the 5 % stroke temperature
    tau = thermal.thermal_time_constant()
    t_c = nylon.temperature_for_stroke(0.05 * 0.054, 1.1)
    expected = tau * math.log((NY.t_max - NY.t_amb) / (t_c - NY.t_amb))
    assert d["cooling_time"] == pytest.approx(expected, rel=1e-9)
    assert math.isnan(d["heating_time"])  # no supply given


def test_12_volts_limit_the_first_example_not_the_second():
    # issue 10: at 12 V example 1 reaches only T_ss (supply-limited, limit 2, smaller tip
    # force); example 2's shorter muscle reaches T_max. Issue 30: with r'(1.1) = 99.3 ohm/m
    # T_ss is 140.6 degC (it was 100.7 with 150 ohm/m) and F* 1.085 N (was 0.545 N)
    free = nf.design_limits(**EXAMPLE_1)
    d1 = nf.design_limits(**EXAMPLE_1, supply_voltage=12.0)
    t_ss = thermal.steady_temperature(12.0, d1["muscle_length"], coil_index=1.1)
    assert t_ss - 273.15 == pytest.approx(140.6, abs=0.1)
    assert d1["limit"] == 2
    assert d1["usable_stroke"] == pytest.approx(nylon.stroke(t_ss, 1.1), rel=1e-12)
    assert d1["tip_force_max"] == pytest.approx(1.085, abs=0.001)
    assert d1["tip_force_max"] < free["tip_force_max"]
    assert d1["heating_voltage"] == pytest.approx(12.0, rel=1e-9)  # it works at T_ss
    assert d1["heating_time"] > 0
    d2 = nf.design_limits(**EXAMPLE_2, supply_voltage=12.0)
    assert d2["limit"] == 0
    assert d2["tip_force_max"] == nf.design_limits(**EXAMPLE_2)["tip_force_max"]


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("voltage", [None, 9.0])
def test_compiled_variants_match_the_python_loop(model, voltage):
    rng = np.random.default_rng(3)
    n = 40
    d = dict(radius=rng.uniform(5e-3, 25e-3, n), wall_thickness=rng.uniform(1e-3, 6e-3, n),
             length=rng.uniform(20e-3, 150e-3, n), coil_index=rng.uniform(1.1, 1.7, n),
             wrap_angle=rng.uniform(3, 25, n) * DEG)
    fast = nf.evaluate(**d, model=model, supply_voltage=voltage)
    slow = python_loop(*d.values(), model=model, supply_voltage=voltage)
    for name, v in slow.items():
        np.testing.assert_allclose(fast[name], v, rtol=1e-12, atol=0, err_msg=name)


def test_paper_through_the_variant_path_is_the_paper():
    # a supply too strong to bind sends the paper's model through _model_state_nodes: same numbers
    a = nf.design_limits(**EXAMPLE_1)
    b = nf.design_limits(**EXAMPLE_1, supply_voltage=1000.0)
    for name in a:
        if name not in SUPPLY_ONLY:  # heating_time and the dynamics need a supply
            assert a[name] == b[name], name


def test_coupled_muscle_with_an_infinitely_strong_muscle_is_the_paper():
    # F_b -> inf: the wrap settles at the free stroke (docs/model.md s. 16). 1e12 N/K is far
    # outside what a config may give (materials.NYLON_RANGES), so the limit case is built
    # as a Nylon object, which is taken as it is
    import dataclasses

    strong = dataclasses.replace(nf.nylon_parameters(), thermal_force_coefficient=1e12)
    for ex in (EXAMPLE_1, EXAMPLE_2):
        p = nf.design_limits(**ex, nylon=strong)
        c = nf.design_limits(**ex, nylon=strong, model="coupled_muscle")
        assert c["limit"] == p["limit"] == 0
        assert c["usable_stroke"] == pytest.approx(p["usable_stroke"], rel=1e-9)
        assert c["tip_force_max"] == pytest.approx(p["tip_force_max"], rel=1e-8)


def test_coupled_muscle_settles_on_the_muscle_line():
    # F_n(s) = F_b (1 - s/s_free) at the settled stroke, F_b = c (T_max - T_amb): load-limited
    c = nf.design_limits(**EXAMPLE_2, model="coupled_muscle")
    f_b = NY.thermal_force_coefficient * (NY.t_max - NY.t_amb)
    assert c["limit"] == 3
    assert c["nylon_force_max"] == pytest.approx(f_b * (1 - c["usable_stroke"] / 0.097),
                                                 rel=1e-9)


def test_paper_eq10_hoop_stress_closed_form():
    # l_theta = l_l = l, l_r = l^-2: S = sum mu (l^(a-1) - l^(-2a-1)) vs the paper's plane
    # strain S = sum mu (l^(a-1) - l^(-a-1)); equal at l = 1, different slopes
    for lam in (1.0, 0.95, 0.9):
        s10, _ = _equibiaxial_stress_and_slope(lam, MU, ALPHA)
        expected = sum(m * (lam ** (a - 1) - lam ** (-2 * a - 1)) for m, a in zip(MU, ALPHA))
        assert s10 == pytest.approx(expected, rel=1e-13, abs=1e-12)
    assert _equibiaxial_stress_and_slope(1.0, MU, ALPHA)[0] == 0.0
    # slope by finite difference
    h = 1e-6
    s_p, s_m = (_equibiaxial_stress_and_slope(0.9 + x, MU, ALPHA)[0] for x in (h, -h))
    assert _equibiaxial_stress_and_slope(0.9, MU, ALPHA)[1] == pytest.approx(
        (s_p - s_m) / (2 * h), rel=1e-7)
    assert abs(_equibiaxial_stress_and_slope(0.9, MU, ALPHA)[0]) > \
        abs(_stress_and_slope(0.9, MU, ALPHA)[0])


def test_incompressible_wall_with_a_vanishing_wall_is_boyle():
    # phi = A_s/A_out -> 0 gives the paper's V1/V2 = (1 - s)^-2
    phi = _solid_fraction(20e-3, 1e-9, 1e-9)
    assert phi < 1e-6
    for s in (0.0, 0.03, 0.097):
        p, _ = _gauge_pressure_wall(s, 101325.0, 0.0)
        assert p == pytest.approx(_gauge_pressure(s, 101325.0), rel=1e-13, abs=1e-9)
        assert _gauge_pressure_wall(s, 101325.0, phi)[0] == pytest.approx(
            _gauge_pressure(s, 101325.0), rel=1e-5, abs=1e-6)
    # closes at (1 - s)^2 = phi: infinite, never NaN
    assert _gauge_pressure_wall(1 - math.sqrt(0.5) + 1e-9, 101325.0, 0.5)[0] == math.inf


def test_chamber_closes_is_flagged_not_nan():
    # a = 5, t = b = 6 mm: phi = 0.878, so the chamber closes at s = 0.063 < s_max(1.7)
    d = nf.design_limits(5e-3, 6e-3, 70e-3, 1.7, 8 * DEG, model="incompressible_wall")
    assert d["validity"] & 8
    assert d["limit"] == 1 and np.isfinite(d["tip_force_max"])
    assert d["usable_stroke"] < 1 - math.sqrt(_solid_fraction(5e-3, 6e-3, 6e-3))
    assert d["range_fraction"] == 0.0


def test_cauchy_and_nominal_moments_agree_at_small_strain():
    nodes = quadrature_nodes()
    for kappa, rtol in ((1e-4, 1e-5), (1e-2, 1e-3)):
        nom = _material_moment_of(kappa, 10e-3, 2e-3, 2e-3, MU, ALPHA, *nodes, False)[0]
        cau = _material_moment_of(kappa, 10e-3, 2e-3, 2e-3, MU, ALPHA, *nodes, True)[0]
        assert cau == pytest.approx(nom, rel=rtol)
    # and differ at a large bend: the Cauchy stress l S is stiffer in tension
    c = nf.design_limits(**EXAMPLE_2, model="cauchy_moment")
    assert c["bend_angle_max"] < nf.design_limits(**EXAMPLE_2)["bend_angle_max"]


def test_validity_bits():
    # self_contact: theta* > 360 deg; under_one_turn: L < pitch; stretch_beyond_fit: a
    # silicone fitted only to stretch 1.01
    d = nf.evaluate(7.5e-3, 2e-3, np.array([70e-3, 300e-3]), 1.7, 8 * DEG)
    assert list(d["bend_angle_max"] > 2 * math.pi) == [False, True]
    assert list(d["validity"] & 1) == [0, 1]
    short = nf.design_limits(25e-3, 1e-3, 5e-3, 1.1, 20 * DEG)
    assert short["validity"] & 4
    tight = nf.design_limits(**EXAMPLE_2, silicone={"set": "tc5005",
                                                    "stretch_range": [1.0, 1.01]})
    assert tight["validity"] & 2
    assert nf.design_limits(**EXAMPLE_2)["validity"] == 0


def test_implausible_silicone_stiffness_is_refused():
    # mu typed in kPa: 1,000 times too small
    with pytest.raises(ValueError, match=r"silicone.mu: .*implausible.*look like kPa"):
        nf.design_limits(**EXAMPLE_2, silicone={"set": "tc5005", "mu": [56.19, 10.49]})
    with pytest.raises(ValueError, match=r"silicone.mu"):
        nf.evaluate(**EXAMPLE_2, silicone={"set": "tc5005", "mu": np.array([[56.19, 10.49]])})


SMALL = {
    "name": "variants",
    "grid": {"radius": {"values": [5, 12, 20], "units": "mm"},
             "wall_thickness": {"values": [2, 6], "units": "mm"},
             "length": {"values": [70, 90], "units": "mm"},
             "coil_index": {"values": [1.1, 1.7]},
             "wrap_angle": {"values": [8], "units": "deg"}},
    "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 5},
               "pressure": {"start": 0, "stop": 20, "num": 5, "units": "kPa"}},
}


def test_a_cube_of_every_model_has_a_model_dimension(tmp_path):
    cfg = parse_config({**SMALL, "model": list(MODELS), "supply": {"voltage": 12}})
    ds = run_sweep(cfg)
    assert list(ds["model"].values) == list(MODELS)
    assert ds["tip_force_max"].dims[-1] == "model"
    assert "model" not in ds["muscle_length"].dims
    # the blocked tip force is the model's moment over L: lateral_pressure's is larger
    assert ds["tip_force"].dims[-1] == "model"
    assert "heating_time" in ds
    one = run_sweep(parse_config({**SMALL, "model": "paper_eq10", "supply": {"voltage": 12}}))
    np.testing.assert_array_equal(ds["nylon_force"].sel(model="paper_eq10").values,
                                  one["nylon_force"].values)
    grids = np.meshgrid(*cfg.axes.values(), indexing="ij")
    exact = nf.evaluate(*grids, model="coupled_muscle", supply_voltage=12.0)
    np.testing.assert_allclose(ds["tip_force_max"].sel(model="coupled_muscle").values,
                               exact["tip_force_max"], rtol=1e-12)
    # and on disk
    run_sweep(cfg, out=tmp_path / "cube.h5")
    back = nf.open_cube(tmp_path / "cube.h5")
    assert list(back["model"].values) == list(MODELS)
    np.testing.assert_array_equal(back["validity"].values, ds["validity"].values)
    assert "flag_masks" in back["validity"].attrs


@pytest.mark.parametrize("raw, match", [
    ({"model": "stiff"}, r"model: must be one of paper"),
    ({"model": ["paper", "paper"]}, r"model: each variant once"),
    ({"supply": {"voltage": -3}}, r"supply.voltage: must be in \(0, 1000\] V"),
    ({"supply": {"voltage": 12, "units": "mm"}}, r"supply.units|not a voltage"),
])
def test_bad_model_or_supply_is_refused(raw, match):
    with pytest.raises(InputError, match=match):
        parse_config({**SMALL, **raw})


def test_a_supply_cube_is_asked_with_its_supply(tmp_path):
    # query --at between grid points and design re-evaluate with the cube's own settings,
    # the supply included (the resolved config stores it as supply_voltage)
    from nylonflex.engine.provenance import cube_settings
    from nylonflex.query import query_cube

    ds = run_sweep(parse_config({**SMALL, "supply": {"voltage": 12}}), tmp_path / "cube.h5")
    assert cube_settings(ds).supply_voltage == 12.0
    at = dict(EXAMPLE_1, radius=19.9e-3)  # between grid radii: the exact model
    res = query_cube(ds, at=at)
    exact = nf.evaluate(**at, supply_voltage=12.0)
    assert res.data["limit"][0] == exact["limit"] == 2
    assert res.data["tip_force_max"][0] == float(exact["tip_force_max"])


def test_the_grid_kernels_paper_eq10_force_takes_the_equibiaxial_hoop_stress():
    # the grid kernel computes paper_eq10's S_theta(s) in a branch of its own
    # (kernels/design.py); F_n = (p a + |S_theta| t) pitch / cos psi (paper eq. 9), so the
    # ratio of paper_eq10's F_n to the paper's at one design and stroke is
    # (p a + |S_eq10| t) / (p a + |S_paper| t), with p = p(s) of Boyle's law
    paper = run_sweep(parse_config(SMALL))
    eq10 = run_sweep(parse_config({**SMALL, "model": "paper_eq10"}))
    s = eq10["stroke"].values
    a = eq10["radius"].values[:, None, None, None, None]
    t = eq10["wall_thickness"].values[None, :, None, None, None]
    p = np.array([_gauge_pressure(x, P_ATM) for x in s])
    s10 = np.array([abs(_equibiaxial_stress_and_slope(1 - x, MU, ALPHA)[0]) for x in s])
    sp = np.array([abs(_stress_and_slope(1 - x, MU, ALPHA)[0]) for x in s])
    f_paper = paper["nylon_force"].values
    expected = f_paper * (p * a + s10 * t) / np.where(p * a + sp * t > 0, p * a + sp * t, 1)
    np.testing.assert_allclose(eq10["nylon_force"].values, expected, rtol=1e-12, atol=1e-15)
    assert not np.allclose(eq10["nylon_force"].values[..., 1:], f_paper[..., 1:], rtol=1e-6)
