import math
import os
import signal

import pytest
from hypothesis import settings

# No property test may fail for timing on a slow or busy machine: no deadline, anywhere.
# CI runs them on a fixed example sequence so that a run is repeatable; local runs keep
# exploring new examples.
settings.register_profile("local", deadline=None)
settings.register_profile("ci", deadline=None, derandomize=True)
settings.load_profile("ci" if os.environ.get("CI") else "local")


# A job a shell starts in the background (a CI runner's, `./.ci/run &`) begins with SIGINT
# ignored (POSIX: asynchronous commands ignore SIGINT and SIGQUIT), and every process it
# starts inherits that: the tests that stop a command with Ctrl-C (SIGINT) then saw it go
# on to the end (CI, 2026-12-07: test_a_signal_before_the_sweeps_own_handler_is_a_stop
# [INT-*] exit 0 and 1, where a terminal's run gives 130). The tests run as from a
# terminal: Python's own SIGINT handler here, which the commands they start set up again.
if signal.getsignal(signal.SIGINT) == signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)


DEG = math.pi / 180.0

#: docs/model.md section 8: the paper's two worked examples (a, t, L, C), psi = 8 deg, b = t.
EXAMPLE_1 = dict(radius=20e-3, wall_thickness=6e-3, length=90e-3, coil_index=1.1,
                 wrap_angle=8 * DEG)
EXAMPLE_2 = dict(radius=7.5e-3, wall_thickness=2e-3, length=70e-3, coil_index=1.7,
                 wrap_angle=8 * DEG)


@pytest.fixture
def example_1():
    return dict(EXAMPLE_1)


@pytest.fixture
def example_2():
    return dict(EXAMPLE_2)
