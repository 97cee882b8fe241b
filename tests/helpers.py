"""Helpers the test files share (fixtures themselves live in conftest.py, where pytest
finds them): writing a config or a cube, and a cube without its run-dependent attributes."""

from pathlib import Path

import yaml


def write_config(folder, raw, name="cfg.yaml"):
    """Write a config mapping as YAML to ``folder/name``; return the path."""
    path = Path(folder) / name
    path.write_text(yaml.safe_dump(raw))
    return path


def write_cube(folder, raw):
    """Sweep a config mapping into ``folder/cube.h5``; return the path."""
    from nylonflex.config import parse_config
    from nylonflex.sweep.conductor import run_sweep

    path = Path(folder) / "cube.h5"
    run_sweep(parse_config(raw), out=path).close()
    return path


def stable(ds):
    """The dataset without the attributes that differ between two runs of one config."""
    from nylonflex.storage import VOLATILE_ATTRS

    ds = ds.copy()
    ds.attrs = {k: v for k, v in ds.attrs.items() if k not in VOLATILE_ATTRS}
    return ds


def fitted_thermal_file(folder, lam=0.05, cap=0.45, lm=0.3, v=5.0, r_meas=40.0):
    """A ``fit thermal`` material file fitted to a synthetic step response (lambda' [W/(K m)],
    c' [J/(K m)] of a muscle of length ``lm`` [m] at ``v`` [V] and ``r_meas`` [ohm]);
    return its path."""
    import numpy as np

    from nylonflex.calibration import fit_thermal
    from nylonflex.files.material_files import write_material_file
    from nylonflex.materials import nylon_parameters

    t_amb = nylon_parameters().t_amb
    t = np.linspace(0.0, 60.0, 40)
    t_ss = t_amb + v ** 2 / (r_meas * lam * lm)
    temp = t_ss + (t_amb - t_ss) * np.exp(-t * lam / cap)
    csv = Path(folder) / "t.csv"
    csv.write_text("time [s],temperature [K]\n" + "\n".join(f"{float(a)!r},{float(b)!r}"
                                                            for a, b in zip(t, temp)))
    fit = fit_thermal(str(csv), v, lm, resistance=r_meas)
    return write_material_file(fit, Path(folder) / "n.yaml")


#: The shipped fitted silicone (nylonflex fit silicone of tests/data/ecoflex_0050.csv,
#: ogden2 to stretch 4): its mu_2 = 9.1 +- 17.9 Pa is too loose for from_fit.
SHIPPED_FIT = Path(__file__).resolve().parents[1] / "configs" / "fits" / \
    "ecoflex_0050_ogden2.yaml"


def tight_fit_file(folder, scale=0.01):
    """The shipped ogden2 fit with its covariance times ``scale`` (standard deviations
    times sqrt(scale): mu_2's 1.97x its value becomes 0.2x, which from_fit samples with no
    truncation); return its path. A made-up file for the sampling tests, not a measurement."""
    doc = yaml.safe_load(SHIPPED_FIT.read_text())
    doc["covariance"] = [[scale * float(x) for x in row] for row in doc["covariance"]]
    path = Path(folder) / "ecoflex_0050_ogden2_tight.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False))
    return path


#: A sweep of 20 designs (5 radii, 2 walls, 2 coil indices): the CLI tests' config.
TINY = {
    "name": "tiny",
    "grid": {
        "radius": {"start": 5, "stop": 15, "num": 5, "units": "mm"},
        "wall_thickness": {"values": [2, 4], "units": "mm"},
        "length": {"values": [70], "units": "mm"},
        "coil_index": {"values": [1.1, 1.7]},
        "wrap_angle": {"values": [8], "units": "deg"},
    },
    "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 6},
               "pressure": {"start": 0, "stop": 30, "num": 6, "units": "kPa"}},
}


def run(capsys, *argv):
    """``nylonflex ARGV`` in this process: (exit status, stdout, stderr)."""
    from nylonflex.cli import main

    rc = main([*map(str, argv)])
    out, err = capsys.readouterr()
    return rc, out, err
