"""``nylonflex fit chamber`` (calibration.chamber_bench, docs/bench.md): it recovers known
chamber parameters from bench data that the coupled model made, with noise."""

import math

import numpy as np
import pytest
import yaml

from nylonflex.calibration.chamber_bench import fit_chamber
from nylonflex.cli import main
from nylonflex.files.material_files import read_chamber_file
from nylonflex.physics import P_ATM
from nylonflex.physics.sealed_model import boyle_pressure

A, T, L = 20e-3, 6e-3, 90e-3
V0 = 0.5 * math.pi * A * A * L
TRUE = dict(stiffness=9000.0, rounding=0.6, air_heating=0.3, squeeze=1.1)
HEADER = ("phase,volume [ml],pressure [kPa],stroke,air_temperature [degC],"
          "muscle_temperature [degC],bend_angle [deg]")


def bench_csv(path, truth=TRUE, noise=1.0, seed=0, held=15000.0, phases=(1, 2, 3, 4)):
    """The four phases of docs/bench.md as the coupled model says (noise in units of
    10 Pa, 0.2 deg and 0.3 K)."""
    rng = np.random.default_rng(seed)
    rows = []
    dv = np.linspace(0.0, 5e-6, 11)
    if 1 in phases:
        p = truth["stiffness"] * dv / V0 + noise * 10.0 * rng.standard_normal(dv.size)
        rows += [(1, v * 1e6, q / 1e3, 0, 25, 25, 0) for v, q in zip(dv, p)]
    if 2 in phases:
        p = held * dv / V0 + noise * 10.0 * rng.standard_normal(dv.size)
        rows += [(2, v * 1e6, q / 1e3, 0, 25, 25, 0) for v, q in zip(dv, p)]
    s = np.linspace(0.0, 0.054, 19)
    t_m = 25.0 + 125.0 * s / 0.054
    t_air = 25.0 + truth["air_heating"] * (t_m - 25.0) + noise * 0.3 * rng.standard_normal(s.size)
    t_air[0] = 25.0
    v = (1 - s) ** 2 * np.exp(truth["rounding"] * s)
    p = boyle_pressure(v, truth["stiffness"], (t_air + 273.15) / 298.15, P_ATM)
    p = p + noise * 10.0 * rng.standard_normal(s.size)
    rows += [(3, 0, q / 1e3, si, ta, tm, 0) for q, si, ta, tm in zip(p, s, t_air, t_m)]
    h = T + A + T / 2  # b + a + t/2, b = t
    theta = truth["squeeze"] * s * L / h + noise * math.radians(0.2) * rng.standard_normal(s.size)
    rows += [(4, 0, 0, si, 25, tm, math.degrees(th)) for si, tm, th in zip(s, t_m, theta)]
    path.write_text(HEADER + "\n" + "\n".join(",".join(f"{x:.9g}" for x in r) for r in rows)
                    + "\n")
    return path


def test_recovers_known_parameters_exactly_without_noise(tmp_path):
    res = fit_chamber(bench_csv(tmp_path / "b.csv", noise=0.0), A, T, L)
    for k, v in TRUE.items():
        assert res.parameters[k] == pytest.approx(v, rel=1e-5, abs=1e-6), k
    assert res.derived["stiffness_held"]["value"] == pytest.approx(15000.0, rel=1e-6)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_recovers_known_parameters_through_noise_inside_the_intervals(tmp_path, seed):
    res = fit_chamber(bench_csv(tmp_path / "b.csv", seed=seed), A, T, L)
    for k, v in TRUE.items():
        lo, hi = res.ci95[k]
        assert lo <= res.parameters[k] <= hi
        assert lo - 0.5 * (hi - lo) <= v <= hi + 0.5 * (hi - lo), (k, v, lo, hi)
    assert res.parameters["stiffness"] == pytest.approx(TRUE["stiffness"], rel=0.05)
    # the heating's share of the top pressure: what tau adds over the isothermal squeeze
    assert 0.0 < res.derived["heating_share"]["value"] < 1.0


def test_cli_writes_a_chamber_file_a_reader_takes_back(tmp_path, capsys):
    data = bench_csv(tmp_path / "bench.csv", seed=4)
    out = tmp_path / "chamber.yaml"
    rc = main(["fit", "chamber", str(data), "--radius", "20mm", "--wall-thickness", "6mm",
               "--length", "90mm", "--out", str(out)])
    assert rc == 0
    text = capsys.readouterr().out
    assert "chamber fit: sealed_chamber" in text and "stiffness [Pa]" in text
    doc = yaml.safe_load(out.read_text())
    assert doc["kind"] == "chamber" and doc["design"]["radius"] == pytest.approx(A)
    back = read_chamber_file(out)
    assert back["stiffness"] == pytest.approx(TRUE["stiffness"], rel=0.05)
    # never overwritten without asking
    assert main(["fit", "chamber", str(data), "--radius", "20mm", "--wall-thickness", "6mm",
                 "--length", "90mm", "--out", str(out)]) == 2
    assert "exists" in capsys.readouterr().err


