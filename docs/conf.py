"""Sphinx configuration of the nylonflex documentation site.

Sphinx with the PyData theme and MyST (Markdown pages and notebooks), as xarray, pvlib and
SALib, whose sites nylonflex's users know: every page under docs/ is the Markdown file that
also reads on GitHub. The CLI reference comes from the argument parser (the
``nylonflex-cli`` directive below: each command's ``--help``, as the terminal shows it),
the API reference from the docstrings (autodoc, numpydoc style through napoleon), the
gallery from docs/examples/ (sphinx-gallery, run at every build), and the tutorial
notebook is executed at every build (myst-nb). Build: ``sphinx-build -W --keep-going docs
docs/_build/html`` (the ``docs`` extra)."""

import os
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # the checkout's nylonflex, as the tests import it
sys.path.insert(0, str(HERE / "_ext"))  # nf_docs: the CLI directive, the gallery's scraper
# ... and in the notebook's kernel and the gallery's examples
os.environ["PYTHONPATH"] = os.pathsep.join(
    [str(HERE.parent), *filter(None, [os.environ.get("PYTHONPATH")])])
os.environ.setdefault("MPLBACKEND", "Agg")

from nylonflex import __version__  # noqa: E402

project = "nylonflex"
author = "the nylonflex developers"
copyright = "2026, the nylonflex developers"
release = version = __version__

extensions = [
    "myst_nb",                 # Markdown pages (MyST) and executed notebooks
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",     # the numpydoc-style docstrings
    "sphinx.ext.mathjax",
    "sphinx_gallery.gen_gallery",
    "nf_docs",
]

source_suffix = {".rst": "restructuredtext", ".md": "myst-nb", ".ipynb": "myst-nb"}
exclude_patterns = ["_build", "tools", "examples", "tutorial_output", "**.ipynb_checkpoints",
                    "gallery/*.ipynb", "gallery/*.py", "gallery/*.zip", "gallery/*.md5",
                    "gallery/*.json"]
root_doc = "index"

myst_enable_extensions = ["dollarmath", "colon_fence", "deflist"]
myst_heading_anchors = 3          # the pages' [text](#section) links
suppress_warnings = ["myst.header"]  # pages written for GitHub start at any heading level

# the notebooks run at every build (CI): a cell that fails fails the build
nb_execution_mode = "force"
nb_execution_timeout = 600
nb_execution_raise_on_error = True

autodoc_typehints = "none"        # the docstrings state types and units
autodoc_member_order = "bysource"
napoleon_numpy_docstring = True
napoleon_google_docstring = False
napoleon_use_rtype = False


sphinx_gallery_conf = {
    "examples_dirs": "examples",
    "gallery_dirs": "gallery",
    "filename_pattern": r"/plot_",
    "image_scrapers": ("nf_docs.chart_scraper",),
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "write_computation_times": False,
    "ignore_pattern": r"^_",   # _grid.py: the grid the examples share
}

html_theme = "pydata_sphinx_theme"
html_title = f"nylonflex {version}"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
}
html_static_path = []
# what the tutorial notebook writes (its explorer page), published beside it
(HERE / "tutorial_output").mkdir(exist_ok=True)
html_extra_path = ["tutorial_output"]
