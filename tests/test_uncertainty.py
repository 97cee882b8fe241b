"""Uncertainty and sensitivity (issue 12): sampled sweeps, feasibility, Sobol' indices.

Expected values come from the model itself: a finite difference of nf.evaluate (the
delta method: sd(F) = |dF/dt| sd(t) for a small sd), the nominal cube (no uncertain
parameter), and Sobol' theory (one factor carries all the variance: S1 = ST = 1).
"""

import copy
import json
from pathlib import Path

import numpy as np
import pytest
from conftest import EXAMPLE_1, EXAMPLE_2
from hypothesis import given, settings
from hypothesis import strategies as st

import nylonflex as nf
from nylonflex.cli import main
from nylonflex.config import parse_config
from nylonflex.uncertainty import propagate, sobol_indices, standard_samples
from nylonflex.units import InputError

from helpers import SHIPPED_FIT, tight_fit_file

REPO = Path(__file__).resolve().parents[1]

SMALL = {
    "name": "uq",
    "grid": {"radius": {"start": 5, "stop": 25, "num": 5, "units": "mm"},
             "wall_thickness": {"values": [1, 2, 6], "units": "mm"},
             "length": {"values": [70, 90], "units": "mm"},
             "coil_index": {"values": [1.1, 1.7]},
             "wrap_angle": {"values": [8], "units": "deg"}},
    "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 5},
               "pressure": {"start": 0, "stop": 25, "num": 5, "units": "kPa"}},
}


def config(uncertainty=None, requirements=None, **extra):
    raw = copy.deepcopy(SMALL)
    if uncertainty is not None:
        raw["uncertainty"] = uncertainty
    if requirements is not None:
        raw["requirements"] = requirements
    raw.update(extra)
    return parse_config(raw)


THREE = {"samples": 64, "seed": 3,
         "parameters": {"wall_thickness": {"sd": 0.1, "units": "mm"},
                        "silicone.mu": {"rel_sd": 0.1},
                        "nylon.stroke_max": {"rel_sd": 0.05}}}


# ---------------------------------------------------------------------------- propagation
@pytest.mark.parametrize("example", [EXAMPLE_1, EXAMPLE_2], ids=["example1", "example2"])
def test_wall_sd_spread_matches_finite_difference(example):
    # delta method: for sd(t) = 0.01 mm, sd(F*) = |dF*/dt| sd(t) to first order
    sd = 0.01e-3
    cfg = config({"samples": 256, "seed": 0,
                  "parameters": {"wall_thickness": {"sd": 0.01, "units": "mm"}}})
    out = propagate(cfg, example, keep_samples=True)
    spread = np.std(out["samples"]["tip_force_max"], ddof=1)
    h = 1e-6
    t = example["wall_thickness"]
    up = nf.evaluate(**{**example, "wall_thickness": t + h})["tip_force_max"]
    down = nf.evaluate(**{**example, "wall_thickness": t - h})["tip_force_max"]
    expected = abs(float(up - down) / (2 * h)) * sd
    assert expected > 0
    assert spread == pytest.approx(expected, rel=0.03)


def test_no_uncertain_parameter_quantiles_equal_nominal():
    cfg = config({"samples": 16, "parameters": {}})
    ds = nf.run_sweep(cfg)
    assert list(ds["quantile"].values) == [0.05, 0.5, 0.95]
    for name in ("tip_force_max", "torque_max", "bend_angle_max", "range_fraction",
                 "nylon_use", "usable_stroke"):
        q = ds[f"{name}_quantile"]
        assert q.dims == (*nf.variables.AXES, "quantile")
        for k in range(3):
            np.testing.assert_allclose(q.isel(quantile=k).values, ds[name].values,
                                       rtol=1e-12, atol=0)
        assert q.attrs["units"] == ds[name].attrs["units"]