@pytest.mark.parametrize("args, match", [
    ([], r"--radius: required for 'fit chamber'"),
    (["--radius", "20mm", "--wall-thickness", "6mm", "--length", "9 deg"],
     r"--length: unit 'deg' is not a length"),
    (["--radius", "20mm", "--wall-thickness", "6mm", "--length", "90mm",
      "--chamber-volume", "5 kPa"], r"--chamber-volume: unit 'kPa' is not a volume"),
])
def test_bad_flags_are_one_line(tmp_path, capsys, args, match):
    import re
    data = bench_csv(tmp_path / "b.csv")
    assert main(["fit", "chamber", str(data), *args]) == 2
    err = capsys.readouterr().err.strip()
    assert re.search(match, err) and len(err.splitlines()) == 1


def test_a_bad_phase_or_too_few_rows_is_refused(tmp_path, capsys):
    bad = tmp_path / "bad.csv"
    bad.write_text(HEADER + "\n5,0,0,0,25,25,0\n")
    assert main(["fit", "chamber", str(bad), "--radius", "20mm", "--wall-thickness", "6mm",
                 "--length", "90mm"]) == 2
    assert "column 'phase': must be one of 1, 2, 3, 4" in capsys.readouterr().err
    few = bench_csv(tmp_path / "few.csv", phases=(1, 2))
    text = few.read_text().splitlines()
    few.write_text("\n".join([text[0]] + [r for r in text[1:] if not r.startswith("4,")]))
    assert main(["fit", "chamber", str(few), "--radius", "20mm", "--wall-thickness", "6mm",
                 "--length", "90mm"]) == 2
    assert "needs at least 3 rows of phase 4" in capsys.readouterr().err


def test_a_chamber_file_with_a_bad_value_is_refused(tmp_path):
    from nylonflex.units import InputError
    f = tmp_path / "c.yaml"
    f.write_text("kind: chamber\nstiffness: -3\nrounding: 0\nair_heating: 0\nsqueeze: 1\n"
                 "units: {stiffness: Pa, rounding: '1', air_heating: '1', squeeze: '1'}\n")
    with pytest.raises(InputError, match=r"stiffness: must be a number in \[0, 1e\+09\] Pa"):
        read_chamber_file(f)


def test_anchored_coefficients_give_the_measured_chamber_at_its_own_design():
    from nylonflex.physics.sealed import COEFFICIENTS, anchored_coefficients
    from nylonflex.physics.sealed_model import chamber_stiffness, free_volume
    from nylonflex.materials import silicone_parameters

    measured = dict(TRUE, radius=A, wall_thickness=T)
    base = COEFFICIENTS._replace(k1=0.4, g1=-0.2, c1=0.3, cb=2.0)
    coef = anchored_coefficients(measured, silicone_parameters("tc5005").initial_shear_modulus,
                                 base)
    assert chamber_stiffness(A, T, coefficients=coef) == pytest.approx(TRUE["stiffness"],
                                                                       rel=1e-12)
    s = 0.05
    assert free_volume(s, A, T, coefficients=coef) == pytest.approx(
        (1 - s) ** 2 * math.exp(TRUE["rounding"] * s), rel=1e-12)
    assert coef.c0 + coef.c1 * math.log(T / A) == pytest.approx(TRUE["squeeze"], rel=1e-12)
    assert (coef.k1, coef.g1, coef.c1, coef.cb) == (0.4, -0.2, 0.3, 2.0)


def _sweep_raw(chamber_file, model=("sealed_chamber",)):
    return {"name": "chamber", "model": list(model), "chamber": {"file": str(chamber_file)},
            "grid": {"radius": {"values": [10, 20], "units": "mm"},
                     "wall_thickness": {"values": [3, 6], "units": "mm"},
                     "length": {"values": [90], "units": "mm"},
                     "coil_index": {"values": [1.1, 1.7]},
                     "wrap_angle": {"values": [8], "units": "deg"}},
            "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 3},
                       "pressure": {"start": 0, "stop": 5, "num": 3, "units": "kPa"}}}


