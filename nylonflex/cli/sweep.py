"""``nylonflex sweep CONFIG``: validate, sweep, write the cube and its charts."""

from __future__ import annotations

import gc
import shlex
import sys
from contextlib import ExitStack
from pathlib import Path

from . import EARLY_SIGNALS
from ._common import progress_bar

HELP = "evaluate a design space into a cube"


def add_arguments(s):
    s.add_argument("config", help="YAML config ('nylonflex init' writes examples to edit)")
    s.add_argument("--out", help="cube path (default sweeps/<name>/cube.h5)")
    s.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override a config key, e.g. grid.radius.num=81 or "
                        "silicone.file=fits/my.yaml (repeatable; a file path is read from "
                        "the current folder, one in the config from the config's folder)")
    s.add_argument("--resume", action="store_true", help="finish an interrupted run")
    s.add_argument("--overwrite", action="store_true",
                   help="replace a cube already at --out (the old one stays until the new "
                        "one is complete)")
    s.add_argument("--workers", type=int, help="local threads (default: all cores)")
    s.add_argument("--scheduler", metavar="ADDRESS",
                   help="run on a Dask distributed cluster, e.g. tcp://host:8786")
    s.add_argument("--no-charts", action="store_true", help="skip the config's charts")
    s.add_argument("--quiet", action="store_true", help="no progress bar")
    s.add_argument("--dry-run", action="store_true",
                   help="print the grid size, the cube's size on disk, memory and an "
                        "estimated time (measured on a small sample); write nothing")


def run(args) -> int:
    return _run(args, charts=not (args.no_charts or args.dry_run))


def _run(args, charts: bool) -> int:
    from ..files.atomic import refuse_special

    bar = None  # while the sweep's bar shows, a message goes above it, never into it

    def log(msg):
        if not args.quiet:
            bar.write(msg) if bar is not None else print(msg, file=sys.stderr)

    # from the kernels' loading to the sweep's end, Ctrl-C and SIGTERM are recorded, never
    # raised inside a finaliser where Python would drop them (Numba's loading runs them):
    # the sweep then stops before its first slab (docs/reliability.md)
    with ExitStack() as signals:
        with _collect_after_start():
            from ..config import load_config
            from ..engine.slabs import deferred_signals
            from ..storage.journal import file_locks
            from ..sweep.conductor import default_output, prepare, sweep_file

            cfg = load_config(args.config, args.set)
            out = Path(args.out) if args.out else default_output(cfg)
            refuse_special(out, "--out")
            if args.dry_run:
                return _dry_run(cfg, out, args, log)
            file_locks()  # a platform without POSIX locks is refused before any work
            signals.enter_context(deferred_signals(on_second=_stop_at_once, earlier=EARLY_SIGNALS))
            unchanged = _up_to_date(cfg, out, args)
            # the chart libraries load while the kernel compiles, when it has to
            prepare(cfg, workers=args.workers, scheduler=args.scheduler, log=log,
                    meanwhile=_chart_libraries if charts and cfg.charts and not unchanged
                    else None)
        with progress_bar("sweep", unit="design", quiet=args.quiet, delay=0.0,
                          unit_scale=True) as bar:
            bar(0, cfg.n_designs)
            sweep_file(cfg, out, resume=args.resume, workers=args.workers,
                       scheduler=args.scheduler, progress=bar.update, log=log,
                       overwrite=args.overwrite, command=_command_line(args))
        bar = None
    print(f"{out}  {cfg.n_designs:,} designs  complete")
    if not charts or not cfg.charts:
        return 0

    names = list(cfg.charts)
    if unchanged:  # nothing was computed: the charts already beside it stay as they are
        names = [n for n in names if not _chart_drawn(out.parent, n)]
        if len(names) < len(cfg.charts):
            log(f"charts beside {out} are up to date (the cube did not change): "
                f"{len(cfg.charts) - len(names)} kept; 'nylonflex chart {out}' redraws them")
        if not names:
            return 0
    skip = lambda msg: print(f"nylonflex sweep: {msg}", file=sys.stderr)  # noqa: E731
    with progress_bar("charts", unit="chart", quiet=args.quiet, delay=0.0) as bar:
        # beside the cube: only this cube's earlier charts are replaced, others skipped
        paths = _draw(out, names, skip, bar)
    for path in paths:
        print(path)
    return 0