def test_standard_samples_are_seeded_and_standard():
    spec = config(THREE).uncertainty
    z = standard_samples(spec, 1024)
    np.testing.assert_array_equal(z, standard_samples(spec, 1024))
    np.testing.assert_allclose(z.mean(axis=0), 0, atol=0.01)
    np.testing.assert_allclose(z.std(axis=0), 1, atol=0.02)
    uni = config({**THREE, "parameters": {"radius": {"rel_sd": 0.05,
                                                      "distribution": "uniform"}}})
    u = standard_samples(uni.uncertainty, 1024)
    assert np.abs(u).max() <= np.sqrt(3) + 1e-12
    assert u.std() == pytest.approx(1, abs=0.01)


def test_from_fit_samples_carry_the_files_covariance(tmp_path):
    fit = str(tight_fit_file(tmp_path))  # no draw of it reaches the truncation
    cfg = config({"samples": 4096, "parameters": {"silicone": {"from_fit": True}}},
                 silicone={"file": fit})
    from nylonflex.uncertainty import perturbed_inputs

    z = standard_samples(cfg.uncertainty)
    args = perturbed_inputs({k: np.asarray(v) for k, v in EXAMPLE_2.items()}, cfg, z)
    x = np.hstack([args["silicone"]["mu"], args["silicone"]["alpha"]])  # mu_1 mu_2 a_1 a_2
    cov = np.asarray(cfg.uncertainty.parameters[0].covariance)
    np.testing.assert_allclose(np.cov(x.T), cov, rtol=0.1, atol=1e-3 * np.abs(cov).max())
    assert propagate(cfg, EXAMPLE_2)["tip_force_max_quantile"].shape == (3,)


def test_a_fit_too_loose_to_sample_is_refused_and_a_fit_sampled_keeps_its_signs(tmp_path):
    # the shipped ogden2 fit leaves mu_2 = 9.1 +- 17.9 Pa: a third of its draws would turn
    # the term negative (mu_i alpha_i < 0), and its sampled bend angles reached 1e121 rad
    with pytest.raises(InputError, match=r"silicone.from_fit: .* fits mu_2 = 9.088 Pa with "
                       r"a standard deviation of 17.9 Pa: 32 % of normal draws .* give "
                       r"silicone.mu a rel_sd"):
        config({"parameters": {"silicone": {"from_fit": True}}},
               silicone={"file": str(SHIPPED_FIT)})
    # mu_2's sd at 0.39x its value: accepted, 0.8 % of normal draws truncated at 1/20 of
    # it, so no sample crosses zero; at 0.43x (1.4 %) refused
    from nylonflex.config.uncertainty import MIN_FACTOR
    from nylonflex.uncertainty import perturbed_inputs

    with pytest.raises(InputError, match=r"fits mu_2 .* 1 % of normal draws"):
        config({"parameters": {"silicone": {"from_fit": True}}},
               silicone={"file": str(tight_fit_file(tmp_path, scale=0.048))})
    cfg = config({"samples": 4096, "parameters": {"silicone": {"from_fit": True}}},
                 silicone={"file": str(tight_fit_file(tmp_path, scale=0.04))})
    z = standard_samples(cfg.uncertainty)
    args = perturbed_inputs({k: np.asarray(v) for k, v in EXAMPLE_2.items()}, cfg, z)
    mu_2 = args["silicone"]["mu"][:, 1]
    floor = MIN_FACTOR * 9.088126273661937
    assert np.all(mu_2 >= floor * (1 - 1e-12))
    assert 0.004 < np.mean(np.isclose(mu_2, floor, rtol=1e-12)) < 0.012
    assert np.all(np.isfinite(propagate(cfg, EXAMPLE_2)["bend_angle_max_quantile"]))


# ---------------------------------------------------------------------------- feasibility
def _feasibility(example, threshold, samples=64):
    cfg = config(THREE, [f"tip_force_max >= {threshold!r} N"])
    return float(propagate(cfg, example, samples=samples)["feasibility"])


