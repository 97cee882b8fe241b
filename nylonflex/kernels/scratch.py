"""Working arrays the engine hands the kernels, so that no compiled kernel allocates.

A kernel that makes no array compiles without Numba's reference counting
(:func:`~._compile.jit_kernel`'s ``borrows``): each thread's call gets its node table and
scratch from here. Imports no Numba (the engine's light paths import it).
"""

from __future__ import annotations

import numpy as np

from ..physics.bending import MOMENT_WORK_ROWS, _node_count
from ..physics.records import NodeTable

__all__ = ["node_scratch"]


def node_scratch(nodes):
    """An unfilled node table and scratch for the quadrature ``nodes`` (a
    :class:`~nylonflex.physics.records.Nodes`, or its four arrays): a
    :class:`~nylonflex.physics.records.NodeTable` of
    :func:`~nylonflex.physics.bending._node_count` nodes that
    :func:`~nylonflex.physics.bending._section_nodes` fills, one a thread, for the kernels
    that make no arrays of their own."""
    n = _node_count(nodes[0], nodes[3])
    return NodeTable(np.empty(n), np.empty(n), np.empty(n), np.empty((MOMENT_WORK_ROWS, n)))
