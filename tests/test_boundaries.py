"""Boundaries and constants pinned against their sources, not against the code's own values.

Each test here kills a behaviour-changing edit that the rest of the suite let through (the
code review of issue 47: a threshold moved by one comparison, a constant read back from the
code instead of its source, a closed bound loosened, a side effect dropped). Every expected
number is quoted from where it comes from.
"""

from __future__ import annotations

import math
import os
import stat
from pathlib import Path

import numpy as np
import pytest

from nylonflex.config.sweep import parse_config
from nylonflex.physics import thermal
from nylonflex.physics.limits import _validity
from nylonflex.physics.records import Section
from nylonflex.conditions import parse_condition
from nylonflex.files import atomic as files
from nylonflex.units import InputError

SECTION = Section(radius=7.5e-3, wall=2e-3, base=2e-3)  # the paper's example 2 [m]
NO_FLAG = dict(bend_angle=1.0, kappa=0.0, section=SECTION, stretch_max=10.0, turns=5.0,
               closes=False, efficiency=float("nan"))


def _flags(**change):
    return _validity(**{**NO_FLAG, **change})


def test_under_one_turn_is_strictly_fewer_than_one():
    """docs/model.md s. 17: bit 4 is "fewer than one turn of wrap"; one whole turn wraps
    the chamber once and is clean."""
    assert _flags(turns=1.0) == 0
    assert _flags(turns=1.0 - 1e-12) == 4
    assert _flags(turns=math.nextafter(1.0, 0.0)) == 4


def test_efficiency_bound_is_haines_1_32_percent():
    """Haines et al., Science 343:868 (2014): the highest efficiency of a coiled polymer
    muscle measured, 1.32 % (polyethylene). Above it the design sets bit 16; at it, not."""
    assert _flags(efficiency=0.0132) == 0
    assert _flags(efficiency=0.01321) == 16
    assert _flags(efficiency=0.0131) == 0
    # nylon 6,6's own 1.08 % (the same paper) is well inside
    assert _flags(efficiency=0.0108) == 0


def test_self_contact_is_past_one_full_turn_of_bend():
    """docs/model.md s. 17: self contact when theta* > 2 pi (the tip meets the base)."""
    assert _flags(bend_angle=2.0 * math.pi) == 0
    assert _flags(bend_angle=2.0 * math.pi * (1 + 1e-12)) == 1


def test_free_convection_uses_standard_gravity():
    """Churchill & Chu (1975) for a horizontal cylinder, evaluated by hand at a film
    temperature of exactly 350 K, where Incropera et al. (6th ed., Table A.4) give air
    k = 30.0e-3 W/(m K), nu = 20.92e-6 m^2/s, alpha = 29.9e-6 m^2/s, Pr = 0.700; g is the
    standard gravity 9.80665 m/s^2 (3rd CGPM, 1901)."""
    d, ts, ta = 0.9e-3, 375.0, 325.0
    ra = 9.80665 * (1.0 / 350.0) * (ts - ta) * d**3 / (20.92e-6 * 29.9e-6)
    nu_d = (0.60 + 0.387 * ra ** (1 / 6) / (1 + (0.559 / 0.700) ** (9 / 16)) ** (8 / 27)) ** 2
    expected = math.pi * 30.0e-3 * nu_d
    got = thermal.free_convection_loss_per_length(d, ts, ta)
    assert got == pytest.approx(expected, rel=1e-12)
    # g = 9.81 would move it by 1.7e-5 relative: far outside the tolerance above
    ra_981 = ra * 9.81 / 9.80665
    nu_981 = (0.60 + 0.387 * ra_981 ** (1 / 6) / (1 + (0.559 / 0.7) ** (9 / 16)) ** (8 / 27)) ** 2
    assert abs(math.pi * 30.0e-3 * nu_981 / got - 1.0) > 1e-6


def test_publish_fsyncs_the_folder_after_the_rename(tmp_path, monkeypatch):
    """A rename is durable only once its folder is fsync'd (POSIX rename(2); the journal's
    crash argument in docs/reliability.md rests on it): publish must fsync the folder after
    os.replace, not only the file before it."""
    events = []
    real_fsync, real_replace = os.fsync, os.replace

    def fsync(fd):
        events.append(("fsync", stat.S_ISDIR(os.fstat(fd).st_mode)))
        return real_fsync(fd)

    def replace(src, dst, *args, **kwargs):
        events.append(("replace", None))
        return real_replace(src, dst, *args, **kwargs)

    monkeypatch.setattr(os, "fsync", fsync)
    monkeypatch.setattr(os, "replace", replace)
    tmp = tmp_path / "x.tmp"
    tmp.write_bytes(b"data")
    files.publish(tmp, tmp_path / "x")
    assert (tmp_path / "x").read_bytes() == b"data"
    i = events.index(("replace", None))
    assert ("fsync", False) in events[:i]  # the file's bytes before the rename
    assert ("fsync", True) in events[i + 1:]  # the folder's entry after it