@pytest.mark.parametrize("example", [EXAMPLE_1, EXAMPLE_2], ids=["example1", "example2"])
def test_feasibility_inside_outside_and_at_the_boundary(example):
    nominal = float(nf.evaluate(**example)["tip_force_max"])
    assert _feasibility(example, 0.5 * nominal) == 1.0  # deep inside
    assert _feasibility(example, 2.0 * nominal) == 0.0  # far outside
    assert 0.0 < _feasibility(example, nominal) < 1.0   # at the boundary


@settings(max_examples=20)
@given(a=st.floats(0.2, 2.0), b=st.floats(0.2, 2.0), wall=st.sampled_from([1e-3, 2e-3, 6e-3]))
def test_feasibility_never_decreases_when_a_requirement_is_relaxed(a, b, wall):
    design = {**EXAMPLE_2, "wall_thickness": wall}
    nominal = float(nf.evaluate(**design)["tip_force_max"])
    strict, relaxed = max(a, b) * nominal, min(a, b) * nominal
    assert _feasibility(design, relaxed, 32) >= _feasibility(design, strict, 32)


def test_feasibility_without_uncertainty_is_the_nominal_check():
    ds = nf.run_sweep(config(None, ["tip_force_max >= 0.5 N", "range_fraction >= 1"]))
    expected = ((ds["tip_force_max"] >= 0.5) & (ds["range_fraction"] >= 1)).astype(float)
    np.testing.assert_array_equal(ds["feasibility"].values, expected.values)
    assert "quantile" not in ds.dims


# ---------------------------------------------------------------------------- the cube
@pytest.fixture(scope="module")
def sampled_cube(tmp_path_factory):
    folder = tmp_path_factory.mktemp("uq")
    cfg = config(THREE, ["tip_force_max >= 0.3 N", "range_fraction >= 1"],
                 slab_megabytes=1.0)
    path = folder / "cube.h5"
    nf.run_sweep(cfg, out=path).close()
    return path, cfg


def test_cube_file_holds_quantiles_feasibility_and_provenance(sampled_cube):
    path, cfg = sampled_cube
    ds = nf.open_cube(path)
    mem = nf.run_sweep(cfg)
    for name in ("tip_force_max_quantile", "feasibility"):
        np.testing.assert_array_equal(ds[name].values, mem[name].values)
    assert ds["feasibility"].attrs["units"] == "1"
    assert ds["tip_force_max_quantile"].attrs["units"] == "N"
    assert "tip force" in ds["tip_force_max_quantile"].attrs["long_name"]
    assert ds.attrs["uncertainty_samples"] == 64 and ds.attrs["uncertainty_seed"] == 3
    assert "silicone.mu" in ds.attrs["uncertainty"] and "rel_sd: 0.1" in ds.attrs["uncertainty"]
    assert ds.attrs["requirements"] == "tip_force_max >= 0.3 N; range_fraction >= 1"
    q = ds["tip_force_max_quantile"].values
    assert np.all(np.diff(q, axis=-1) >= 0)  # 5 % <= 50 % <= 95 %
    ds.close()


def test_config_hash_follows_the_uncertainty_section():
    plain = config()
    assert "uncertainty" not in plain.text and "requirements" not in plain.text
    a, b = config(THREE), config({**THREE, "seed": 4})
    assert len({plain.sha256, a.sha256, b.sha256}) == 3
    # the order the parameters are written in changes neither the hash nor the samples
    shuffled = config({**THREE, "parameters": dict(reversed(THREE["parameters"].items()))})
    assert shuffled.sha256 == a.sha256 and shuffled.uncertainty == a.uncertainty


