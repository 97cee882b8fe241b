"""The ``nylonflex`` command line: argument parsing and printing, and nothing else.

Each command is a module of this package with ``HELP`` (one line), ``add_arguments(parser)``
and ``run(args) -> int``; it calls library functions that return values and prints them. No
science lives here. Exit status: 0 done (also when the reader of the output has gone:
``nylonflex list | head -1``), 2 bad input (one line naming the field) or a problem of the
environment (a read-only or full folder, a missing extra, a damaged chunk: one line naming
it, :func:`environment_problem`), 1 other failure, 128 + the signal for a run a signal
stopped (130 Ctrl-C, 143 SIGTERM). A traceback is printed only with ``--debug``.

Command modules import nothing heavy at module level, so ``nylonflex --help`` stays light.
"""

from __future__ import annotations

import argparse
import atexit
import errno as errnos
import importlib
import os
import signal
import sys
import threading
import warnings

from .. import __version__
from ._common import say

EXIT_OK, EXIT_FAILURE, EXIT_INPUT = 0, 1, 2

#: The commands, in the order ``--help`` lists them: name -> module of this package.
COMMANDS = {
    "sweep": "sweep",
    "chart": "chart",
    "query": "query",
    "design": "design",
    "info": "info",
    "simulate": "simulate",
    "bench": "bench",
    "warmup": "warmup",
    "fit": "fit",
    "validate": "validate",
    "init": "init",
    "list": "listing",
    "schema": "schema",
    "sensitivity": "sensitivity",
    "explore": "explore",
    "fe": "fe",
    "verify": "verify",
    "completion": "completion",
}


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # argparse's own usage errors are bad input too: one line, 2
        self.exit(EXIT_INPUT, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")


def _module(name):
    return importlib.import_module(f".{COMMANDS[name]}", __name__)


def build_parser(command: str | None = None, alone: bool = False) -> argparse.ArgumentParser:
    """The parser of every ``nylonflex`` command (docs/interface.md).

    ``command``: only that command's arguments are added (the others are listed by name
    and help line only, which is all ``--help`` and ``--version`` need), so a command
    imports nothing it does not use; None adds every command's arguments. ``alone``: the
    other commands are left out altogether (their modules not imported, their parsers not
    made: 25-30 ms of every command), for a command line that names ``command`` first.
    """
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--debug", action="store_true", help="show tracebacks on errors")
    p = _Parser(prog="nylonflex", parents=[common],
                description="Design-space sweeps of nylon-muscle soft bending actuators.")
    p.add_argument("--version", action="version", version=f"nylonflex {__version__}")
    sub = p.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for name in COMMANDS if not (alone and command) else (command,):
        mod = _module(name)
        sp = sub.add_parser(name, parents=[common], help=mod.HELP,
                            description=getattr(mod, "DESCRIPTION", mod.HELP),
                            formatter_class=argparse.RawDescriptionHelpFormatter)
        if command is None or name == command:
            mod.add_arguments(sp)
    return p


def _command(argv) -> str:
    """The command named in ``argv`` ("" when there is none: ``--help``, ``--version``)."""
    return next((a for a in argv if a in COMMANDS), "")


def _named_first(argv, command: str) -> bool:
    """Whether ``command`` is the first argument of ``argv`` that is not an option (so
    that a parser of that command alone reads ``argv`` as the whole parser would)."""
    return bool(command) and next((a for a in argv if not a.startswith("-")), "") == command


def _join_negative_values(argv):
    """``--sort -tip_force_max`` means descending; argparse would read ``-tip...`` as a flag."""
    out = list(argv)
    for i, item in enumerate(out[:-1]):
        if item == "--sort" and out[i + 1].startswith("-") and out[i + 1][1:2].isalpha():
            out[i:i + 2] = [f"--sort={out[i + 1]}"]
            return _join_negative_values(out)
    return out


def run():
    """The ``nylonflex`` console script and ``python -m nylonflex``: :func:`main`, then exit.

    Tearing the interpreter down (freeing Numba's, NumPy's and h5py's objects one by one)
    took 30-45 ms of every command. Once the command has returned, its files are closed;
    here its output is flushed, the exit handlers run (``atexit``: multiprocessing,
    logging, thread pools, weakref finalizers), and the process ends without freeing the
    rest, as mypy's ``--fast-exit`` does. Where a normal exit would still wait for
    something (a non-daemon thread) or the output cannot be flushed (a closed pipe), the
    exit is the usual one.
    """
    _block_unused_dask(_command(sys.argv[1:]))
    code = main()
    try:
        sys.stdout.flush()
    except BrokenPipeError:  # the last of the output, into a closed pipe
        code = closed_output()
    try:
        sys.stdout.flush()
        sys.stderr.flush()
    except (OSError, ValueError):
        sys.exit(code)  # Python reports it as usual
    if any(t is not threading.main_thread() and not t.daemon
           for t in threading.enumerate()):
        sys.exit(code)

    atexit._run_exitfuncs()
    try:
        sys.stdout.flush()
        sys.stderr.flush()
    finally:
        os._exit(0 if code is None else int(code))


#: Commands that read cubes and configs and never compute on Dask: they import no Numba
#: (their modules import none) and no dask (:func:`_block_unused_dask`); tests/test_layers.py
#: runs each and checks. ``query --at`` off the grid evaluates (Numba, never dask).
LIGHT_COMMANDS = ("info", "query", "chart", "list", "init")


def _block_unused_dask(command):
    """Keep dask out of a light command's own process (the console script only).

    xarray imports ``dask.base`` and ``dask.array`` (0.3-0.5 CPU-s) the first time it
    checks whether an array is a dask one, whenever dask is installed. A ``None`` in
    ``sys.modules`` is Python's documented way to make a module unimportable, and
    ``importlib.util.find_spec`` (xarray's check) then reports it absent: xarray works on
    NumPy arrays only, which is all these commands give it. Not done by :func:`main`, so
    that a process running several commands (the tests) keeps dask for the others.
    """
    if command in LIGHT_COMMANDS and "dask" not in sys.modules:
        sys.modules["dask"] = None


#: SIGINT and SIGTERM (numbers) that reached the running command before a sweep's
#: ``deferred_signals`` scope took them over (:class:`_early_signals`).
EARLY_SIGNALS: list = []


def main(argv=None) -> int:
    """The command line: run the command in ``argv`` (default ``sys.argv[1:]``) and return
    its exit status (:func:`run` is the console script around it)."""
    _lighten_process()
    EARLY_SIGNALS.clear()
    try:
        with _early_signals():
            return _main(argv)
    except KeyboardInterrupt:  # Ctrl-C while the parser's modules are imported
        print("nylonflex: interrupted", file=sys.stderr)
        return interrupted_status()


class _early_signals:
    """From a command's start, SIGINT and SIGTERM are recorded (:data:`EARLY_SIGNALS`) and
    raise ``KeyboardInterrupt``; the handlers before it are put back at the end.

    Without it, a signal that lands while numpy's C extension is being imported leaves
    numpy half-initialised: Python's KeyboardInterrupt can be lost on the way (a finaliser
    drops it) and the next ``import numpy`` fails with an ImportError, which the command
    would report as a failure (exit 1) instead of a stop. With the record, any exception
    after a signal is a stop (:func:`_main`), and a sweep's ``deferred_signals`` scope
    starts with it, so the sweep stops before its first slab. SIGTERM used to end the
    process at once (status -15) until the sweep's own handler was set; it now stops the
    command as Ctrl-C does, with status 143. Handlers someone else set (an embedding
    program's) are left alone, and nothing is done outside the main thread.
    """

    def __enter__(self):
        self.previous = {}
        if threading.current_thread() is not threading.main_thread():
            return self
        defaults = {signal.SIGINT: signal.default_int_handler, signal.SIGTERM: signal.SIG_DFL}
        for sig, default in defaults.items():
            if signal.getsignal(sig) is default:
                self.previous[sig] = signal.signal(sig, _record_signal)
        return self

    def __exit__(self, *exc):
        for sig, old in self.previous.items():
            signal.signal(sig, old)
        return False


def _record_signal(signum, frame):
    EARLY_SIGNALS.append(int(signum))
    raise KeyboardInterrupt


def interrupted_status() -> int:
    """The exit status of a command a signal stopped: 128 + the signal's number, the shell's
    convention (130 for Ctrl-C, 143 for SIGTERM)."""
    if EARLY_SIGNALS:
        return 128 + EARLY_SIGNALS[0]
    slabs = sys.modules.get("nylonflex.engine.slabs")  # it records the sweep's signals
    sig = slabs.stopping_signal() if slabs is not None else None
    return 128 + int(sig or signal.SIGINT)


def _lighten_process():
    """Settings of a command's own process, made before numpy is imported.

    OpenBLAS's thread pool is kept to one thread (unless the user set its size): the
    commands' parallel work is Numba's threads, and the pools of numpy's and scipy's
    OpenBLAS spin as they start, about 0.2 CPU-s of every command on a 2-core machine, for
    no BLAS work.
    """
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")


def _main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    command = _command(argv)
    parser = build_parser(command, alone=_named_first(argv, command))
    args = parser.parse_args(_join_negative_values(argv))
    if args.command is None:
        parser.print_help()
        return EXIT_OK
    try:
        with _compile_notices(args.command):
            return _module(args.command).run(args) or EXIT_OK
    except KeyboardInterrupt:
        print("nylonflex: interrupted", file=sys.stderr)
        return interrupted_status()
    except BrokenPipeError:  # `nylonflex list | head -1`: the reader has all it wanted
        return closed_output()
    except Exception as exc:  # noqa: BLE001 - one line for the user, --debug for the rest
        if args.debug:
            raise
        if EARLY_SIGNALS:  # a signal's fallout (a half-imported numpy): a stop
            print("nylonflex: interrupted", file=sys.stderr)
            return interrupted_status()
        if isinstance(exc, ValueError):  # InputError and the physics' range checks
            print(f"nylonflex {args.command}: error: {one_line(exc)}", file=sys.stderr)
            return EXIT_INPUT
        problem = environment_problem(exc, args)
        if problem:  # the machine's, not the program's: a read-only folder, an extra
            print(f"nylonflex {args.command}: error: {problem}", file=sys.stderr)
            return EXIT_INPUT
        print(f"nylonflex {args.command}: failed: {type(exc).__name__}: {one_line(exc)}",
              file=sys.stderr)
        return EXIT_FAILURE


def closed_output() -> int:
    """The reader of stdout has gone (a pipe into ``head``): stop quietly with status 0.

    Python's own advice (the signal module's docs, "Note on SIGPIPE"): point stdout at
    /dev/null, so that the interpreter's last flush does not fail again.
    """
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass
    return EXIT_OK


#: Optional dependencies by the module a command imports: ImportError -> what to install.
EXTRAS = {"felupe": "fe", "bokeh": "explore", "zstandard": "zstd", "hdf5plugin": "zstd",
          "distributed": "dask", "dask": "dask"}

#: errno values of an OSError that is the machine's state, not the program's fault.
_ENV_ERRNOS = {"EACCES": "permission denied", "EPERM": "not permitted",
               "EROFS": "a read-only file system", "ENOSPC": "no space left on the device",
               "EDQUOT": "the disk quota is exceeded"}

#: The words of HDF5's error for a chunk whose bytes do not decode.
_DAMAGED = ("filter returned failure", "can't synchronously read data", "can't read data")


def environment_problem(exc, args=None) -> str | None:
    """One line for an exception that is the environment's (exit 2), else None.

    A folder or disk that refuses the write (permission, read-only, full), an optional
    dependency not installed (its extra named, :data:`EXTRAS`), a cube whose chunk does not
    decode (the chunk named, by :func:`nylonflex.storage.check_cube`).
    """
    if type(exc).__name__ in ("MissingPlugin", "DiskFull"):
        return one_line(exc)
    if isinstance(exc, ImportError):
        top = (getattr(exc, "name", None) or "").split(".")[0]
        if top in EXTRAS:
            return (f"needs the optional package {top}: pip install "
                    f"'nylonflex[{EXTRAS[top]}]'")
        return None
    if not isinstance(exc, OSError):
        return None
    code = errnos.errorcode.get(exc.errno or -1, "")
    if code in _ENV_ERRNOS:
        where = exc.filename or getattr(args, "out", None) or "the output"
        if os.path.basename(str(where)).startswith("."):  # a temporary beside the file
            where = os.path.dirname(str(where)) or "."
        todo = "free some space there, or write somewhere else (--out)" \
            if code in ("ENOSPC", "EDQUOT") else "write somewhere else (--out)"
        return f"cannot write {where}: {_ENV_ERRNOS[code]}; {todo}"
    if any(w in str(exc).lower() for w in _DAMAGED):
        return _damaged_chunk(getattr(args, "cube", None), exc)
    return None


def _damaged_chunk(cube, exc) -> str:
    """The damaged chunk of ``cube`` named (the first :func:`check_cube` finds)."""
    found = []
    if cube:
        try:
            from ..storage import check_cube

            found = check_cube(cube, full=True)
        except Exception:  # noqa: BLE001 - the original error is reported instead
            found = []
    if found:
        more = f" (and {len(found) - 1} more: nylonflex info {cube} --check)" \
            if len(found) > 1 else ""
        return f"{found[0]}{more}"
    return (f"{cube or 'the cube'}: a chunk cannot be read ({one_line(exc)}); the cube is "
            f"damaged: 'nylonflex info {cube or 'CUBE'} --check' names it; sweep it again "
            "with --overwrite")


class _compile_notices:
    """A kernel compiling during a command (nylonflex.kernels.compiling's
    ``CompileWarning``, Numba's own signal): one line on stderr, when it starts. Other
    warnings are shown as Python shows them. Nothing is imported here (no numba)."""

    def __init__(self, command):
        self.command = command

    def __enter__(self):
        self._show = warnings.showwarning

        def show(message, category, filename, lineno, file=None, line=None):
            if category.__name__ == "CompileWarning":  # above a progress bar, never in it
                say(f"nylonflex {self.command}: {message}")
            else:
                self._show(message, category, filename, lineno, file, line)

        warnings.showwarning = show
        return self

    def __exit__(self, *exc):
        warnings.showwarning = self._show
        return False


def one_line(exc) -> str:
    """An exception's message on one line (at most 500 characters)."""
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text if len(text) <= 500 else text[:497] + "..."


def warn(command: str, message: str):
    """One warning line on stderr, ``nylonflex COMMAND: warning: ...`` (above a progress
    bar, never in it)."""
    say(f"nylonflex {command}: warning: {message}")


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
