"""nylonflex's own Sphinx pieces (docs/conf.py loads this as an extension): the
``nylonflex-cli`` directive (the CLI reference, made from the parser), the gallery's image
scraper, and the escape of ``|x|`` in docstrings."""

def _figures(value):
    from matplotlib.figure import Figure

    if isinstance(value, Figure):
        yield value
    elif isinstance(value, dict):
        for item in value.values():
            yield from _figures(item)
    elif isinstance(value, (list, tuple)):
        for item in value:
            yield from _figures(item)


_DRAWN: dict = {}


def chart_scraper(block, block_vars, gallery_conf):
    """The gallery's images: the matplotlib Figures an example holds (nylonflex's charts
    are Figures made without pyplot, so sphinx-gallery's own scraper cannot see them)."""
    from sphinx_gallery.scrapers import figure_rst

    drawn = _DRAWN.setdefault(block_vars["src_file"], set())
    paths = []
    for fig in _figures(list(block_vars["example_globals"].values())):
        if id(fig) in drawn:
            continue
        drawn.add(id(fig))
        path = next(block_vars["image_path_iterator"])
        fig.savefig(path, dpi=80)
        paths.append(path)
    return figure_rst(paths, gallery_conf["src_dir"])


def _absolute_bars(app, what, name, obj, options, lines):
    """Docstrings write absolute values as |x| (plain text for help()); in reST a bar
    opens a substitution, so bars outside tables are escaped."""
    for i, line in enumerate(lines):
        if "|" in line and not line.lstrip().startswith(("|", "+")):
            lines[i] = line.replace("|", "\\|")


def _subparsers(parser):
    import argparse

    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            yield from action.choices.items()


def _cli_sections():
    """(title, help text) of ``nylonflex`` and of every command and sub-command, from the
    parser the console script itself builds."""
    from nylonflex.cli import build_parser

    parser = build_parser()
    yield "nylonflex", parser.format_help()
    for name, sub in _subparsers(parser):
        yield f"nylonflex {name}", sub.format_help()
        for inner, subsub in _subparsers(sub):
            yield f"nylonflex {name} {inner}", subsub.format_help()


def _cli_directive():
    from docutils import nodes
    from sphinx.util.docutils import SphinxDirective

    class NylonflexCli(SphinxDirective):
        """Every command's ``--help`` as a section with a literal block."""

        def run(self):
            out = []
            for title, text in _cli_sections():
                ident = nodes.make_id(title)
                section = nodes.section(ids=[ident], names=[nodes.fully_normalize_name(title)])
                section += nodes.title(text=title)
                section += nodes.literal_block(text, text, language="text")
                out.append(section)
                self.state.document.note_implicit_target(section)
            return out

    return NylonflexCli


def setup(app):
    app.connect("autodoc-process-docstring", _absolute_bars)
    app.add_directive("nylonflex-cli", _cli_directive())