def test_query_where_feasibility(sampled_cube, capsys):
    path, _ = sampled_cube
    rc = main(["query", str(path), "--where", "feasibility >= 0.9", "--format", "json"])
    doc = json.loads(capsys.readouterr().out)  # one object (docs/interface.md)
    rows = doc["designs"]
    assert rc == 0 and rows and doc["shown"] == len(rows)
    assert all(r["feasibility"] >= 0.9 for r in rows)
    assert doc["units"]["feasibility"] == "1"


def test_query_at_off_the_grid_of_a_sampled_cube_gives_the_exact_design_variables(
        sampled_cube, capsys):
    # the exact model computes the design variables, not the sampled ones: the off-grid
    # row has no feasibility column, and asking for it there is one line, exit 2 (it
    # raised KeyError: 'feasibility' before)
    path, cfg = sampled_cube
    at = "radius=7.7mm,wall_thickness=2mm,length=70mm,coil_index=1.1,wrap_angle=8deg"
    assert main(["query", str(path), "--at", at, "--format", "json"]) == 0
    row = json.loads(capsys.readouterr().out)["designs"][0]
    exact = nf.evaluate(7.7e-3, 2e-3, 70e-3, 1.1, np.radians(8))
    assert "feasibility" not in row
    assert row["tip_force_max"] == pytest.approx(float(exact["tip_force_max"]), rel=1e-9)
    assert main(["query", str(path), "--at", at, "--where", "feasibility >= 0.5"]) == 2
    err = capsys.readouterr().err
    assert "feasibility: not computed off the grid" in err and "--interpolate" in err


def test_query_feasibility_on_a_plain_cube_is_refused(tmp_path, capsys):
    from helpers import write_cube

    path = write_cube(tmp_path, SMALL)
    assert main(["query", str(path), "--where", "feasibility >= 0.9"]) == 2
    assert "no feasibility" in capsys.readouterr().err


def test_charts_feasibility_map_and_bands(sampled_cube, tmp_path):
    from nylonflex.charts import draw_charts

    path, _ = sampled_cube
    ds = nf.open_cube(path)
    files = draw_charts(ds, ["feasibility_map", "fig12b"], tmp_path)
    ds.close()
    assert [f.name for f in files] == ["feasibility_map.png", "fig12b.png"]
    assert all(f.stat().st_size > 10_000 for f in files)
    import matplotlib.pyplot as plt

    from nylonflex.charts import feasibility_map

    ds = nf.open_cube(path)
    fig = feasibility_map(ds)
    labels = " ".join(ax.get_xlabel() + " " + ax.get_ylabel() for ax in fig.axes)
    assert "chamber radius [mm]" in labels and "wall thickness [mm]" in labels
    assert "probability of meeting the requirements" in labels
    title = fig._suptitle.get_text()
    assert "tip_force_max >= 0.3 N" in title and "64 samples" in title and "L = 90 mm" in title
    plt.close(fig)
    ds.close()


# ---------------------------------------------------------------------------- config errors
@pytest.mark.parametrize("section, match", [
    ({"parameters": {"diameter": {"sd": 1}}}, r"uncertainty.parameters.diameter: unknown"),
    ({"parameters": {"radius": {"sd": 1, "rel_sd": 0.1}}}, r"one of sd .* or rel_sd"),
    ({"parameters": {"radius": {"sd": 1, "units": "kPa"}}}, r"parameters.radius.sd"),
    ({"parameters": {"silicone.mu": {"rel_sd": 2}}}, r"rel_sd: must be in \(0, 1\]"),
    ({"parameters": {"silicone.beta": {"rel_sd": 0.1}}}, r"unknown silicone field"),
    ({"parameters": {"silicone": {"from_fit": True}}}, r"fitted material file"),
    ({"samples": 1}, r"uncertainty.samples: must be in \[2, 65536\]"),
    ({"quantiles": [0.5, 0.05]}, r"uncertainty.quantiles: must be increasing"),
    ({"draws": 5}, r"uncertainty.draws: unknown key"),
])
def test_bad_uncertainty_sections_are_refused(section, match):
    with pytest.raises(InputError, match=match):
        config(section)


