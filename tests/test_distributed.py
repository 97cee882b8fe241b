"""Sweeps on a Dask distributed cluster: two worker processes on loopback.

The expected cube is the local run of the same config: the cluster runs the same compiled
loop (serially) on the same slab boundaries, so the cubes must agree bit for bit
(nylonflex.distributed's docstring); the test allows rtol 1e-12 as the issue states.
"""

from __future__ import annotations

import signal
import socket

import numpy as np
import pytest
from killing import kill_after_slabs

distributed = pytest.importorskip("distributed")

import nylonflex as nf  # noqa: E402
from nylonflex.cli import main  # noqa: E402
from nylonflex.engine.cluster import DaskExecutor, _normalise_address  # noqa: E402
from nylonflex.storage import VOLATILE_ATTRS, Journal  # noqa: E402
from nylonflex.engine.grid import plan_slabs  # noqa: E402
from nylonflex.units import InputError  # noqa: E402

# Eighteen slabs of about 1 MB, some 50 ms of work each: enough tasks for both workers and
# a window to kill a run half-way, in a few seconds in all.
CONFIG = """\
name: dist
grid:
  radius:         {start: 5, stop: 25, num: 160, units: mm}
  wall_thickness: {start: 1, stop: 6, num: 10, units: mm}
  length:         {values: [60, 90]}
  coil_index:     {values: [1.1, 1.25, 1.4, 1.55, 1.7]}
  wrap_angle:     {start: 2, stop: 30, num: 10, units: deg}
curves:
  stroke:   {start: 0, stop: 0.1, num: 11}
  pressure: {start: 0, stop: 40, num: 21, units: kPa}
slab_megabytes: 1
"""


@pytest.fixture(scope="module")
def cluster():
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  host="127.0.0.1", dashboard_address="127.0.0.1:0",
                                  worker_dashboard_address="127.0.0.1:0") as c:
        yield c


@pytest.fixture(scope="module")
def config_path(tmp_path_factory):
    path = tmp_path_factory.mktemp("cfg") / "dist.yaml"
    path.write_text(CONFIG)
    return path


@pytest.fixture(scope="module")
def local_cube(config_path, tmp_path_factory):
    out = tmp_path_factory.mktemp("local") / "cube.h5"
    nf.run_sweep(nf.load_config(config_path), out).close()
    return out


def _assert_same_cube(path, reference):
    with nf.open_cube(path) as got, nf.open_cube(reference) as want:
        assert got.attrs["complete"] == 1
        assert set(got.variables) == set(want.variables)
        for name in want.variables:
            a, b = got[name].values, want[name].values
            assert a.dtype == b.dtype, name
            np.testing.assert_allclose(a, b, rtol=1e-12, atol=0, equal_nan=True,
                                       err_msg=name)
        stable = {k: v for k, v in want.attrs.items() if k not in VOLATILE_ATTRS}
        assert set(stable) <= set(got.attrs)
        for k, v in stable.items():  # the settings' arrays among them (cube format 2)
            np.testing.assert_array_equal(got.attrs[k], v, err_msg=k)


def _numba_threads_started():
    from numba.np.ufunc import parallel

    return bool(getattr(parallel, "_is_initialized", False))

@pytest.mark.slow

def test_cluster_cube_identical_to_local(cluster, config_path, local_cube, tmp_path):
    cfg = nf.load_config(config_path)
    slabs, _ = plan_slabs(cfg)
    assert len(slabs) >= 10  # several tasks, so both workers take part
    out = tmp_path / "cube.h5"
    nf.run_sweep(cfg, out, scheduler=cluster.scheduler_address).close()
    _assert_same_cube(out, local_cube)
    with nf.open_cube(out) as ds:
        assert ds.attrs["scheduler"] == cluster.scheduler_address
        assert ds.attrs["workers"] == 2  # typed (issue 24)
    # one level of parallelism: the workers never started Numba's thread pool
    with distributed.Client(cluster, set_as_default=False) as client:
        assert not any(client.run(_numba_threads_started).values())

