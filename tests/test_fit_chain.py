"""Issue 46, item 3: the README's fit chain, run as written in a folder 'nylonflex init'
made: the cube of the second line holds the silicone the first line fitted, not the
shipped fit the config names."""

import pytest
import yaml

from nylonflex.cli import main
from nylonflex.storage import cube_attrs

#: The README's two lines (README.md, "Commands"), word for word.
FIT = "fit silicone data/ecoflex_0050.csv --model ogden2 --max-stretch 4 --out fits/my.yaml"
SWEEP = "sweep configs/fig12_fitted.yaml --set silicone.file=fits/my.yaml"


@pytest.mark.slow
def test_the_readme_fit_chain_sweeps_the_users_fit(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["init", "my-project"]) == 0  # the README's first line
    monkeypatch.chdir(tmp_path / "my-project")
    tmp_path = tmp_path / "my-project"
    assert main(FIT.split()) == 0
    mine = yaml.safe_load((tmp_path / "fits" / "my.yaml").read_text())
    shipped = yaml.safe_load((tmp_path / "configs" / "fits" /
                              "ecoflex_0050_ogden2.yaml").read_text())
    assert main(SWEEP.split()) == 0
    out = capsys.readouterr().out
    assert "sweeps/fig12_fitted/cube.h5  11,808 designs  complete" in out
    attrs = cube_attrs(tmp_path / "sweeps" / "fig12_fitted" / "cube.h5")
    silicone = yaml.safe_load(attrs["silicone_parameters"])
    assert silicone["sources"]["file"] == "fits/my.yaml"
    assert silicone["mu"] == mine["mu"] and silicone["alpha"] == mine["alpha"]
    # the file's own provenance too: the fit of the user's data file, as the cube says
    assert silicone["sources"]["data_path"] == "data/ecoflex_0050.csv"
    assert silicone["name"] == f"file:{mine['name']}" != f"file:{shipped['name']}"
    assert attrs["silicone"] == f"file:{mine['name']}"  # what nylonflex info shows
