"""Issue 46: a bare number is never silently read in another unit, at every edge: configs
(a bare angle that may be radians is refused; a length or pressure that would be in range
in another unit names it), ``query --where`` (a note when the answer hints at a slip) and
``ds.nf.sel`` (tests/test_sweep.py)."""

import copy
import math

import pytest
from helpers import TINY, run, write_config, write_cube

from nylonflex.config import parse_config
from nylonflex.units import InputError, plainly_degrees


def with_axis(name, axis, where="grid"):
    raw = copy.deepcopy(TINY)
    raw[where][name] = axis
    return raw


def test_bare_radians_for_a_wrap_angle_are_refused_naming_the_slip():
    # the config: 0.14 rad (8 deg) typed bare used to sweep 0.14 deg, muscle 4 m long
    with pytest.raises(InputError, match=r"^grid\.wrap_angle\.values\[0\]: 0\.14 has no unit; "
                       r"it reads as 0\.14 deg - did you mean 0\.14 rad \(8\.02 deg\)\? "
                       r"write '8\.02deg' or '0\.14rad'"):
        parse_config(with_axis("wrap_angle", {"values": [0.14, 0.21]}))
    with pytest.raises(InputError, match=r"grid\.wrap_angle\.start: 0\.1 has no unit"):
        parse_config(with_axis("wrap_angle", {"start": 0.1, "stop": 0.3, "num": 3}))


@pytest.mark.parametrize("axis, degrees", [
    ({"values": [0.14, 0.21], "units": "deg"}, [0.14, 0.21]),   # the unit stated: as typed
    ({"values": ["0.14rad", "0.21 rad"]}, [math.degrees(0.14), math.degrees(0.21)]),
    ({"values": [1, 20]}, [1, 20]),             # 20 is plainly degrees, so the axis is
    ({"values": [5, 8, 12]}, [5, 8, 12]),       # the shipped configs' bare form
])
def test_an_angle_with_its_unit_or_plainly_degrees_is_read(axis, degrees):
    cfg = parse_config(with_axis("wrap_angle", axis))
    assert cfg.axes["wrap_angle"] == pytest.approx([math.radians(d) for d in degrees],
                                                   rel=1e-12)


def test_the_plainly_degrees_rule():
    hi = math.radians(80.0)  # wrap_angle's largest, 1.396 rad
    assert plainly_degrees(0.0, hi) and plainly_degrees(1.4, hi) and plainly_degrees(-5, hi)
    assert not plainly_degrees(1.0, hi) and not plainly_degrees(0.14, hi)


def test_a_lone_bare_one_is_ambiguous():
    with pytest.raises(InputError, match=r"1 has no unit.*1 rad \(57\.3 deg\)"):
        parse_config(with_axis("wrap_angle", {"values": [1]}))


@pytest.mark.parametrize("name, axis, hint", [
    ("radius", {"values": [0.0075]}, r"got 0\.0075 mm; did you mean 0\.0075 m \(7\.5 mm\)\? "
                                      r"write '7\.5mm'"),
    ("wall_thickness", {"values": [0.002]}, r"did you mean 0\.002 m \(2 mm\)"),
    ("length", {"values": [0.07]}, r"did you mean 0\.07 m \(70 mm\)"),
])
def test_a_length_in_metres_typed_bare_names_the_metres(name, axis, hint):
    with pytest.raises(InputError, match=rf"^grid\.{name}\.values\[0\]: must be in .* {hint}"):
        parse_config(with_axis(name, axis))


def test_a_pressure_in_pascals_typed_bare_names_the_pascals():
    with pytest.raises(InputError, match=r"curves\.pressure\.stop: .*got 30000 kPa; did you "
                       r"mean 30000 Pa \(30 kPa\)\? write '30kPa'"):
        parse_config(with_axis("pressure", {"start": 0, "stop": 30000, "num": 6},
                               "curves"))


def test_a_bare_radian_in_a_config_file_exits_2_with_one_line(tmp_path, capsys):
    cfg = write_config(tmp_path, with_axis("wrap_angle", {"values": [0.14, 0.21]}))
    rc, out, err = run(capsys, "sweep", cfg, "--dry-run")
    assert rc == 2 and out == "" and len(err.strip().splitlines()) == 1
    assert "wrap_angle.values[0]: 0.14 has no unit" in err


@pytest.fixture(scope="module")
def cube(tmp_path_factory):
    return write_cube(tmp_path_factory.mktemp("edges"), TINY)


def test_where_with_units_and_a_note_when_a_bare_number_hints_at_a_slip(cube, capsys):
    rc, out, err = run(capsys, "query", cube, "--where", "radius <= 0.01")
    assert rc == 0 and "0 designs" in out
    assert err.strip() == ('nylonflex query: note: --where "radius <= 0.01": the bare 0.01 '
                           "is read in mm (0.01 mm); the cube's radius spans 5 .. 15 mm; "
                           "write '0.01m' for m")
    rc, out, err = run(capsys, "query", cube, "--where", "radius <= 10mm", "--format", "json")
    assert rc == 0 and err == "" and '"radius": 0.0125' not in out and '"radius": 0.01' in out
    # 3.14 read as deg is below every design's bend: every design matches, and it is said
    rc, out, err = run(capsys, "query", cube, "--where", "bend_angle_max >= 3.14")
    assert rc == 0 and "20 designs" in out
    assert "the bare 3.14 is read in deg (3.14 deg); the cube's bend_angle_max spans" in err
    assert "write '3.14rad' for rad" in err
    rc, out, err = run(capsys, "query", cube, "--where", "bend_angle_max >= 3.14rad")
    assert rc == 0 and err == ""
    # a plausible bare value that matches says nothing
    rc, out, err = run(capsys, "query", cube, "--where", "radius <= 10")
    assert rc == 0 and err == ""


def test_at_off_the_cube_names_the_unit_of_a_bare_number(cube, capsys):
    rc, out, err = run(capsys, "query", cube, "--at", "radius=0.0075")
    assert rc == 2 and err.strip().endswith("radius takes 5, 7.5, 10, 12.5, 15 mm (a bare "
                                            "number is read in mm)")