def test_a_sweep_names_a_chamber_file_and_runs_its_chamber(tmp_path):
    import nylonflex as nf
    from nylonflex.config import parse_config
    from nylonflex.engine.provenance import cube_settings
    from nylonflex.materials import silicone_parameters
    from nylonflex.physics.sealed import anchored_coefficients
    from nylonflex.sweep.conductor import run_sweep

    out = tmp_path / "chamber.yaml"
    assert main(["fit", "chamber", str(bench_csv(tmp_path / "b.csv", seed=5)), "--radius",
                 "20mm", "--wall-thickness", "6mm", "--length", "90mm", "--out", str(out)]) == 0
    measured = read_chamber_file(out)
    cfg = parse_config(_sweep_raw(out, ("paper", "sealed_chamber")))
    assert measured["initial_shear_modulus"] == pytest.approx(
        silicone_parameters("tc5005").initial_shear_modulus)
    coef = anchored_coefficients(measured, measured["initial_shear_modulus"])
    ds = run_sweep(cfg, out=tmp_path / "cube.h5")
    grids = np.meshgrid(*cfg.axes.values(), indexing="ij")
    exact = nf.evaluate(*grids, model="sealed_chamber", chamber=coef)
    sealed = ds.sel(model="sealed_chamber")
    for name in ("pressure_max", "bend_angle_max", "tip_force_max", "usable_stroke"):
        np.testing.assert_allclose(sealed[name].values, exact[name], rtol=1e-9, err_msg=name)
    shipped = nf.evaluate(*grids, model="sealed_chamber")
    assert not np.allclose(shipped["pressure_max"], exact["pressure_max"])
    # the cube remembers the coefficients: re-evaluating under its settings gives its values
    back = nf.open_cube(tmp_path / "cube.h5")
    settings = cube_settings(back)
    assert settings.chamber == pytest.approx(tuple(coef))
    again = nf.evaluate(*grids, **settings.evaluate_kwargs("sealed_chamber"))
    np.testing.assert_allclose(again["pressure_max"], exact["pressure_max"], rtol=1e-12)
    # design re-evaluates a one-model cube's designs under the coefficients it ran with
    from nylonflex.design import parse_spec, run_design
    one = run_sweep(parse_config(_sweep_raw(out)))
    res = run_design(parse_spec({"cube": "unused.h5", "objectives": [{"max": "tip_force_max"}],
                                 "refine": {"starts": 2, "maxiter": 5}}), cube=one)
    best = res.designs[0]
    want = nf.evaluate(*(best[a] for a in ("radius", "wall_thickness", "length", "coil_index",
                                           "wrap_angle")), model="sealed_chamber", chamber=coef)
    assert best["tip_force_max"] == pytest.approx(float(want["tip_force_max"]), rel=1e-9)
    # info --config names the file again, while it says what the cube ran with
    from nylonflex.engine.provenance import runnable_config
    text = runnable_config(back.attrs)
    assert yaml.safe_load(text)["chamber"] == {"file": str(out)}
    assert parse_config(yaml.safe_load(text)).sha256 == cfg.sha256
    # the explorer's "copy as config" of one design keeps both models and the chamber file:
    # its sweep gives that design's values of the cube, the anchored chamber's included
    from nylonflex.explore.data import design_config
    from nylonflex.variables import AXES
    at = {a: float(back[a].values[-1]) for a in AXES}
    doc = yaml.safe_load(design_config(back, at))
    assert doc["model"] == ["paper", "sealed_chamber"] and doc["chamber"] == {"file": str(out)}
    one = run_sweep(parse_config(doc))
    for name in ("pressure_max", "bend_angle_max", "tip_force_max", "limit"):
        np.testing.assert_array_equal(one[name].squeeze().values,
                                      back[name].sel(at).values, err_msg=name)
    out.write_text(out.read_text().replace("squeeze: ", "squeeze: 1", 1))
    # the explorer still opens the cube: its copy names the file and warns it has changed
    changed = design_config(back, at)
    assert "has changed since the sweep" in changed.splitlines()[1]
    with pytest.raises(ValueError, match="chamber file .* has changed since the sweep"):
        runnable_config(back.attrs)


def test_a_chamber_file_needs_the_sealed_model_and_a_good_file(tmp_path):
    from nylonflex.config import parse_config
    from nylonflex.units import InputError

    out = tmp_path / "chamber.yaml"
    main(["fit", "chamber", str(bench_csv(tmp_path / "b.csv")), "--radius", "20mm",
          "--wall-thickness", "6mm", "--length", "90mm", "--out", str(out)])
    with pytest.raises(InputError, match="chamber: applies to model sealed_chamber only"):
        parse_config(_sweep_raw(out, ("paper",)))
    with pytest.raises(InputError, match="chamber.file: .*no such material file"):
        parse_config(_sweep_raw(tmp_path / "missing.yaml"))
    bare = tmp_path / "bare.yaml"
    bare.write_text(out.read_text().replace("stiffness: Pa", "stiffness: kPa"))
    with pytest.raises(InputError, match="chamber.file: .*stiffness: the file's units must "
                                         "say 'Pa'"):
        parse_config(_sweep_raw(bare))
