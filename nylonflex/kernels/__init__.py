"""Numba kernels over design grids. Only :mod:`nylonflex.sweep` (and the simulator) call them."""
