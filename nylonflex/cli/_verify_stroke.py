"""``nylonflex verify CUBE --drive stroke [--blocked]``: the models at full stroke against
the sealed, stroke-driven FE twin (:mod:`nylonflex.fe.verify_stroke`)."""

from __future__ import annotations

import time

from ._common import progress_bar


def run_stroke(args) -> int:
    import xarray as xr

    from ..charts.fidelity import fidelity_map
    from ..fe.verify_stroke import (check_stroke_outputs, run_verify_stroke, stroke_map_path,
                                    stroke_summary)
    from ..files.atomic import save_figure

    start = time.monotonic()
    with progress_bar("verify", unit="design", quiet=args.quiet, delay=0.0) as bar:
        path = run_verify_stroke(args.cube, args.designs, blocked=args.blocked,
                                 workers=args.workers, scheduler=args.scheduler,
                                 mesh=args.mesh, seed=args.seed, progress=bar,
                                 overwrite=args.overwrite,
                                 log=lambda m: bar.write(f"nylonflex verify: {m}"))
    with xr.open_dataset(path, engine="h5netcdf") as fid:
        fid.load()
    chart = stroke_map_path(args.cube)
    owned = check_stroke_outputs(args.cube, args.overwrite)  # nothing put there meanwhile
    save_figure(fidelity_map(fid), chart, what="verify", inputs=(args.cube,), dpi=130)
    owned.record([chart])
    print(f"fidelity  {path} ({fid.sizes['design']} designs at full stroke, drive stroke"
          f"{', blocked' if args.blocked else ''}, mesh {fid.attrs['fe_mesh']}, "
          f"{time.monotonic() - start:.0f} s)")
    print(f"map       {chart}")
    for line in stroke_summary(fid):
        print(f"  {line}")
    return 0