@pytest.mark.parametrize("reqs, match", [
    (["tip_force >= 1 N"], r"requirements\[0\]: unknown name 'tip_force'"),
    (["tip_force_max >= 1 kPa"], r"requirements\[0\]"),
    (["tip_force_max 1 N"], r"expected 'NAME OP VALUE"),
])
def test_bad_requirements_are_refused(reqs, match):
    with pytest.raises(InputError, match=match):
        config(None, reqs)


# ---------------------------------------------------------------------------- sensitivity
def test_one_uncertain_parameter_takes_all_the_variance():
    cfg = config({"samples": 64, "parameters": {"wall_thickness": {"sd": 0.1,
                                                                    "units": "mm"}}})
    res = sobol_indices(cfg, ("tip_force_max", "bend_angle_max"), at=EXAMPLE_2,
                        base_samples=256)
    for out in ("tip_force_max", "bend_angle_max"):
        assert res.indices[out]["first"]["wall_thickness"] == pytest.approx(1, abs=0.05)
        assert res.indices[out]["total"]["wall_thickness"] == pytest.approx(1, abs=0.05)


@pytest.mark.parametrize("example", [EXAMPLE_1, EXAMPLE_2], ids=["example1", "example2"])
def test_paper_examples_indices_sum_sensibly(example):
    # a nearly additive model: first-order indices sum to about 1, totals at least the firsts
    res = sobol_indices(config(THREE), ("tip_force_max", "bend_angle_max"), at=example,
                        base_samples=512)
    for out, d in res.indices.items():
        first, total = (np.array(list(d[k].values())) for k in ("first", "total"))
        assert set(d["first"]) == {"wall_thickness", "silicone.mu", "nylon.stroke_max"}
        assert 0.85 <= first.sum() <= 1.1, (out, d)
        assert total.sum() >= 0.95
        assert np.all(total >= first - 0.1)
        assert np.all((first > -0.1) & (total < 1.15))


def test_sensitivity_json_and_chart_name_each_parameter(tmp_path, capsys):
    cfg_path = tmp_path / "uq.yaml"
    import yaml

    cfg_path.write_text(yaml.safe_dump({**SMALL, "uncertainty": THREE}))
    rc = main(["sensitivity", str(cfg_path), "--at",
               "radius=7.5mm,wall_thickness=2mm,length=70mm,coil_index=1.7,wrap_angle=8deg",
               "--output", "tip_force_max", "range_fraction", "--samples", "64",
               "--format", "json", "--chart", str(tmp_path)])
    doc = json.loads(capsys.readouterr().out)
    assert rc == 0
    names = {"wall_thickness", "silicone.mu", "nylon.stroke_max"}
    for out in ("tip_force_max", "range_fraction"):
        assert set(doc["outputs"][out]) == {"first", "total", "first_conf", "total_conf"}
        for key in ("first", "total", "first_conf", "total_conf"):
            assert set(doc["outputs"][out][key]) == names
    assert (tmp_path / "sensitivity.png").stat().st_size > 10_000
    # over the design space: grid designs with the --at axes fixed
    assert main(["sensitivity", str(cfg_path), "--at", "coil_index=1.7", "--samples", "32",
                 "--designs", "4"]) == 0
    out = capsys.readouterr().out
    assert "mean over 4 grid designs" in out and "nylon.stroke_max" in out


def test_sensitivity_refusals(tmp_path, capsys):
    import yaml

    plain = tmp_path / "plain.yaml"
    plain.write_text(yaml.safe_dump(SMALL))
    assert main(["sensitivity", str(plain)]) == 2
    assert "at least one uncertain parameter" in capsys.readouterr().err
    unc = tmp_path / "uq.yaml"
    unc.write_text(yaml.safe_dump({**SMALL, "uncertainty": THREE}))
    assert main(["sensitivity", str(unc), "--output", "limit"]) == 2
    assert "--output: unknown limit" in capsys.readouterr().err


