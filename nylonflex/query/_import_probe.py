import numpy


def f():
    import json
    import numpy as np
    from . import scan
    import scipy.optimize
    from ..kernels import design
