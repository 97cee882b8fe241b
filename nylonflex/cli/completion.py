"""``nylonflex completion bash|zsh|tcsh``: print a shell completion script, made by shtab
from the same parser the console script builds (every command, flag and choice)."""

from __future__ import annotations

from . import build_parser

HELP = "print a shell completion script (bash, zsh, tcsh)"
DESCRIPTION = """\
Print a shell completion script for nylonflex: commands, flags and their choices, made
from the command line's own parser (shtab). Install it once:

  nylonflex completion bash > ~/.local/share/bash-completion/completions/nylonflex
  nylonflex completion zsh > ~/.zfunc/_nylonflex   # with ~/.zfunc in fpath
"""

SHELLS = ("bash", "zsh", "tcsh")


def add_arguments(p):
    p.add_argument("shell", choices=SHELLS, help="the shell to complete in")


def run(args) -> int:
    import shtab  # here, not at the top: every command's parser imports this module

    print(shtab.complete(build_parser(), shell=args.shell))
    return 0
