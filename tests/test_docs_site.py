"""The documentation (issue 50): every code block of the README and docs/*.md runs, or says
why not right above it (``<!-- not run: REASON -->``); every registered chart has a gallery
example; the docs site's pages exist. The site itself is built by .ci/run
(``sphinx-build -W --keep-going docs docs/_build/html``: warnings are errors, the gallery
and the tutorial notebook are executed)."""

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
RUNNABLE = ("python", "bash")
NOT_RUN = re.compile(r"<!-- not run: (?P<reason>[^>]{10,}?) -->\s*$")


def code_blocks():
    """(file, line, language, code, reason or None) of every fenced python/bash block."""
    out = []
    for path in DOCS:
        lines = path.read_text(encoding="utf-8").splitlines()
        i = 0
        while i < len(lines):
            m = re.match(r"^```(\w+)\s*$", lines[i])
            if not m:
                i += 1
                continue
            lang, start = m.group(1), i
            i += 1
            body = []
            while not lines[i].startswith("```"):
                body.append(lines[i])
                i += 1
            i += 1
            if lang not in RUNNABLE:
                continue
            before = lines[start - 1] if start else ""
            hit = NOT_RUN.search(before)
            out.append((path.relative_to(ROOT).as_posix(), start + 1, lang, "\n".join(body),
                        hit.group("reason") if hit else None))
    return out


#: The README's first block, its two commands (install and run the main job; install and
#: run the tests), stays its first lines as they are: .ci/run makes that environment and
#: runs its test command (test_ci_runs_the_readmes_test_command), and the main job runs in
#: the blocks below (docs/getting_started.md).
README_COMMANDS = ("README.md", 3)
BLOCKS = [b for b in code_blocks() if b[:2] != README_COMMANDS]
TO_RUN = [b for b in BLOCKS if b[4] is None]


def test_ci_runs_the_readmes_test_command():
    first = next(b for b in code_blocks() if b[:2] == README_COMMANDS)[3]
    install, tests = [line for line in first.splitlines() if "pip install" in line]
    assert install.endswith("nylonflex sweep configs/fig12.yaml")
    command = tests.rsplit("&& ", 1)[1]          # python -m pytest -q
    assert command == "python -m pytest -q"
    ci = (ROOT / ".ci" / "run").read_text()
    assert f"coverage run -m pytest -q\n" in ci or f"\n{command}\n" in ci
    assert 'pip install -q -e ".[test' in ci


def test_every_block_runs_or_says_why_not():
    # a marker is a reason, not a bare opt-out; and most blocks do run
    assert BLOCKS and len(TO_RUN) >= 4
    for where, line, _, _, reason in BLOCKS:
        assert reason is None or len(reason.split()) >= 3, (where, line)


def test_every_registered_chart_has_a_gallery_example():
    from nylonflex.charts import CHARTS

    text = "\n".join(p.read_text() for p in (ROOT / "docs" / "examples").glob("plot_*.py"))
    missing = [name for name in CHARTS if f'CHARTS["{name}"]' not in text]
    assert not missing, f"charts without a gallery example (docs/examples/): {missing}"


def test_the_site_names_its_pages():
    index = (ROOT / "docs" / "index.md").read_text()
    for page in ("getting_started", "tutorial", "gallery/index", "guide", "model", "fidelity",
                 "design", "calibration", "uncertainty", "distributed", "reliability",
                 "architecture", "cli", "api", "interface", "benchmarks"):
        assert f"\n{page}\n" in index, page
        if "/" not in page and page != "tutorial":
            assert (ROOT / "docs" / f"{page}.md").exists(), page
    assert (ROOT / "docs" / "tutorial.ipynb").exists()


@pytest.fixture(scope="module")
def project(tmp_path_factory):
    """A folder made by ``nylonflex init`` with the main job's cube in it, as the docs'
    commands expect (the README's 'Using it')."""
    folder = tmp_path_factory.mktemp("docs") / "my-project"
    env = dict(os.environ, MPLBACKEND="Agg")
    for cmd in (["init", str(folder)], ["sweep", "configs/fig12.yaml", "--no-charts",
                                        "--quiet"]):
        subprocess.run([sys.executable, "-m", "nylonflex", *cmd], check=True, env=env,
                       cwd=folder if cmd[0] != "init" else folder.parent, timeout=600)
    return folder


@pytest.mark.slow
@pytest.mark.parametrize("where, line, lang, code, reason", TO_RUN,
                         ids=[f"{b[0]}:{b[1]}" for b in TO_RUN])
def test_the_block_runs(project, tmp_path, where, line, lang, code, reason):
    work = tmp_path / "work"
    subprocess.run(["cp", "-a", str(project), str(work)], check=True)
    env = dict(os.environ, MPLBACKEND="Agg")
    bindir = Path(sys.executable).parent  # the nylonflex command of this environment
    env["PATH"] = f"{bindir}{os.pathsep}{env.get('PATH', '')}"
    if lang == "python":
        cmd = [sys.executable, "-c", code]
    else:
        # a block that starts with `nylonflex init x && cd x` runs in a fresh folder
        cmd = ["bash", "-euo", "pipefail", "-c", code]
        if code.lstrip().startswith("nylonflex init"):
            work = tmp_path / "fresh"
            work.mkdir()
    done = subprocess.run(cmd, cwd=work, env=env, capture_output=True, text=True,
                          timeout=900)
    assert done.returncode == 0, f"{where}:{line}\n{done.stdout[-2000:]}\n{done.stderr[-3000:]}"


@pytest.mark.parametrize("codec, reads", [("zstd", True), ("lz4", False)])
def test_netcdf4_reads_the_codecs_docs_cube_md_says(tmp_path, codec, reads):
    # docs/cube.md's codec table: netCDF4's wheel carries the zstd filter, not LZ4's
    pytest.importorskip("netCDF4")
    from helpers import write_cube

    raw = {"name": "codec", "compression": codec, "charts": [],
           "grid": {"radius": {"start": 5, "stop": 25, "num": 3, "units": "mm"},
                    "wall_thickness": {"values": [2], "units": "mm"},
                    "length": {"values": [70], "units": "mm"},
                    "coil_index": {"values": [1.7]}, "wrap_angle": {"values": [8], "units": "deg"}},
           "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 3},
                      "pressure": {"start": 0, "stop": 25, "num": 3, "units": "kPa"}}}
    cube = write_cube(tmp_path, raw)
    env = {k: v for k, v in os.environ.items() if k != "HDF5_PLUGIN_PATH"}
    code = f"import netCDF4; print(netCDF4.Dataset({str(cube)!r})['tip_force_max'][:].sum())"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env=env, timeout=120)
    assert (done.returncode == 0) is reads, done.stderr[-500:]
    if not reads:
        assert "filter" in done.stderr.lower()
    row = next(line for line in (ROOT / "docs" / "cube.md").read_text().splitlines()
               if line.startswith(f"| `{codec}` |"))
    assert "netCDF4" in row
