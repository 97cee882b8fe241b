import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import naive
from conftest import DEG, EXAMPLE_1, EXAMPLE_2
from nylonflex import design_limits
from nylonflex.materials import nylon_parameters, silicone_parameters
from nylonflex.physics import bending, chamber, nylon, wrap
from nylonflex.physics.limits import DESIGN_VARIABLES

NAMES = {"usable_stroke", "limit", "pressure_max", "torque_max", "tip_force_max",
         "bend_angle_max", "range_fraction", "nylon_force_max", "nylon_use",
         # issue 10: heating, supply and validity
         "muscle_length", "resistance", "heating_power", "heating_voltage", "cooling_time",
         "heating_time", "validity",
         # issue 29: the dynamics with a supply (docs/model.md s. 20)
         "cycle_time", "cycle_rate", "heating_energy", "mechanical_work", "efficiency"}


def test_returns_every_design_variable_of_the_cube_table():
    # docs/interface.md, the cube's design variables
    assert set(design_limits(**EXAMPLE_2)) == NAMES == set(DESIGN_VARIABLES)


def test_paper_example_1_large_actuator():
    # paper section 4 / docs/model.md section 8: (20, 6, 90 mm, C 1.1) ~ 1.2 N, full range
    d = design_limits(**EXAMPLE_1)
    assert d["tip_force_max"] == pytest.approx(1.20, rel=0.01)
    assert d["limit"] == 0
    assert d["range_fraction"] == 1.0  # exactly: a full range of motion
    assert d["usable_stroke"] == 0.054


def test_paper_example_2_small_actuator():
    # paper section 4 / docs/model.md section 8: (7.5, 2, 70 mm, C 1.7) ~ 0.15 N
    d = design_limits(**EXAMPLE_2)
    assert d["tip_force_max"] == pytest.approx(0.150, rel=0.01)
    assert d["limit"] == 0
    assert d["range_fraction"] == 1.0


def test_stroke_limited_values_follow_the_closed_forms():
    d = design_limits(**EXAMPLE_2)
    p = 101325 * (1 / (1 - 0.097) ** 2 - 1)  # Boyle at s_max(1.7)
    m = p * (4 * 7.5e-3**3 + 3 * math.pi * 7.5e-3**2 * 2e-3) / 6  # eq. (16)
    assert d["pressure_max"] == pytest.approx(p, rel=1e-14)
    assert d["torque_max"] == pytest.approx(m, rel=1e-14)
    assert d["tip_force_max"] == pytest.approx(m / 0.07, rel=1e-14)
    assert d["bend_angle_max"] == pytest.approx(bending.bend_angle(p, 7.5e-3, 2e-3, 0.07),
                                                rel=1e-12)


# a large actuator with a steep wrap: strength-limited (docs/model.md section 8)
STRONG = dict(radius=25e-3, wall_thickness=6e-3, length=90e-3, coil_index=1.7,
              wrap_angle=25 * DEG)


def test_strength_limited_design():
    d = design_limits(**STRONG)
    assert d["limit"] == 1
    assert d["nylon_use"] == pytest.approx(1.0, rel=1e-9)  # F_n(s*) = F_lim
    assert d["usable_stroke"] < nylon.stroke_max(1.7)
    # range fraction [choice]: theta* / theta(s_max), theta(s_max) from the physics
    full = bending.bend_angle(chamber.chamber_pressure(0.097), 25e-3, 6e-3, 90e-3)
    assert d["range_fraction"] == pytest.approx(d["bend_angle_max"] / full, rel=1e-9)
    assert 0 < d["range_fraction"] < 1


@pytest.mark.parametrize("design", [EXAMPLE_1, EXAMPLE_2, STRONG,
                                    dict(STRONG, radius=12e-3, wrap_angle=15 * DEG)])
def test_stroke_limit_matches_slow_reference(design):
    ny = nylon_parameters()
    mu, alpha = silicone_parameters().arrays()
    c, t = design["coil_index"], design["wall_thickness"]
    s_ref = naive.stroke_limit(nylon.nylon_force_limit(c), nylon.stroke_max(c), design["radius"],
                             t, t, design["wrap_angle"], c, mu, alpha, ny.fibre_diameter)
    assert design_limits(**design)["usable_stroke"] == pytest.approx(s_ref, rel=1e-9)


def test_nylon_force_formula_against_reference():
    mu, alpha = silicone_parameters().arrays()
    for s in (0.0, 0.03, 0.09):
        got = wrap.nylon_force(s, 12e-3, 3e-3, 10 * DEG, 1.3)
        exp = naive.nylon_force(s, 12e-3, 3e-3, 3e-3, 10 * DEG, 1.3, mu, alpha, 0.34e-3)
        assert got == pytest.approx(exp, rel=1e-14)


