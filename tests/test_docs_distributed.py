"""docs/distributed.md's SLURM example, run as written (issue 50: its last line raised a
TypeError). ``dask_jobqueue.SLURMCluster`` is stood in for by a loopback Dask cluster with
the same keyword arguments, and ``configs/big20m.yaml`` by a small grid of that name."""

from __future__ import annotations

import re
import sys
import types
from pathlib import Path

import pytest

distributed = pytest.importorskip("distributed")

import nylonflex as nf  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]

SMALL = """\
name: big20m
grid:
  radius:         {start: 5, stop: 25, num: 12, units: mm}
  wall_thickness: {start: 1, stop: 6, num: 4, units: mm}
  length:         {values: [60, 90]}
  coil_index:     {values: [1.1, 1.7]}
  wrap_angle:     {start: 2, stop: 30, num: 3, units: deg}
curves:
  stroke:   {start: 0, stop: 0.1, num: 5}
  pressure: {start: 0, stop: 40, num: 5, units: kPa}
slab_megabytes: 1
charts: []
"""


def slurm_example() -> str:
    """The Python block of docs/distributed.md's section "On SLURM with dask-jobqueue"."""
    text = (ROOT / "docs" / "distributed.md").read_text()
    section = text.split("## On SLURM with dask-jobqueue", 1)[1].split("\n## ", 1)[0]
    blocks = re.findall(r"```python\n(.*?)```", section, flags=re.S)
    assert len(blocks) == 1, "the section has one Python example"
    return blocks[0]


class _Client:
    """The real client, but waiting for the loopback cluster's workers, not 128."""

    def __init__(self, client, n):
        self._client, self._n = client, n

    def wait_for_workers(self, n_workers, **kw):
        assert n_workers >= 1
        return self._client.wait_for_workers(self._n, **kw)

    def __getattr__(self, name):
        return getattr(self._client, name)


class FakeSLURMCluster:
    """``SLURMCluster``'s arguments as the example uses them (keywords only, so a renamed
    one fails), served by a loopback cluster of two in-process workers."""

    def __init__(self, *, queue, account, cores, processes, memory, walltime,
                 job_script_prologue):
        assert cores % processes == 0 and isinstance(job_script_prologue, list)
        self._cluster = distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=False, protocol="tcp",
            host="127.0.0.1", dashboard_address="127.0.0.1:0")
        self.scheduler_address = self._cluster.scheduler_address
        self.scaled = None

    def scale(self, *, jobs):
        self.scaled = jobs

    def get_client(self):
        return _Client(distributed.Client(self._cluster), 2)

    def close(self):
        self._cluster.close()


@pytest.mark.slow
def test_the_slurm_example_runs_as_written(tmp_path, monkeypatch, capsys):
    (tmp_path / "configs").mkdir()
    (tmp_path / "configs" / "big20m.yaml").write_text(SMALL)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setitem(sys.modules, "dask_jobqueue",
                        types.SimpleNamespace(SLURMCluster=FakeSLURMCluster))
    try:
        exec(compile(slurm_example(), "docs/distributed.md", "exec"), {})
    finally:
        monkeypatch.undo()
    cube = tmp_path / "sweeps" / "big20m" / "cube.h5"
    with nf.open_cube(cube) as ds:
        assert ds.attrs["complete"] == 1
        assert ds.sizes["radius"] == 12
    assert capsys.readouterr().out.strip(), "log=print printed the run's progress"
