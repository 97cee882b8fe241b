import math
import os

import pytest
from hypothesis import settings

# No property test may fail for timing on a slow or busy machine: no deadline, anywhere.
# CI runs them on a fixed example sequence so that a run is repeatable; local runs keep
# exploring new examples.
settings.register_profile("local", deadline=None)
settings.register_profile("ci", deadline=None, derandomize=True)
settings.load_profile("ci" if os.environ.get("CI") else "local")


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