# ---------------------------------------------------------------------------- slab loop
@pytest.mark.slow
def test_sampled_sweep_on_dask_and_resumed_equals_local(tmp_path):
    # the sampled variables go through the one slab loop: a Dask run (serial evaluator in
    # the workers) and a run resumed from a journal give the local cube's values
    import signal

    import yaml
    from killing import kill_after_slabs

    distributed = pytest.importorskip("distributed")
    raw = {**copy.deepcopy(SMALL), "uncertainty": THREE,
           "requirements": ["tip_force_max >= 0.3 N"], "slab_megabytes": 1.0}
    raw["grid"]["radius"]["num"] = 40
    cfg = parse_config(raw)
    want = nf.run_sweep(cfg)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  host="127.0.0.1", dashboard_address="127.0.0.1:0") as c:
        got = nf.run_sweep(cfg, tmp_path / "dask.h5", scheduler=c.scheduler_address)
    path = tmp_path / "uq.yaml"
    path.write_text(yaml.safe_dump(raw))
    out = tmp_path / "resumed.h5"
    argv = ["sweep", str(path), "--out", str(out), "--no-charts", "--quiet"]
    assert kill_after_slabs(argv, 1, signal.SIGTERM) != 0  # stopped after its first slab
    assert main([*argv, "--resume"]) == 0
    resumed = nf.open_cube(out)
    assert resumed.attrs["resumed_slabs"] != 0
    for which, ds in (("dask", got), ("resumed", resumed)):
        for name in ("tip_force_max_quantile", "feasibility", "tip_force_max"):
            np.testing.assert_allclose(ds[name].values, want[name].values, rtol=1e-12,
                                       err_msg=f"{which} {name}")
    resumed.close()


@pytest.mark.parametrize("silicone", ["tc5005", "elastosil_m4601", "dragon_skin_10",
                                      {"file": "configs/fits/ecoflex_0050_ogden2.yaml"}])
def test_perturbed_silicone_keeps_the_cubes_own_set(silicone):
    # the samples' Ogden constants move; the set's stiffness kind and fitted stretch range
    # (stretch_beyond_fit) stay the cube's own, not tc5005's
    from nylonflex.engine.pointwise import _materials
    from nylonflex.engine.sampled import perturbed_inputs

    raw = {"name": "s", "silicone": silicone,
           "grid": {"radius": {"values": [10], "units": "mm"},
                    "wall_thickness": {"values": [2], "units": "mm"},
                    "length": {"values": [70], "units": "mm"}, "coil_index": {"values": [1.3]},
                    "wrap_angle": {"values": [8], "units": "deg"}},
           "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 3},
                      "pressure": {"start": 0, "stop": 20, "num": 3, "units": "kPa"}},
           "uncertainty": {"samples": 8, "seed": 1,
                           "parameters": {"silicone.mu": {"rel_sd": 0.1}}}}
    cfg = parse_config(raw)
    kw = perturbed_inputs({k: np.array([v[0]]) for k, v in cfg.axes.items()}, cfg,
                          standard_samples(cfg.uncertainty))
    _, stretch_max, _ = _materials(kw["silicone"], kw["nylon"])
    assert stretch_max == cfg.silicone.stretch_range[1]
    # the nominal sample (z = 0) is the grid's design, flags included
    nominal = perturbed_inputs({k: np.array([v[0]]) for k, v in cfg.axes.items()}, cfg,
                               np.zeros((1, 1)))
    one = nf.evaluate(**nominal)
    grid = nf.run_sweep(parse_config({k: v for k, v in raw.items() if k != "uncertainty"}))
    for name in ("validity", "tip_force_max", "bend_angle_max"):
        assert float(np.ravel(one[name])[0]) == pytest.approx(
            float(grid[name].values.reshape(-1)[0]), rel=1e-10), name
