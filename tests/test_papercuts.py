"""Issue 25's papercuts, one test each: what a user types and what nylonflex says back."""

import numpy as np
import pytest
import yaml
from helpers import write_cube

from nylonflex.cli import main
from nylonflex.config import parse_config
from nylonflex.config.sweep import apply_overrides
from nylonflex.units import InputError

ONE = {
    "name": "one",
    "grid": {
        "radius": {"values": [7.5], "units": "mm"},
        "wall_thickness": {"values": [2], "units": "mm"},
        "length": {"values": [70], "units": "mm"},
        "coil_index": {"values": [1.7]},
        "wrap_angle": {"values": [8], "units": "deg"},
    },
    "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 3},
               "pressure": {"start": 0, "stop": 20, "num": 3, "units": "kPa"}},
}


def run(capsys, *argv):
    rc = main([*map(str, argv)])
    out, err = capsys.readouterr()
    return rc, out, err


@pytest.fixture(scope="module")
def one_cube(tmp_path_factory):
    return write_cube(tmp_path_factory.mktemp("one"), ONE)


def test_set_a_field_of_a_named_material_set_overrides_it():
    raw = apply_overrides({**ONE, "silicone": "tc5005"}, ["silicone.mu=[50000, 10000]"])
    assert raw["silicone"] == {"set": "tc5005", "mu": [50000, 10000]}
    assert parse_config(raw).silicone.mu == (50e3, 10e3)
    with pytest.raises(InputError, match=r"--set 'name.x': 'name' is 'one', not a mapping "
                                         r"with fields; set it whole instead"):
        apply_overrides(ONE, ["name.x=3"])


@pytest.mark.parametrize("typo, right", [("gird", "grid"), ("curvse", "curves")])
def test_a_misspelt_key_is_named_as_the_misspelling(typo, right):
    raw = {k if k != right else typo: v for k, v in ONE.items()}
    with pytest.raises(InputError, match=rf"^{typo}: unknown key; did you mean '{right}'\?$"):
        parse_config(raw)


def test_missing_curves_says_what_they_are():
    raw = {k: v for k, v in ONE.items() if k != "curves"}
    with pytest.raises(InputError, match=r"curves: missing key; every sweep needs its curve "
                                         r"axes, e.g. curves: \{stroke:"):
        parse_config(raw)


def test_chart_figure_before_the_cube(one_cube, tmp_path, capsys):
    rc, out, err = run(capsys, "chart", "--figure", "fig4", one_cube, "--out", tmp_path,
                       "--quiet")
    assert rc == 0 and (tmp_path / "fig4.png").exists(), err
    rc, _, err = run(capsys, "chart", "--figure", "fig4", "--quiet")
    assert rc == 2 and "cube: give the cube to draw" in err


def test_a_named_figure_that_cannot_be_drawn_is_a_failure(one_cube, tmp_path, capsys):
    # one radius: fig12b draws maximum torque against radius, so it needs two or more
    rc, out, err = run(capsys, "chart", one_cube, "--figure", "fig12b", "fig4", "--out",
                       tmp_path, "--quiet")
    assert rc == 1 and "fig12b skipped: it needs at least 2 values of radius" in err
    assert "1 of the 2 figure(s) asked for could not be drawn" in err
    assert (tmp_path / "fig4.png").exists() and not (tmp_path / "fig12b.png").exists()


def test_explore_html_without_the_extra_says_how_to_install(one_cube, tmp_path, capsys,
                                                            monkeypatch):
    from nylonflex.cli import explore

    monkeypatch.setattr(explore, "_has", lambda module: False)
    rc, out, err = run(capsys, "explore", one_cube, "--html", tmp_path / "x.html")  # issue 46: 2
    assert rc == 2 and out == "" and len(err.strip().splitlines()) == 1
    assert "pip install 'nylonflex[explore]'" in err and "Traceback" not in err
    assert not (tmp_path / "x.html").exists()


def test_every_doc_the_code_and_docs_cite_exists():
    # issue 25: twelve docstrings cited an INTERFACE.md the repository did not have
    import re
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    texts = [*root.joinpath("nylonflex").rglob("*.py"), root / "README.md",
             *root.joinpath("docs").glob("*.md")]
    cited = set()
    for path in texts:
        text = path.read_text(encoding="utf-8")
        assert "INTERFACE.md" not in text, path
        cited |= set(re.findall(r"\bdocs/[a-z_]+\.md\b", text))
    assert "docs/interface.md" in cited
    missing = sorted(c for c in cited if not (root / c).exists())
    assert not missing, missing