@pytest.mark.slow
def test_the_workers_encode_the_slabs_and_the_client_prepares_none(cluster, config_path,
                                                                   tmp_path):
    # with the sink's encoder, a worker sends the compressed chunks (an EncodedSlab, the
    # bytes the cube file would make of the arrays), and the client's own first step
    # (prepare: compression in its threads) is not run
    from nylonflex.engine.grid import compute_slab, coords, cube_variables
    from nylonflex.engine.provenance import provenance
    from nylonflex.storage.codec import EncodedSlab
    from nylonflex.storage.cube import CubeFile

    cfg = nf.load_config(config_path)
    slabs, chunk = plan_slabs(cfg)
    cube = CubeFile(tmp_path / "c.h5", coords(cfg), provenance(cfg), chunk, cfg.compression,
                    cube_variables(cfg), cfg.models, cfg.cooling_names)

    def prepare(i0, arrays):
        raise AssertionError("the client compressed a slab a worker had encoded")

    executor = DaskExecutor(cluster.scheduler_address)
    try:
        got = dict(executor.map_slabs(cfg, slabs, [0, 3], prepare=prepare,
                                      remote=cube.remote_encoder()))
        assert got.keys() == {0, 3}
        for k, slab in got.items():
            assert isinstance(slab, EncodedSlab)
            want = cube.encode(slabs[k][0], compute_slab(cfg, *slabs[k], parallel=False))
            assert slab.arrays.keys() == want.keys()
            for key, value in want.items():
                np.testing.assert_array_equal(slab.arrays[key], value, err_msg=key)
    finally:
        executor.close()
        cube.close()


@pytest.mark.slow
def test_killed_cluster_run_resumes(cluster, config_path, local_cube, tmp_path):
    out = tmp_path / "cube.h5"
    argv = ["sweep", str(config_path), "--out", str(out), "--scheduler",
            cluster.scheduler_address, "--quiet", "--no-charts"]
    # killed right after the first slab is journaled: deterministic on any machine
    assert kill_after_slabs(argv, 1, signal.SIGKILL) == -signal.SIGKILL
    journal = Journal(out)
    n_slabs = len(plan_slabs(nf.load_config(config_path))[0])
    saved = journal.done()
    assert len(saved) == 1 < n_slabs and not out.exists()

    cfg = nf.load_config(config_path)
    nf.run_sweep(cfg, out, resume=True, scheduler=cluster.scheduler_address).close()
    _assert_same_cube(out, local_cube)
    with nf.open_cube(out) as ds:
        assert int(ds.attrs["resumed_slabs"]) >= len(saved)
    assert not journal.dir.exists()


def _free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_no_scheduler_is_refused():
    with pytest.raises(InputError, match="no Dask scheduler answers at tcp://127.0.0.1"):
        DaskExecutor(f"tcp://127.0.0.1:{_free_port()}", timeout=0.5)


def test_malformed_address_is_refused_by_the_cli(config_path, tmp_path, capsys):
    code = main(["sweep", str(config_path), "--out", str(tmp_path / "c.h5"),
                 "--scheduler", "tcp://127.0.0.1", "--quiet"])
    err = capsys.readouterr().err
    assert code == 2
    assert "--scheduler: expected a Dask scheduler address" in err
    assert len(err.strip().splitlines()) == 1
    assert not (tmp_path / "c.h5").exists()


@pytest.mark.parametrize("given, address", [
    ("tcp://10.0.0.5:8786", "tcp://10.0.0.5:8786"),
    ("node17:8786", "tcp://node17:8786"),
    ("tls://[::1]:9000", "tls://[::1]:9000"),
])
def test_address_forms(given, address):
    assert _normalise_address(given) == address


@pytest.mark.parametrize("given", ["", "node17", "http://node17:8786", "tcp://h:0",
                                   "tcp://h:99999", "tcp://h:8786/x"])
def test_bad_address_forms(given):
    with pytest.raises(InputError, match="--scheduler"):
        _normalise_address(given)