def test_wrap_pitch_choice_helix_or_touching_turns():
    # docs/model.md section 4 [choice]: pitch = max(P_out tan psi, w / cos psi), w = d_f (C + 1)
    p_out = math.pi * 9.5e-3 + 2 * 9.5e-3 + 2 * 2e-3
    assert wrap.outer_perimeter(7.5e-3, 2e-3) == pytest.approx(p_out)
    assert wrap.wrap_pitch(7.5e-3, 2e-3, 8 * DEG, 1.7) == pytest.approx(p_out * math.tan(8 * DEG))
    w = 0.34e-3 * 2.7
    assert wrap.wrap_pitch(7.5e-3, 2e-3, 0.5 * DEG, 1.7) == pytest.approx(w / math.cos(0.5 * DEG))
    turns = wrap.wrap_turns(7.5e-3, 2e-3, 70e-3, 8 * DEG, 1.7)
    assert wrap.muscle_length(7.5e-3, 2e-3, 70e-3, 8 * DEG, 1.7) == pytest.approx(
        turns * p_out / math.cos(8 * DEG))


@settings(max_examples=20, deadline=None)
@given(st.floats(5e-3, 25e-3), st.floats(1e-3, 6e-3), st.floats(1.1, 1.7),
       st.floats(2 * DEG, 30 * DEG), st.floats(0.03, 0.2), st.floats(0.03, 0.2))
def test_nylon_force_and_limits_independent_of_length(a, t, c, psi, l1, l2):
    # docs/model.md section 4: F_n independent of L; section 6: theta proportional to L
    d1, d2 = design_limits(a, t, l1, c, psi), design_limits(a, t, l2, c, psi)
    for k in ("usable_stroke", "limit", "pressure_max", "torque_max", "nylon_force_max",
              "nylon_use", "range_fraction"):
        assert d1[k] == d2[k]
    assert d1["bend_angle_max"] / l1 == pytest.approx(d2["bend_angle_max"] / l2, rel=1e-14)
    assert d1["tip_force_max"] * l1 == pytest.approx(d2["tip_force_max"] * l2, rel=1e-14)


def test_steeper_wrap_reaches_the_limit_sooner():
    # paper section 4: a larger wrap angle loads fewer turns
    uses = [design_limits(15e-3, 3e-3, 0.09, 1.3, psi * DEG)["nylon_use"] for psi in (5, 10, 20)]
    assert uses[0] < uses[1] < uses[2]


def test_broadcasts_arrays():
    a = np.array([6e-3, 10e-3, 20e-3])
    d = design_limits(a[:, None], 2e-3, 0.07, np.array([1.1, 1.7]), 8 * DEG)
    assert d["tip_force_max"].shape == (3, 2)
    assert d["limit"].dtype == np.int8
    assert d["tip_force_max"][1, 1] == pytest.approx(
        design_limits(10e-3, 2e-3, 0.07, 1.7, 8 * DEG)["tip_force_max"], rel=1e-15)


@pytest.mark.parametrize("override,match", [
    (dict(radius=0.0), r"radius: must be in \[0.0005, 0.2\] m, got 0 m"),
    (dict(radius=-7.5e-3), r"radius: must be in \[0.0005, 0.2\] m"),
    (dict(wall_thickness=0.0), r"wall_thickness: must be in \[0.0001, 0.05\] m"),
    (dict(length=-1.0), r"length: must be in \[0.001, 2\] m"),
    (dict(coil_index=1.05), r"coil_index: must be in \[1.1, 1.7\] .*, got 1.05"),
    (dict(coil_index=2.0), r"coil_index: must be in \[1.1, 1.7\]"),
    (dict(wrap_angle=0.0), r"wrap_angle: must be in \[0.00174533, 1.39626\] rad"),
    (dict(wrap_angle=math.pi / 2), r"wrap_angle: must be in \[0.00174533, 1.39626\]"),
    (dict(base_thickness=0.0), r"base_thickness: must be in \[0.0001, 0.05\] m"),
    (dict(radius=float("nan")), r"radius: must be in \[0.0005, 0.2\] m, got nan"),
    (dict(length=float("inf")), r"length: must be in \[0.001, 2\] m, got inf"),
    # unit slips: mm typed where the API takes metres, deg for radians (registry ranges)
    (dict(radius=7.5), r"radius: .*got 7.5 m; 7.5 looks like mm: the Python API takes metres"),
    (dict(wrap_angle=8.0), r"wrap_angle: .*8 looks like deg: the Python API takes radians"),
    (dict(silicone="latex"), r"silicone: unknown set 'latex'"),
    (dict(nylon="steel"), r"nylon: unknown set 'steel'"),
    (dict(radius="big"), r"radius: must be a number"),
])
def test_bad_values_raise_naming_the_parameter_never_nan(override, match):
    with pytest.raises(ValueError, match=match):
        design_limits(**{**EXAMPLE_2, **override})
