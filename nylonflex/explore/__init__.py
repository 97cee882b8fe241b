"""``nylonflex explore``: one page over a cube, served locally or saved as one offline file.

* :mod:`.data`: the parts of a cube the page shows (display units, flag names, the
  stand-in note, "copy as config"), read lazily, never interpolated;
* :mod:`.page`: the page itself, one Bokeh document whose views are all drawn in the
  browser by ``update.js`` from one state; :func:`~.page.build_html` saves it,
  :func:`~.page.serve` serves it. Bokeh is imported only when a page is built;
* :mod:`.views`: the page's views (the state's widgets, the map, the lines, the curves,
  the ``--where`` table), each built from the page's numbers;
* :mod:`.fidelity`, :mod:`.model_spread`: the parts of a page that a ``verify`` dataset
  and a model spread add.
"""

from .data import *  # noqa: F401,F403
from .data import __all__ as _data_all
from .page import DEFAULT_DESIGN, MAX_DESIGNS, build_document, build_html, serve

__all__ = [*_data_all, "DEFAULT_DESIGN", "MAX_DESIGNS", "build_document", "build_html", "serve"]
