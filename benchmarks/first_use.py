"""First use and light commands (issue 27) for ``nylonflex bench``: every kernel's compile
with an empty cache, and the whole-process CPU and memory of the light commands, each in a
child process of this one (the operating system's accounting of the finished child).
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

from .ratios import child_env

__all__ = ["cold_compiles", "command_costs", "light_commands"]

#: A line of ``nylonflex warmup`` for a kernel that compiled.
_COMPILED = re.compile(r"\[\d+/\d+\]\s+(\S+)\s+compiled in ([\d.]+) s \(([\d.]+) CPU-s\)")


#: GNU time: the peak memory of a child of a small process (a child forked from this one
#: reports this process's peak as its own: Linux copies the high-water mark at fork).
_GNU_TIME = "/usr/bin/time"


def _child(args, *, env=None, cwd=None) -> dict:
    """Run ``python -m nylonflex *args``; its CPU seconds [s] (user + system), peak
    memory [MB] (None without GNU time), exit status and output (stdout and stderr)."""
    command = [sys.executable, "-m", "nylonflex", *args]
    with tempfile.TemporaryDirectory(prefix="nylonflex-child-") as tmp:
        measured = Path(tmp) / "time.txt"
        gnu = os.access(_GNU_TIME, os.X_OK)
        if gnu:
            command = [_GNU_TIME, "-f", "%U %S %M", "-o", str(measured), *command]
        with open(Path(tmp) / "log.txt", "w+") as log:
            proc = subprocess.Popen(command, stdin=subprocess.DEVNULL, stdout=log,
                                    stderr=subprocess.STDOUT, env=env or child_env(),
                                    cwd=cwd)
            _, status, usage = os.wait4(proc.pid, 0)
            proc.returncode = os.waitstatus_to_exitcode(status)
            log.seek(0)
            text = log.read()
        cpu, peak = usage.ru_utime + usage.ru_stime, None
        if gnu and measured.exists():
            user, system, kb = measured.read_text().split()[-3:]
            cpu, peak = float(user) + float(system), float(kb) / 1024
    return {"cpu_s": cpu, "peak_mb": peak, "rc": proc.returncode, "output": text}


def cold_compiles() -> dict:
    """Every kernel family's compile with an empty Numba cache (``nylonflex warmup`` with
    ``NUMBA_CACHE_DIR`` a new folder): ``{family: (wall s, CPU s)}`` and the whole
    process's CPU seconds under ``"process_cpu_s"``."""
    with tempfile.TemporaryDirectory(prefix="nylonflex-cold-") as cache:
        run = _child(["warmup"], env={**child_env(), "NUMBA_CACHE_DIR": cache})
    if run["rc"] != 0:
        raise RuntimeError(f"nylonflex warmup failed with an empty cache: {run['output'][-400:]}")
    found = {m[1]: (float(m[2]), float(m[3])) for m in _COMPILED.finditer(run["output"])}
    return {"kernels": found, "process_cpu_s": run["cpu_s"]}


def light_commands(cube: Path, folder: Path) -> dict:
    """The light commands timed, by label: arguments of ``nylonflex`` on ``cube``, writing
    only under ``folder``."""
    return {
        "--version": ["--version"],
        "list materials": ["list", "materials"],
        "chart --help": ["chart", "--help"],
        "init": ["init", str(folder / "init")],
        "info": ["info", str(cube)],
        "query --where": ["query", str(cube), "--where", "tip_force_max >= 0.5 N",
                          "--limit", "5"],
        "query --at": ["query", str(cube), "--at", "radius=7.7mm,wall_thickness=2.1mm,"
                       "length=70mm,coil_index=1.5,wrap_angle=8deg"],
    }


def command_costs(cube: Path) -> dict:
    """Whole-process CPU seconds [s] and peak memory [MB] of each of :func:`light_commands` on
    ``cube`` (a warm cache): ``{label: (cpu s, peak MB)}``."""
    costs = {}
    with tempfile.TemporaryDirectory(prefix="nylonflex-light-") as tmp:
        for label, args in light_commands(Path(cube), Path(tmp)).items():
            run = _child(args, cwd=tmp)
            if run["rc"] != 0:
                raise RuntimeError(f"nylonflex {label} failed: {run['output'][-400:]}")
            costs[label] = (run["cpu_s"], run["peak_mb"])
    return costs
