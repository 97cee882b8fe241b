"""Platforms without POSIX file locks (issue 50): writing a cube needs ``fcntl.flock``
(storage/journal.py), which Windows lacks. ``nylonflex sweep`` there exits 2 with one line
(never a ModuleNotFoundError traceback) before any work or any file; reading needs no lock."""

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: Runs the console script's entry with ``fcntl`` unimportable, as on Windows.
WITHOUT_FCNTL = (
    "import sys; sys.modules['fcntl'] = None\n"
    "from nylonflex.cli import main\n"
    "sys.exit(main(sys.argv[1:]))\n"
)


def _nylonflex_without_fcntl(*args, cwd):
    return subprocess.run([sys.executable, "-c", WITHOUT_FCNTL, *args], cwd=cwd,
                          capture_output=True, text=True, timeout=300)


def test_sweep_without_fcntl_exits_2_with_one_line_and_writes_nothing(tmp_path):
    out = tmp_path / "sub" / "cube.h5"
    done = _nylonflex_without_fcntl("sweep", str(ROOT / "configs" / "fig12.yaml"),
                                    "--out", str(out), cwd=tmp_path)
    assert done.returncode == 2, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr
    assert "fcntl" in lines[0] and "Linux or macOS" in lines[0]
    assert "Traceback" not in done.stderr
    assert not out.parent.exists()


def test_dry_run_and_reading_need_no_file_locks(tmp_path):
    # --dry-run estimates without writing: it works where a sweep to a file cannot
    done = _nylonflex_without_fcntl("sweep", str(ROOT / "configs" / "fig12.yaml"),
                                    "--dry-run", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "designs" in done.stdout + done.stderr


def test_file_locks_names_the_platform_gap(monkeypatch):
    from nylonflex.storage.journal import file_locks
    from nylonflex.units import InputError

    assert file_locks().flock  # here, POSIX: the module itself
    monkeypatch.setitem(sys.modules, "fcntl", None)
    with pytest.raises(InputError, match=r"^sweep: writing a cube needs POSIX file locks"):
        file_locks()


def test_the_fe_extra_without_pardiso_solves_with_scipy(monkeypatch):
    # [fe] is FElupe with SciPy's solver; [fe-fast] adds pypardiso, used when importable
    pytest.importorskip("felupe")
    import numpy as np
    import scipy.sparse as sp
    from scipy.sparse.linalg import spsolve

    from nylonflex.fe.solve import linear_solver

    monkeypatch.setitem(sys.modules, "pypardiso", None)
    solve = linear_solver()
    assert solve is spsolve
    A = sp.csr_matrix(np.array([[4.0, 1.0, 0.0], [1.0, 3.0, 1.0], [0.0, 1.0, 2.0]]))
    b = np.array([1.0, 2.0, 3.0])
    np.testing.assert_allclose(A @ solve(A, b), b, rtol=1e-12)
