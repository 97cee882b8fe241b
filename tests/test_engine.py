"""The engine: the compiled pointwise evaluator against the uncompiled physics loop, and the
grid engine against a cube written before the rewrite (bit for bit)."""

from pathlib import Path

import numpy as np
import pytest

import nylonflex as nf
from naive import random_designs
from nylonflex.engine.pointwise import _interp
from nylonflex.physics import design_limits as python_loop
from nylonflex.variables import DESIGN

DATA = Path(__file__).parent / "data"


def _rel(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    assert np.array_equal(np.isnan(a), np.isnan(b))  # heating_time is NaN without a supply
    a, b = a[~np.isnan(b)], b[~np.isnan(b)]
    return float(np.max(np.abs(a - b) / np.maximum(np.abs(b), 1e-300), initial=0.0))


def test_evaluate_matches_the_python_loop_over_the_whole_accepted_range():
    # 1,500 designs over every axis's accepted range (registry), against the same formulas
    # run uncompiled one design at a time; the issue asks 1e-12, the code gives 0
    d = random_designs(1500, seed=7)
    fast = nf.evaluate(**d)
    slow = python_loop(*d.values())
    assert list(fast) == list(DESIGN)
    for name in DESIGN:
        assert fast[name].shape == (1500,)
        assert _rel(fast[name], slow[name]) <= 1e-12, name
    assert fast["limit"].dtype == np.int8
    assert 0.2 < fast["limit"].mean() < 0.95  # both branches are exercised


def test_per_design_ogden_arrays_are_one_call():
    d = {k: v[:60] for k, v in random_designs(60, seed=3).items()}
    rng = np.random.default_rng(1)
    mu = np.array([56.19e3, 10.49e3]) * rng.uniform(0.7, 1.3, (60, 2))
    alpha = np.array([0.2975, 2.770]) * rng.uniform(0.9, 1.1, (60, 2))
    fast = nf.evaluate(**d, silicone={"set": "tc5005", "mu": mu, "alpha": alpha})
    for i in range(60):
        one = python_loop(*(v[i] for v in d.values()),
                          silicone={"set": "tc5005", "mu": list(mu[i]), "alpha": list(alpha[i])})
        for name in DESIGN:
            assert _rel(fast[name][i], one[name]) <= 1e-12, (i, name)


def test_material_arrays_broadcast_against_the_designs():
    # one design, 5 silicone samples -> shape (5,); 3 radii x 5 samples -> (3, 5)
    mu = np.array([56.19e3, 10.49e3]) * np.linspace(0.8, 1.2, 5)[:, None]
    one = nf.evaluate(7.5e-3, 2e-3, 70e-3, 1.7, 0.1396, silicone={"set": "tc5005", "mu": mu})
    assert one["tip_force_max"].shape == (5,)
    grid = nf.evaluate(np.array([6e-3, 7.5e-3, 9e-3])[:, None], 2e-3, 70e-3, 1.7, 0.1396,
                       silicone={"set": "tc5005", "mu": mu})
    assert grid["tip_force_max"].shape == (3, 5)
    np.testing.assert_array_equal(grid["tip_force_max"][1], one["tip_force_max"])
    # a stiffer silicone resists more: the usable stroke (stroke-limited) stays, the angle drops
    assert np.all(np.diff(one["bend_angle_max"]) < 0)


def test_per_design_coil_index_tables():
    smax = np.array([0.054, 0.068, 0.083, 0.097]) * np.array([[0.9], [1.0], [1.1]])
    fast = nf.evaluate(7.5e-3, 2e-3, 70e-3, 1.45, 0.1396,
                       nylon={"set": "silver_nylon66", "stroke_max_table": smax})
    for i in range(3):
        one = python_loop(7.5e-3, 2e-3, 70e-3, 1.45, 0.1396,
                          nylon={"set": "silver_nylon66", "stroke_max_table": list(smax[i])})
        for name in DESIGN:
            assert _rel(fast[name][i], one[name]) <= 1e-12, (i, name)


def test_design_limits_is_the_scalar_face_of_evaluate():
    # paper section 4, example 2: 0.150 N, stroke-limited (docs/model.md s. 8)
    out = nf.design_limits(7.5e-3, 2e-3, 70e-3, 1.7, np.radians(8.0))
    assert isinstance(out["tip_force_max"], float) and isinstance(out["limit"], int)
    assert out["tip_force_max"] == pytest.approx(0.15007, rel=1e-4)
    assert out["limit"] == 0


def test_one_design_is_its_row_of_a_batch_bit_for_bit_through_one_compiled_body():
    # issue 27's single-design path (scalars filled directly, named materials prepared
    # once) gives the bits the broadcast path gives the same design inside a batch, and
    # both run the one compiled signature of each pointwise loop (no second compile)
    from nylonflex.kernels import design as kernels

    d = random_designs(80, seed=27)
    batch = nf.evaluate(**d)
    nf.evaluate(**{k: v[:3] for k, v in d.items()})  # a small batch: one thread
    compiled = list(kernels.design_points.signatures)
    for i in (0, 17, 79):
        one = nf.evaluate(*(float(v[i]) for v in d.values()))
        for name in DESIGN:
            np.testing.assert_array_equal(one[name], batch[name][i], err_msg=name)
    again = nf.evaluate(**{k: float(v[3]) for k, v in d.items()}, silicone="tc5005",
                        nylon={"set": "silver_nylon66"})  # a mapping: the general path
    for name in DESIGN:
        np.testing.assert_array_equal(again[name], batch[name][3], err_msg=name)
    # NumPy scalars, per-design materials (what propagate and sensitivity pass: copies and
    # views alike), a cooling set: the same compiled body, no compile in between
    nf.evaluate(*(np.float64(v[5]) for v in d.values()))
    mu = np.asarray(nf.silicone_parameters("tc5005").mu) * np.array([[1.0], [1.1], [0.9]])
    nf.evaluate(**{k: v[:3] for k, v in d.items()}, silicone={"set": "tc5005", "mu": mu},
                nylon={"set": "silver_nylon66", "fibre_diameter": np.array([0.3, 0.31, 0.29])
                       * 1e-3})
    nf.evaluate(**{k: v[:3] for k, v in d.items()}, cooling="still_air")
    nf.evaluate(*(float(v[6]) for v in d.values()), cooling="forced_air")
    assert kernels.design_points.signatures == compiled


def test_a_single_out_of_range_design_says_what_the_array_check_says():
    # the scalar fast check of check_input must refuse what the array check refuses
    for bad in (0.0, -1e-3, float("nan"), float("inf"), 0.5):
        with pytest.raises(ValueError, match="radius: must be") as one:
            nf.evaluate(bad, 2e-3, 70e-3, 1.7, 0.1396)
        with pytest.raises(ValueError, match="radius: must be") as arr:
            nf.evaluate(np.array([bad]), 2e-3, 70e-3, 1.7, 0.1396)
        assert str(one.value) == str(arr.value)


@pytest.mark.parametrize("kwargs,match", [
    (dict(radius=7.5), r"radius: .*7.5 looks like mm"),
    (dict(coil_index=2.5), r"coil_index: must be in \[1.1, 1.7\]"),
    (dict(silicone={"set": "tc5005", "mu": np.full((3, 2), -1.0)}), r"silicone.mu: initial"),
    (dict(silicone={"set": "tc5005", "mu": np.full((3, 3), 1e3)}), r"silicone.mu/alpha"),
    (dict(nylon={"set": "silver_nylon66", "stroke_max_table": np.full((2, 4), 1.5)}),
     r"nylon.stroke_max_table"),
    (dict(model="magic"), r"model: unknown model 'magic'; accepted: paper"),
])
def test_bad_input_is_one_line_naming_the_parameter(kwargs, match):
    d = dict(radius=7.5e-3, wall_thickness=2e-3, length=70e-3, coil_index=1.7,
             wrap_angle=0.1396)
    d.update(kwargs)
    with pytest.raises(ValueError, match=match):
        nf.evaluate(**d)


def test_designs_that_do_not_broadcast_are_refused():
    with pytest.raises(ValueError, match="do not broadcast"):
        nf.evaluate(np.full(3, 7e-3), np.full(4, 2e-3), 70e-3, 1.7, 0.14)


def test_interp_of_per_design_tables_is_numpys_bit_for_bit():
    xp = np.array([1.1, 1.3, 1.5, 1.7])
    fp = np.array([0.054, 0.068, 0.083, 0.097])
    x = np.concatenate([xp, np.linspace(1.1, 1.7, 97)])
    rows = np.broadcast_to(xp, (x.size, 4))
    vals = np.broadcast_to(fp, (x.size, 4))
    np.testing.assert_array_equal(_interp(x, rows, vals), np.interp(x, xp, fp))


def test_the_grid_engine_writes_the_cube_the_code_wrote_before_the_rewrite():
    # tests/data/reference_cube.h5 was written by nylonflex 0.1.0 (before the engine
    # rewrite) from reference_cube.yaml; every variable it has must come out the same:
    # integers (flags) and coordinates identical, floats within 1e-12 relative since the
    # node tables and curve-started Newton of issue 17 (largest difference seen: 6e-15)
    # Issue 30 made r' depend on the coil index; a muscle set with resistance_coil_index 0
    # (the same r' at every C, as 0.1.0 had it) must still write that cube and hash:
    import dataclasses

    import xarray as xr

    cfg = nf.load_config(DATA / "reference_cube.yaml")
    cfg = dataclasses.replace(cfg, nylon=dataclasses.replace(cfg.nylon,
                                                             resistance_coil_index=0.0))
    new = nf.run_sweep(cfg)
    with xr.open_dataset(DATA / "reference_cube.h5", engine="h5netcdf") as old:
        for name in old.variables:
            expected = old[name].values
            if name == "nylon_use":  # issue 16: at most 1 (it was 1 + 6e-15 at the root)
                expected = np.minimum(expected, 1.0)
            if new[name].dtype.kind == "f" and name not in old.coords:
                # issue 17's node tables, Newton starts and base order: within 1e-12
                np.testing.assert_allclose(new[name].values, expected, rtol=1e-12, atol=0.0,
                                           err_msg=name)
            else:
                np.testing.assert_array_equal(new[name].values, expected, err_msg=name)
            assert new[name].attrs.get("units") == old[name].attrs.get("units"), name
        assert old.attrs["config_sha256"] == new.attrs["config_sha256"]
    # what the cube stores now beside them: s_max per coil index, for the charts
    np.testing.assert_array_equal(new["stroke_max"].values,
                                  np.interp(cfg.axes["coil_index"],
                                            cfg.nylon.coil_index_table,
                                            cfg.nylon.stroke_max_table))


def test_the_default_muscle_set_moves_only_resistance_and_heating_voltage_by_coil_index():
    # Issue 30: the default set's r' = 0.15 ohm/mm holds at C = 1.7 and scales by the thread
    # per length of a close-wound coil, sqrt((pi C)^2 + 1) (docs/model.md s. 9). Without a
    # supply that moves R = r' l_m by the ratio and V* = sqrt(R P) by its square root against
    # the same set with one r' for every C (resistance_coil_index 0, the cubes before issue
    # 30), and nothing else: heating power, cooling time and the design variables do not
    # depend on R.
    import dataclasses

    cfg = nf.load_config(DATA / "reference_cube.yaml")
    flat = dataclasses.replace(cfg, nylon=dataclasses.replace(cfg.nylon,
                                                              resistance_coil_index=0.0))
    new, old = nf.run_sweep(cfg), nf.run_sweep(flat)
    c = cfg.axes["coil_index"]
    ratio = (np.sqrt((np.pi * c) ** 2 + 1) / np.sqrt((np.pi * 1.7) ** 2 + 1))[:, None]
    for name in old.data_vars:
        expected = old[name].values
        if name == "resistance":
            np.testing.assert_allclose(new[name].values, expected * ratio, rtol=1e-15)
        elif name == "heating_voltage":
            np.testing.assert_allclose(new[name].values, expected * np.sqrt(ratio),
                                       rtol=1e-15)
        else:
            np.testing.assert_array_equal(new[name].values, expected, err_msg=name)
    # at the paper's coil index (1.7) the old values bit for bit
    np.testing.assert_array_equal(new["resistance"].values[..., -1, :],
                                  old["resistance"].values[..., -1, :])
    assert new.attrs["config_sha256"] != old.attrs["config_sha256"]


def test_array_pool_hands_back_what_was_given_back():
    from nylonflex.engine.grid import ArrayPool

    pool = ArrayPool()
    a = pool.empty((3, 4))
    b = pool.empty((3, 4), dtype=np.int8)
    stranger = np.empty((3, 4))
    pool.give_back({"view": a[1], "whole": b, "stranger": stranger})
    assert pool.empty((3, 4)) is a  # a view counts as its array
    assert pool.empty((3, 4), dtype=np.int8) is b
    assert pool.empty((3, 4)) is not stranger  # only the pool's own arrays come back
    assert pool.empty((2, 4)) is not a


def test_slabs_from_reused_arrays_are_the_slabs_computed_alone(tmp_path):
    # the local executor reuses a stored slab's arrays for the slab after next: every slab
    # of a many-slab sweep must still be what computing it alone gives
    from nylonflex.config import parse_config
    from nylonflex.engine.grid import compute_slab, plan_slabs
    from nylonflex.engine.slabs import LocalExecutor

    raw = {"name": "pool", "slab_megabytes": 1,  # one radius a slab (0.6 MB a radius)
           "grid": {"radius": {"start": 5, "stop": 25, "num": 6, "units": "mm"},
                    "wall_thickness": {"start": 1, "stop": 6, "num": 10, "units": "mm"},
                    "length": {"start": 50, "stop": 140, "num": 10, "units": "mm"},
                    "coil_index": {"start": 1.1, "stop": 1.7, "num": 5},
                    "wrap_angle": {"start": 2, "stop": 30, "num": 10, "units": "deg"}},
           "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 5},
                      "pressure": {"start": 0, "stop": 25, "num": 5, "units": "kPa"}}}
    cfg = parse_config(raw)
    slabs, _ = plan_slabs(cfg)
    assert len(slabs) >= 4
    seen = set()
    for k, arrays in LocalExecutor().map_slabs(cfg, slabs, range(len(slabs))):
        alone = compute_slab(cfg, *slabs[k])
        for name, value in alone.items():
            np.testing.assert_array_equal(arrays[name], value, err_msg=name)
        seen.update(id(a.base) for a in arrays.values() if a.base is not None)
    assert len(seen) < 2 * len(slabs)  # arrays were reused, not made afresh each slab