def test_settled_error_at_the_end_of_each_reference_level():
    from nylonflex.sim import settled_errors

    t = np.arange(6.0)
    ref = np.array([0, 0, 1, 1, 1, 2.0])   # levels end at indices 1, 4 and 5
    angle = np.array([0, 0.1, 0.2, 0.5, 0.9, 1.5])
    np.testing.assert_allclose(settled_errors(t, angle, ref), [0.1, 0.1, 0.5])


@pytest.mark.parametrize("name", ["step", "gripper"])
def test_simulate_step_and_gripper_report_a_settled_error_not_an_rms(name, tmp_path, capsys):
    from pathlib import Path

    config = Path(__file__).resolve().parents[1] / "configs" / f"{name}.yaml"
    rc, out, _ = run(capsys, "simulate", config, "--out", tmp_path / "sim.h5", "--no-charts")
    assert rc == 0 and "settled error" in out and "RMS error" not in out


def test_validate_prints_the_rmse_in_the_datas_units(tmp_path, capsys):
    # bend angles read in deg: the table's RMSE in deg (JSON stays SI, with its unit)
    import math
    from pathlib import Path

    from nylonflex.calibration.validate import validate_design

    control = Path(__file__).resolve().parents[1] / "configs" / "control.yaml"
    data = tmp_path / "fig6.csv"
    data.write_text("pressure [kPa],bend_angle [deg]\n0,0\n5,10\n10,25\n15,45\n20,70\n")
    (c,) = validate_design(control, data)
    assert c.quantity == "bend_angle" and c.unit == "rad"
    rc, out, _ = run(capsys, "validate", control, data)
    assert rc == 0 and f"RMSE {math.degrees(c.rmse):.4g} deg" in out and " rad " not in out


def test_fit_thermal_prints_tau_once_and_temperatures_in_degc(tmp_path, capsys):
    # a noiseless eq. (3) step from 25 degC (the set's ambient) with tau = c'/lambda' = 15 s
    from nylonflex.physics import steady_temperature, thermal_time_constant

    tau, t_ss = thermal_time_constant(), steady_temperature(5.0, 0.3) - 273.15
    t = np.linspace(0.0, 5 * tau, 40)
    data = tmp_path / "thermal.csv"
    np.savetxt(data, np.column_stack([t, t_ss + (25.0 - t_ss) * np.exp(-t / tau)]),
               delimiter=",", header="time [s],temperature [degC]", comments="")
    rc, out, _ = run(capsys, "fit", "thermal", data, "--voltage", "5V", "--muscle-length",
                     "300mm")
    assert rc == 0 and out.count("tau [s]") == 1 and "[K]" not in out
    row = next(line for line in out.splitlines() if "temperature_0" in line).split()
    assert row[1] == "[degC]" and float(row[2]) == pytest.approx(25.0, abs=1e-6)


def test_an_up_to_date_sweep_keeps_its_charts(tmp_path, capsys):
    raw = dict(ONE, name="charted", charts=["fig4", "fig7"],
               grid=dict(ONE["grid"], radius={"values": [7.5, 10], "units": "mm"}))
    config = tmp_path / "charted.yaml"
    config.write_text(yaml.safe_dump(raw))
    out = tmp_path / "run" / "cube.h5"
    rc, first, _ = run(capsys, "sweep", config, "--out", out, "--quiet")
    assert rc == 0 and "fig4.png" in first and "fig7.png" in first
    stamps = {p.name: p.stat().st_mtime_ns for p in out.parent.glob("*.png")}
    rc, again, err = run(capsys, "sweep", config, "--out", out)
    assert rc == 0 and "nothing to do" in err and ".png" not in again
    assert "2 kept" in err
    assert {p.name: p.stat().st_mtime_ns for p in out.parent.glob("*.png")} == stamps
    (out.parent / "fig7.png").unlink()  # a missing one is drawn again, alone
    rc, third, _ = run(capsys, "sweep", config, "--out", out, "--quiet")
    assert rc == 0 and "fig7.png" in third and "fig4.png" not in third
