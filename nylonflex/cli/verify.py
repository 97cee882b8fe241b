"""``nylonflex verify CUBE``: the FE twin on a sample of the cube's designs."""

from __future__ import annotations

import argparse
import time

from ..units import InputError
from ._common import progress_bar
from ._verify_stroke import run_stroke

HELP = "hold a cube's models against the FE twin (needs the [fe] extra)"
DESCRIPTION = """\
Sample designs over the cube's axes (the paper's examples among them where the cube holds
them), solve each with the finite-element twin at half and all of the pressure it reaches,
and write a fidelity dataset beside the cube (<cube>.fidelity.nc): every variant's bend
angle over the FE's, per design and pressure. Each FE run is journaled: a killed verify
resumes where it stopped. 'nylonflex chart CUBE --figure fidelity_map' draws the map.
--drive stroke instead drives the sealed twin by each design's full stroke s* and holds
every model's pressure_max and bend_angle_max (tip_force_max with --blocked) against it:
<cube>.fidelity_stroke.nc and its map."""


def _integer(text):
    """An integer flag's value (argparse names the flag in its message)."""
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be an integer, got {text!r}") from None


def add_arguments(p):
    p.add_argument("cube")
    p.add_argument("--designs", type=_integer, default=24, metavar="N",
                   help="designs to sample (default 24, at most 500)")
    p.add_argument("--workers", type=_integer, default=1, metavar="N",
                   help="local processes, one FE run each (default 1)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="a Dask scheduler (tcp://HOST:PORT): the runs go to its workers")
    p.add_argument("--mesh", default="coarse", metavar="coarse|default|fine",
                   help="the FE mesh (default coarse); the FE angle is its Richardson "
                        "extrapolation with the next coarser mesh")
    p.add_argument("--seed", type=_integer, default=0, help="the sample's seed (default 0)")
    p.add_argument("--overwrite", action="store_true",
                   help="replace a <cube>.fidelity.nc or its map that nylonflex did not "
                        "write for this cube")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--drive", default="pressure", metavar="pressure|stroke",
                   help="pressure (default): the twin at half and all of each design's p*; "
                        "stroke: the sealed twin at each design's full stroke s*, every "
                        "model's pressure_max and bend_angle_max over the twin's "
                        "(<cube>.fidelity_stroke.nc)")
    p.add_argument("--blocked", action="store_true",
                   help="with --drive stroke: also the held tip, tip_force_max over the "
                        "twin's force")


def run(args) -> int:
    import xarray as xr

    from ..charts.fidelity import fidelity_map
    from ..fe import require_felupe
    from ..fe.verify import check_outputs, fidelity_map_path, fidelity_summary, run_verify
    from ..files.atomic import save_figure

    if args.drive not in ("pressure", "stroke"):
        raise InputError(f"--drive: must be pressure or stroke, got {args.drive!r}")
    if args.blocked and args.drive != "stroke":
        raise InputError("--blocked: only with --drive stroke (the held tip's force at s*)")
    require_felupe()
    if args.drive == "stroke":
        return run_stroke(args)
    start = time.monotonic()
    with progress_bar("verify", unit="design", quiet=args.quiet, delay=0.0) as bar:
        path = run_verify(args.cube, args.designs, workers=args.workers,
                          scheduler=args.scheduler, mesh=args.mesh, seed=args.seed,
                          progress=bar, overwrite=args.overwrite,
                          log=lambda m: bar.write(f"nylonflex verify: {m}"))
    with xr.open_dataset(path, engine="h5netcdf") as fid:
        fid.load()
    chart = fidelity_map_path(args.cube)
    owned = check_outputs(args.cube, args.overwrite)  # nothing was put there meanwhile
    save_figure(fidelity_map(fid), chart, what="verify", inputs=(args.cube,), dpi=130)
    owned.record([chart])
    print(f"fidelity  {path} ({fid.sizes['design']} designs x {fid.sizes['level']} "
          f"pressures, mesh {fid.attrs['fe_mesh']}, {time.monotonic() - start:.0f} s)")
    print(f"map       {chart}")
    for line in fidelity_summary(fid):
        print(f"  {line}")
    return 0

