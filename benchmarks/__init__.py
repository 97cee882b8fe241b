"""nylonflex's benchmarks, which come with a source checkout (not with the package).

``suite.py``: the suite ``nylonflex bench [--quick]`` runs (nylonflex/cli/bench.py finds
this folder beside the package of an editable install); ``yardstick.py``: the NumPy
yardstick it times the grid kernel against; ``issue27.sh``: issue 27's whole-process
figures. The scipy reference the suite times is the tests' ``tests/naive.py``.
"""