def _command_line(args) -> str:
    """The sweep as a command line, for the cube's ``history``: the config, every option
    given (--set, --out, --resume, ...), shell-quoted."""
    words = ["nylonflex", "sweep", str(args.config)]
    words += [w for value in args.set or () for w in ("--set", value)]
    for flag, value in (("--out", args.out), ("--workers", args.workers),
                        ("--scheduler", args.scheduler)):
        if value is not None:
            words += [flag, str(value)]
    words += [flag for flag, on in (("--resume", args.resume), ("--overwrite", args.overwrite))
              if on]
    return shlex.join(words)


def _chart_libraries():
    """Import what drawing the charts needs (matplotlib, xarray); a failure is left to the
    drawing, which reports it."""
    try:
        from ..charts import warm_up

        warm_up()
    except Exception:  # noqa: BLE001, S110 - the drawing imports again and says why
        pass


def _draw(out, names, skip, progress) -> list:
    """Draw the charts ``names`` of the complete cube ``out`` beside it; only this cube's
    earlier charts are replaced (others are skipped, reported through ``skip``)."""
    from ..charts import draw_charts
    from ..storage import open_cube

    ds = open_cube(out)
    try:
        return draw_charts(ds, names, out.parent, "png", on_skip=skip, progress=progress,
                           refuse_foreign=False)
    finally:
        ds.close()


def _up_to_date(cfg, out, args) -> bool:
    """Whether ``out`` already holds this config's complete cube, so the sweep will have
    nothing to do (storage decides that too; here it only spares the charts)."""
    if getattr(args, "overwrite", False) or not out.is_file():
        return False
    from ..storage.reader import cube_attrs

    try:
        attrs = cube_attrs(out)
    except Exception:  # noqa: BLE001 - not a cube: the sweep itself says so
        return False
    from ..variables import is_complete

    return bool(attrs) and is_complete(attrs) and attrs.get("config_sha256") == cfg.sha256


def _chart_drawn(folder, name) -> bool:
    """A chart ``name`` is beside the cube (``fig4.png``, or per model ``fig4_paper.png``)."""
    return (folder / f"{name}.png").is_file() or any(folder.glob(f"{name}_*.png"))


def _stop_at_once():
    """A second Ctrl-C while the sweep starts: stop now."""
    raise KeyboardInterrupt


class _collect_after_start:
    """The garbage collector paused while the command starts, and what it made frozen.

    Importing the config, Numba, the kernels and HDF5 makes about a million objects that
    live as long as the process; collecting them as they come, again and again, took 0.1-0.2
    s of a 2 s sweep. Afterwards they are frozen (:func:`gc.freeze`), so that the
    collections of the run skip them, and the collector runs as before.
    """

    def __enter__(self):
        self.enabled = gc.isenabled()
        gc.disable()
        return self

    def __exit__(self, *exc):
        gc.freeze()
        if self.enabled:
            gc.enable()
        return False


def _size(n) -> str:
    for unit in ("B", "kB", "MB", "GB", "TB"):
        if n < 1000 or unit == "TB":
            return f"{n:.0f} {unit}" if unit == "B" else f"{n:.3g} {unit}"
        n /= 1000.0


def _duration(seconds) -> str:
    if seconds < 90:
        return f"{seconds:.2g} s" if seconds < 10 else f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"


def _dry_run(cfg, out, args, log) -> int:
    from ..sweep.conductor import estimate

    if args.scheduler:
        log("dry run: the time is estimated for this machine's threads, not the cluster")
    e = estimate(cfg, workers=args.workers, notice=log)
    shape = " x ".join(f"{n} {name}" for name, n in e["shape"].items())
    print(f"dry run of {args.config} (nothing written)")
    print(f"  grid        {e['designs']:,} designs = {shape}")
    print(f"  cube        {out}: about {_size(e['disk_bytes'])} on disk "
          f"({_size(e['raw_bytes'])} uncompressed, compressed to "
          f"{100 * e['compression_ratio']:.0f} % as a sample was); the journal holds "
          "about as much again while it runs")
    print(f"  memory      about {_size(e['memory_bytes'])} ({e['slabs']} slab"
          f"{'s' if e['slabs'] != 1 else ''} of up to {_size(e['slab_bytes'])}, two at once, "
          "plus Python and the kernels)")
    print(f"  time        about {_duration(e['seconds'])} here "
          f"({e['designs_per_second']:,.0f} designs/s measured on {e['sample_designs']:,} "
          f"designs, plus compression{'; charts extra' if cfg.charts else ''})")
    if out.exists():
        print(f"  note        {out} exists: a sweep would refuse it (or --resume it)")
    return 0
