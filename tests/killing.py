"""Stop a ``nylonflex`` run at a fixed point: right after its K-th slab is stored.

The kill-and-resume tests used to poll the journal from outside and kill when it looked
half done; on a fast machine the run could finish first and the test skipped itself. Here
the run signals itself from inside the slab loop, so the kill lands at the same point on a
fast machine and a slow one.
"""

import os
import subprocess
import sys

#: Runs ``nylonflex ARGS`` and signals itself once the sink has journaled K slabs: the kill
#: lands at the same point on a fast machine and a slow one (no race with a timer).
_KILL_AFTER = """
import os, signal, sys
import nylonflex.engine.slabs as slabs
import nylonflex.sweep.run as run

K, SIG = int(sys.argv[1]), int(sys.argv[2])
original = slabs.run_slabs


def run_slabs(cfg, plan, todo, executor, sink, progress=None):
    class Killing:
        stored = 0

        def put(self, *args):
            sink.put(*args)
            Killing.stored += 1
            if Killing.stored == K:
                # a file sink journals a slab while the next one is stored: wait for the
                # K-th journal file, so the kill lands after K journaled slabs
                getattr(sink, "flush", lambda: None)()
                os.kill(os.getpid(), SIG)

    return original(cfg, plan, todo, executor, Killing(), progress)


run.run_slabs = run_slabs
from nylonflex.cli import main
sys.exit(main(sys.argv[3:]))
"""


def kill_after_slabs(argv, k, sig, timeout=300):
    """Run ``nylonflex ARGV`` in a fresh process that sends itself ``sig`` right after its
    ``k``-th slab is stored (journaled, for a sweep to a file); return its exit status."""
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    proc = subprocess.run([sys.executable, "-c", _KILL_AFTER, str(k), str(int(sig)),
                           *argv], env=env, capture_output=True, timeout=timeout)
    return proc.returncode


