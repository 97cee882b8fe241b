"""One condition grammar: the same table of conditions through ``--where``, a sweep's
``requirements:`` and a design's ``constraints:`` (conditions.py).

Each row: the text, then what each of the three makes of it, a ``(name, op, SI value)`` or
the pattern of the one-line refusal. The SI values are the typed numbers converted by hand
(1 N = 1 N; 25 kPa = 25e3 Pa; 20 mm = 0.020 m; 30 deg = pi/6 rad).
"""

import copy
import math

import numpy as np
import pytest

from nylonflex.config import parse_config
from nylonflex.design.spec import parse_spec
from nylonflex.query import Condition, parse_condition, parse_where
from nylonflex.conditions import parse_requirements
from nylonflex.units import InputError

SWEEP = {
    "name": "conditions",
    "grid": {"radius": {"values": [7.5], "units": "mm"},
             "wall_thickness": {"values": [2], "units": "mm"},
             "length": {"values": [70], "units": "mm"},
             "coil_index": {"values": [1.7]},
             "wrap_angle": {"values": [8], "units": "deg"}},
    "curves": {"stroke": {"values": [0.05]}, "pressure": {"values": [0]}},
}


def through_where(text):
    (c,) = parse_where([text])
    return c


def through_requirements(text):
    raw = copy.deepcopy(SWEEP)
    raw["requirements"] = [text]
    cfg = parse_config(raw)
    (c,) = parse_requirements(list(cfg.requirements))
    return c


def through_constraints(text):
    spec = parse_spec({"cube": "any.h5", "objectives": [{"max": "tip_force_max"}],
                       "constraints": [text]})
    (c,) = spec.constraints
    return c


#: text, --where, requirements:, constraints:
TABLE = [
    ("tip_force_max >= 0.5 N", ("tip_force_max", ">=", 0.5), ("tip_force_max", ">=", 0.5),
     ("tip_force_max", ">=", 0.5)),
    ("tip_force_max>=0.5", ("tip_force_max", ">=", 0.5), ("tip_force_max", ">=", 0.5),
     ("tip_force_max", ">=", 0.5)),
    ("pressure_max < 25 kPa", ("pressure_max", "<", 25e3), ("pressure_max", "<", 25e3),
     ("pressure_max", "<", 25e3)),
    ("bend_angle_max > 30 deg", ("bend_angle_max", ">", math.pi / 6),
     ("bend_angle_max", ">", math.pi / 6), ("bend_angle_max", ">", math.pi / 6)),
    ("radius <= 20 mm", ("radius", "<=", 0.020), r"requirements\[0\]: unknown name 'radius'",
     ("radius", "<=", 0.020)),
    ("radius = 7.5 mm", ("radius", "==", 0.0075), r"requirements\[0\]: expected 'NAME OP",
     ("radius", "==", 0.0075)),
    ("limit != supply", ("limit", "!=", 2.0), r"requirements\[0\]: expected 'NAME OP",
     ("limit", "!=", 2.0)),
    ("valid", ("validity", "==", 0.0), r"requirements\[0\]: expected 'NAME OP",
     ("validity", "==", 0.0)),
    ("tip_force >= 1 N", r"--where: unknown name 'tip_force'",
     r"requirements\[0\]: unknown name 'tip_force'", r"constraints\[0\]: unknown name 'tip_force'"),
    ("tip_force_max >= 1 kPa", r"--where tip_force_max: .*kPa",
     r"requirements\[0\] tip_force_max: .*kPa", r"constraints\[0\] tip_force_max: .*kPa"),
    ("tip_force_max 1 N", r"--where: expected 'NAME OP VALUE",
     r"requirements\[0\]: expected 'NAME OP VALUE", r"constraints\[0\]: expected 'NAME OP VALUE"),
    ("tip_force_max >= 1e999", ("tip_force_max", ">=", math.inf),
     r"requirements\[0\]: the value must be finite", ("tip_force_max", ">=", math.inf)),
]
PARSERS = {"--where": through_where, "requirements": through_requirements,
           "constraints": through_constraints}


@pytest.mark.parametrize("row", TABLE, ids=[r[0] for r in TABLE])
@pytest.mark.parametrize("parser", list(PARSERS))
def test_one_table_of_conditions_through_all_three(row, parser):
    text, expected = row[0], row[1 + list(PARSERS).index(parser)]
    if isinstance(expected, str):
        with pytest.raises(InputError, match=expected):
            PARSERS[parser](text)
        return
    c = PARSERS[parser](text)
    assert isinstance(c, Condition)
    assert (c.name, c.op) == expected[:2]
    assert c.value == pytest.approx(expected[2], rel=1e-12)
    assert c.text == ("validity == 0" if text == "valid" else text)  # as typed


def test_a_condition_is_its_name_op_and_value():
    # equal records whatever the spelling; the text is kept for messages, not compared
    assert parse_condition("radius=7.5mm") == Condition("radius", "==", 0.0075)
    assert parse_condition("radius == 7.5 mm") == parse_condition("radius=7.5mm")


@pytest.mark.parametrize("op, expected", [
    # x = [0.4, 0.5, 0.6, NaN] N against 0.5 N: NaN never meets a condition
    (">=", [False, True, True, False]), (">", [False, False, True, False]),
    ("<=", [True, True, False, False]), ("<", [True, False, False, False]),
    ("==", [False, True, False, False]), ("!=", [True, False, True, False]),
])
def test_mask_of_each_comparison(op, expected):
    x = np.array([0.4, 0.5, 0.6, np.nan])
    assert parse_condition(f"tip_force_max {op} 0.5 N").mask(x).tolist() == expected
