"""Helpers the command modules share: opening a cube with its warning as one line, and the
one progress report of every long command (a bar on a terminal, a line a minute off one)."""

from __future__ import annotations

import sys
import threading
import time
import warnings


def open_cube_for(command: str, path, light=None):
    """:func:`nylonflex.open_cube` for a command: an incomplete cube's warning as one line.

    ``light``: a test of a :class:`~nylonflex.storage.light.LightCube` (the cube read
    through h5py alone, no xarray); where the cube opens as one and passes it, that view is
    returned instead of the Dataset (with the same checks and warning).
    """
    from ..storage import open_cube, open_light

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        ds = open_light(path) if light is not None else None
        if ds is not None and not light(ds):
            ds.close()
            ds = None
        if ds is None:
            del caught[:]  # open_cube warns again
            ds = open_cube(path)
    for w in caught:
        say(f"nylonflex {command}: warning: {w.message}")
    return ds


#: Seconds between the progress lines of a command whose stderr is not a terminal.
LINE_EVERY = 60.0

#: The progress report showing now (messages go above its bar), or None.
ACTIVE = None


def say(message: str):
    """One message line on stderr: above the progress bar while one shows (tqdm.write),
    never into it; the warnings and compile notices of every command come through here."""
    if ACTIVE is not None:
        ACTIVE.write(message)
    else:
        print(message, file=sys.stderr, flush=True)


class progress_bar:
    """The progress of a long command, on every output: ``bar(done, total)``.

    The domain code takes a ``progress(done, total)`` callback; this is the CLI's one.
    On a terminal (stderr) it is a tqdm bar that appears after ``delay`` seconds (quick
    work prints nothing) and leaves no trace when it closes; otherwise (a pipe, a log file,
    a batch job) a line every :data:`LINE_EVERY` seconds, ``nylonflex verify: 3 of 8 designs
    (38 %), 12 min elapsed, about 20 min left``, from a timer, so that a step longer than a
    minute still says the command is alive. ``--quiet`` prints neither. Work with no count
    (``total`` None: a simulation, a fit) shows the time elapsed.

    Messages while it runs go through :meth:`write` (above the bar, never into it).
    """

    def __init__(self, desc: str, unit: str = "it", quiet: bool = False, delay: float = 0.5,
                 command: str | None = None, unit_scale: bool = False,
                 every: float | None = None):
        self.desc, self.unit, self.delay = desc, unit, delay
        self.command = command or desc
        self.unit_scale, self.every = unit_scale, LINE_EVERY if every is None else every
        self.quiet = quiet
        self.tty = sys.stderr.isatty()
        self.enabled = not quiet and self.tty  # the bar (kept for the callers that ask)
        self.done, self.total = 0, None
        self._bar = None
        self._stop = None
        self._timer = None

    def __enter__(self):
        global ACTIVE
        self._previous, ACTIVE = ACTIVE, self
        self._start = time.monotonic()
        if not self.quiet:
            self._stop = threading.Event()
            self._timer = threading.Thread(target=self._tick, daemon=True,
                                           name=f"nylonflex-progress-{self.desc}")
            self._timer.start()
        return self

    def __call__(self, done, total=None):
        self.done, self.total = done, total
        if not self.enabled:
            return
        if self._bar is None:
            from tqdm import tqdm

            self._bar = tqdm(total=total, desc=self.desc, unit=self.unit, leave=False,
                             delay=self.delay, dynamic_ncols=True, file=sys.stderr,
                             unit_scale=self.unit_scale, smoothing=0.1)
        self._bar.total = total
        self._bar.update(done - self._bar.n)

    def update(self, n):
        """Count ``n`` more done (tqdm's own call, for code that counts in steps)."""
        self(self.done + n, self.total)

    def write(self, message: str):
        """Print ``message`` on stderr, above the bar (tqdm.write) while it shows."""
        if self._bar is not None:
            self._bar.write(message, file=sys.stderr)
        else:
            print(message, file=sys.stderr, flush=True)

    def line(self) -> str:
        """The progress as one line: ``nylonflex verify: 3 of 8 designs (38 %), 12 min
        elapsed, about 20 min left``."""
        elapsed = time.monotonic() - self._start
        head = f"nylonflex {self.command}" + (f": {self.desc}" if self.desc != self.command
                                               else "")
        if not self.total:
            return f"{head}: running, {_duration(elapsed)} elapsed"
        part = self.done / self.total
        left = (f", about {_duration(elapsed * (1 - part) / part)} left"
                if 0 < part < 1 else "")
        return (f"{head}: {_count(self.done)} of {_count(self.total)} {self.unit}s "
                f"({100 * part:.0f} %), {_duration(elapsed)} elapsed{left}")

    def _tick(self):
        """The timer: a line every ``every`` seconds off a terminal; on a terminal, the
        bar of work with no count kept moving (its elapsed time)."""
        step = self.every if not self.tty else 1.0
        while not self._stop.wait(step):
            if not self.tty:
                print(self.line(), file=sys.stderr, flush=True)
            elif self.total is None and self.enabled:
                self(self.done, None)
                if self._bar is not None:
                    self._bar.refresh()

    def __exit__(self, *exc):
        global ACTIVE
        ACTIVE = self._previous
        if self._stop is not None:
            self._stop.set()
            # a line the timer is printing lands before the block ends, never after it
            self._timer.join(timeout=5.0)
        if self._bar is not None:
            self._bar.close()
            self._bar = None
        return False


def _count(x) -> str:
    """A count as read: ``1,234``; a fraction of one (an FE solve's progress) ``0.81``."""
    return f"{int(x):,}" if float(x).is_integer() else f"{x:,.2f}"


def _duration(seconds: float) -> str:
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"
