"""The sweep conductor: a config's grid through the engine's slab loop into a cube.

- :mod:`.conductor`: :func:`run_sweep` (in memory or into a file), :func:`sweep_file`,
  the dry run's estimate, the compile-aside start, locally or on a Dask cluster;
- :mod:`.run`: a sweep into a file: the journaled sink of the slab loop, resume, the
  signals' exits (:class:`~.run.CubeSink`, :class:`~.run.Interrupted`).

It sits above the engine (which computes slabs) and storage (which writes and reads the
cube), and is the one place that joins them.
"""
