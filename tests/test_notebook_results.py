"""Results that read well in a notebook (issue 50): ``nf.evaluate(..., as_dataset=True)``,
``to_dataframe()`` and ``_repr_html_`` of query and design results, and ``ds.nf``'s
summary of a cube (its model, materials and completeness)."""

import numpy as np
import pytest
from helpers import write_cube

import nylonflex as nf
from nylonflex.query import query_cube
from nylonflex.variables import DESIGN

SMALL = {
    "name": "small",
    "grid": {"radius": {"start": 5, "stop": 25, "num": 5, "units": "mm"},
             "wall_thickness": {"values": [2, 6], "units": "mm"},
             "length": {"values": [70, 90], "units": "mm"},
             "coil_index": {"values": [1.1, 1.7]},
             "wrap_angle": {"values": [8], "units": "deg"}},
    "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 5},
               "pressure": {"start": 0, "stop": 25, "num": 5, "units": "kPa"}},
    "charts": [],
}


@pytest.fixture(scope="module")
def cube(tmp_path_factory):
    return write_cube(tmp_path_factory.mktemp("nb"), SMALL)


def test_evaluate_as_dataset_holds_the_dicts_values_with_units():
    radius = np.linspace(5e-3, 25e-3, 4)
    plain = nf.evaluate(radius, 2e-3, 70e-3, 1.7, np.radians(8))
    ds = nf.evaluate(radius, 2e-3, 70e-3, 1.7, np.radians(8), as_dataset=True)
    assert set(ds.data_vars) == set(plain)
    for name, value in plain.items():
        np.testing.assert_array_equal(ds[name].values, value, err_msg=name)
        assert ds[name].dims == ("design",)
        assert ds[name].attrs["units"] == DESIGN[name].units
    assert ds["tip_force_max"].attrs["units"] == "N"
    assert list(ds["validity"].attrs["flag_masks"]) == [1, 2, 4, 8, 16]
    np.testing.assert_array_equal(ds["radius"].values, radius)
    np.testing.assert_array_equal(ds["length"].values, np.full(4, 70e-3))
    assert ds["wrap_angle"].attrs["units"] == "rad" and ds.attrs["model"] == "paper"


def test_evaluate_as_dataset_of_one_design_and_of_a_grid():
    # the paper's second worked example: 0.150 N (docs/model.md s. 8)
    one = nf.evaluate(7.5e-3, 2e-3, 70e-3, 1.7, 0.1396, as_dataset=True)
    assert one["tip_force_max"].dims == ()
    assert float(one["tip_force_max"]) == pytest.approx(0.150, abs=5e-4)
    grid = nf.evaluate(np.array([10e-3, 20e-3])[:, None], np.array([2e-3, 4e-3, 6e-3]),
                       70e-3, 1.1, np.radians(8), supply_voltage=12.0, as_dataset=True)
    assert grid["tip_force_max"].dims == ("design_0", "design_1")
    assert grid["radius"].shape == (2, 3) and grid.attrs["supply_voltage"] == 12.0


def test_query_result_to_dataframe_and_html(cube):
    with nf.open_cube(cube) as ds:
        res = query_cube(ds, where=["tip_force_max >= 0.3 N"], sort="radius", limit=3)
    df = res.to_dataframe()
    assert len(df) == len(res) == 3
    assert (df["tip_force_max"] >= 0.3).all()
    assert list(df["radius"]) == sorted(df["radius"])
    assert df.attrs["units"]["radius"] == "m" and df.attrs["units"]["tip_force_max"] == "N"
    page = res._repr_html_()
    assert page.startswith("<table") and "radius [mm]" in page
    assert "tip_force_max [N]" in page and "shown of" in page
    assert "<td>valid</td>" in page or "self_contact" in page  # validity by flag name


def test_design_result_to_dataframe_and_html(cube):
    spec = {"name": "best", "cube": str(cube), "objectives": [{"max": "tip_force_max"}],
            "constraints": ["range_fraction >= 1", "length == 90 mm", "coil_index == 1.1"],
            "refine": False}
    res = nf.run_design(spec)
    df = res.to_dataframe()
    assert len(df) == len(res.designs) >= 1
    assert df.loc[0, "tip_force_max"] == res.designs[0]["tip_force_max"]
    assert df.loc[0, "source"] == "grid" and df.attrs["units"]["length"] == "m"
    assert "tip_force_max [N]" in res._repr_html_()
    spec["constraints"].append("tip_force_max >= 1000 N")
    nothing = nf.run_design(spec)
    assert "no design meets the spec" in nothing._repr_html_()


def test_cube_summary_names_model_materials_and_completeness(cube):
    with nf.open_cube(cube) as ds:
        text = repr(ds.nf)
        assert text.splitlines()[0].startswith("nylonflex cube 'small'")
        assert "\ncomplete\n" in text
        assert "40 designs: radius 5-25 mm (5)" in text  # 5 x 2 x 2 x 2 x 1
        assert "model: paper" in text and "silicone: tc5005" in text
        assert "nylon: silver_nylon66" in text
        assert "<li>complete</li>" in ds.nf._repr_html_()
        part = ds.copy()
        part.attrs["complete"] = np.int8(0)
        assert "INCOMPLETE" in repr(part.nf)
