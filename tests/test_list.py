"""Issues 46 and 50: ``nylonflex list`` names its topics, ``list models`` describes every
variant from one registry (nylonflex/variants.py), ``list variables`` includes the tracking
ones, ``list charts`` shows no reStructuredText, and ``list`` and ``info`` speak JSON."""

import json

import pytest
from helpers import TINY, run, write_cube

from nylonflex.variables import MODELS, TRACKING
from nylonflex.variants import VARIANTS


def test_every_model_variant_has_one_record():
    # a variant added to MODELS without its record here fails: list models must describe it
    assert set(VARIANTS) == set(MODELS)
    for v in VARIANTS.values():
        assert v.adds and v.holds and v.use and v.short and v.section.startswith("s. ")


def test_list_alone_names_its_topics(capsys):
    rc, out, err = run(capsys, "list")
    assert rc == 0 and err == ""
    for topic in ("materials", "models", "charts", "variables"):
        assert f"\n  {topic} " in out


def test_list_models_introduces_each_variant_and_where_it_holds(capsys):
    rc, out, _ = run(capsys, "list", "models")
    assert rc == 0
    for name in MODELS:
        assert f"\n  {name}" in out
    assert "paper (the default)" in out
    # cauchy_moment, which nylonflex fe prints, is introduced with its measured ratio
    assert "cauchy_moment: the wall's moment from the Cauchy (true) stress" in out
    assert "0.52 (0.28-0.67) at p*" in out
    assert "'valid' and unmeasured" in out  # geometry outside the measured space


def test_list_variables_includes_tracking_and_charts_show_no_markup(capsys):
    rc, out, _ = run(capsys, "list", "variables")
    assert rc == 0 and all(f"\n  {name} " in out for name in TRACKING)
    assert "feasibility" in out
    rc, out, _ = run(capsys, "list", "charts")
    assert rc == 0 and "``" not in out and ":func:" not in out
    assert "compare " in out and "variable against radius for every model" in out


@pytest.mark.parametrize("topic", ["materials", "models", "charts", "variables", None])
def test_list_speaks_json(capsys, topic):
    rc, out, _ = run(capsys, "list", *([topic] if topic else []), "--format", "json")
    data = json.loads(out)
    assert rc == 0
    if topic is None:
        assert set(data["topics"]) == {"materials", "models", "charts", "variables"}
    elif topic == "models":
        assert [m["name"] for m in data["models"]] == list(MODELS)
    elif topic == "materials":
        assert data["silicone"]["tc5005"]["fields"]["mu"]["units"] == "Pa"
    elif topic == "variables":
        assert data["design"]["tip_force_max"]["units"] == "N"
        assert data["tracking"]["tracking_rms_error"]["display"] == "deg"


def test_info_speaks_json_in_si(tmp_path, capsys):
    cube = write_cube(tmp_path, TINY)
    rc, out, err = run(capsys, "info", cube, "--format", "json")
    d = json.loads(out)
    assert rc == 0 and d["status"] == "complete" and d["designs"] == 20
    assert d["axes"]["radius"] == {"min": 0.005, "max": 0.015, "count": 5, "units": "m",
                                   "display": "mm", "stored_over": "radius"}
    assert d["variables"]["tip_force_max"]["units"] == "N"
    assert d["validity"]["values"] == 20 and "self_contact" in d["validity"]["by_flag"]
    # the text is the same description, in display units
    rc, text, _ = run(capsys, "info", cube)
    assert "  radius          5 .. 15 mm (5)" in text