def _config(**grid):
    base = {"radius": {"values": [5, 10], "units": "mm"},
            "wall_thickness": {"values": [2], "units": "mm"},
            "length": {"values": [70], "units": "mm"},
            "coil_index": {"values": [1.7]},
            "wrap_angle": {"values": [8], "units": "deg"}}
    base.update(grid)
    return {"name": "t", "silicone": "tc5005", "nylon": "silver_nylon66", "grid": base,
            "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 3},
                       "pressure": {"start": 0, "stop": 25, "num": 3, "units": "kPa"}}}


def test_repeated_axis_values_are_refused():
    """An axis is a coordinate of the cube: xarray's label selection and the cube's
    monotonic coordinate need strictly increasing values (CF 1.8 s. 5: coordinate variables
    are strictly monotonic), so 5 mm given twice is an error, not a duplicate row."""
    with pytest.raises(InputError, match="strictly increasing"):
        parse_config(_config(radius={"values": [5, 5], "units": "mm"}), "t.yaml")
    with pytest.raises(InputError, match="strictly increasing"):
        parse_config(_config(radius={"values": [10, 5], "units": "mm"}), "t.yaml")


def test_closed_lower_bound_is_not_widened():
    """The registry's radius range is [0.5 mm, 200 mm], closed (variables.py, docs/model.md
    s. 1): 0.5 mm is accepted exactly; half a micrometre less (1e-6 of the bound's own
    units, far above the parser's float slack of 1e-12 m) is refused."""
    cfg = parse_config(_config(radius={"values": [0.5, 1], "units": "mm"}), "t.yaml")
    assert cfg.axes["radius"][0] == pytest.approx(0.5e-3, rel=1e-15)
    with pytest.raises(InputError, match="radius"):
        parse_config(_config(radius={"values": [0.4995, 1], "units": "mm"}), "t.yaml")
    with pytest.raises(InputError, match="radius"):
        parse_config(_config(radius={"values": [0.499999, 1], "units": "mm"}), "t.yaml")


def test_equality_condition_tolerates_float_noise_only():
    """"radius == 7.5 mm" must find 7.5e-3 m written as any float within its decimal noise
    (a few ulp, 1e-16 relative; docs/interface.md, the condition grammar) and nothing
    further: a value one part in 10^7 away is another value, not noise."""
    cond = parse_condition("radius == 7.5 mm")
    x = 7.5e-3
    noisy = np.array([x, np.nextafter(x, 1.0), x * (1 + 1e-12)])
    assert cond.mask(noisy).all()
    assert not cond.mask(np.array([x * (1 + 1e-7), x * (1 - 1e-7)])).any()
    assert not cond.mask(np.array([np.nan])).any()


def test_slab_plan_covers_every_radius_once():
    """The slabs partition the radius axis: every radius in exactly one slab, the last slab
    holding the remainder (one radius when n = k m + 1), never empty; and a slab budget
    smaller than one radius still gives one radius a slab (the floor), not zero."""
    from dataclasses import replace

    from nylonflex.engine.grid import bytes_per_radius, plan_slabs

    cfg = parse_config(_config(radius={"start": 5, "stop": 25, "num": 9, "units": "mm"}),
                       "t.yaml")
    per = bytes_per_radius(cfg)
    # four radii a slab: 9 = 2 x 4 + 1, the last slab holds one radius
    slabs, chunk = plan_slabs(replace(cfg, slab_megabytes=4 * per / 2**20))
    assert slabs == [(0, 4), (4, 8), (8, 9)]
    assert chunk >= 1 and 4 % chunk == 0
    # a budget below one radius: one radius a slab
    slabs, chunk = plan_slabs(replace(cfg, slab_megabytes=0.1 * per / 2**20))
    assert slabs == [(i, i + 1) for i in range(9)]
    assert chunk == 1
    covered = np.concatenate([np.arange(a, b) for a, b in slabs])
    np.testing.assert_array_equal(covered, np.arange(9))


def test_tests_do_not_write_into_the_package():
    """No test leaves a file in the installed package's folder (a source checkout's
    ``nylonflex/``): a test that does writes into the user's site-packages."""
    root = Path(files.__file__).resolve().parents[1]
    strays = [p for p in root.rglob("*")
              if p.is_file() and p.suffix not in (".py", ".pyc", ".json", ".yaml", ".csv",
                                                 ".md", ".js")
              and "__pycache__" not in p.parts]
    assert strays == []
