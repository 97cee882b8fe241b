#!/usr/bin/env bash
# Issue 27's "Done when" figures, each a median of RUNS whole-process runs, CPU seconds
# (user + system, /usr/bin/time) and peak memory, ratios measured side by side in this run.
#
#   benchmarks/issue27.sh                 # this checkout
#   BASE=../base benchmarks/issue27.sh    # ... and the same figures of another checkout
#                                         # (its .venv/bin/nylonflex) beside them
#   RUNS=5 COLD_RUNS=3 BIG=/tmp/big.h5 benchmarks/issue27.sh
#   SKIP_BENCH=1 SKIP_SAMPLED=1 ...       # leave out section 7 (the full nylonflex bench)
#                                         # or 5 (three 3 M-evaluation sampled sweeps each)
#
# Cold runs point NUMBA_CACHE_DIR at a new empty folder each time (every kernel compiles).
# BIG is the 20 M-design cube (made with 'nylonflex sweep configs/big20m.yaml' if missing,
# 0.5 GB). Needs GNU time (/usr/bin/time).
set -euo pipefail
cd "$(dirname "$0")/.."
RUNS=${RUNS:-3}
COLD_RUNS=${COLD_RUNS:-3}
WORK=${WORK:-$(mktemp -d /tmp/issue27.XXXXXX)}
BIG=${BIG:-$WORK/big.h5}
NF=${NF:-$PWD/.venv/bin/nylonflex}
PY=${PY:-$PWD/.venv/bin/python}
export MPLBACKEND=Agg

# cpu_mem CMD...: one whole-process run -> "cpu_seconds peak_MB" (the command's output dropped)
cpu_mem() {
    /usr/bin/time -f "%U %S %M" -o "$WORK/time.txt" "$@" >/dev/null 2>&1 || {
        echo "failed: $*" >&2; return 1; }
    awk '{printf "%.3f %.0f\n", $1 + $2, $3 / 1024}' "$WORK/time.txt"
}
# median N CMD...: the median CPU seconds and peak MB of N runs
median() {
    local n=$1; shift
    for _ in $(seq "$n"); do cpu_mem "$@"; done | sort -n | awk '
        {cpu[NR] = $1; mem[NR] = $2} END {m = int((NR + 1) / 2); printf "%s %s\n", cpu[m], mem[m]}'
}
ratio() { awk -v a="$1" -v b="$2" 'BEGIN {printf "%.2f", a / b}'; }
# "$COLD" CMD...: CMD with a new, empty Numba cache folder (every kernel it uses compiles)
COLD=$WORK/cold.sh
printf '#!/bin/sh\nNUMBA_CACHE_DIR=$(mktemp -d "%s/cache.XXXXXX") exec "$@"\n' "$WORK" > "$COLD"
chmod +x "$COLD"

echo "issue 27 figures: $(git rev-parse --short HEAD) on $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg); RUNS=$RUNS COLD_RUNS=$COLD_RUNS"
[ -f "$BIG" ] || "$NF" sweep configs/big20m.yaml --out "$BIG" --quiet --no-charts >/dev/null

echo "== 1. first use: the README's main job and an off-grid query --at, cold / warm (CPU s)"
"$NF" warmup --quiet
read -r warm _ < <(median "$RUNS" "$NF" sweep configs/fig12.yaml --out "$WORK/fig12/cube.h5" --overwrite)
read -r coldc _ < <(median "$COLD_RUNS" "$COLD" "$NF" sweep configs/fig12.yaml --out "$WORK/fig12c/cube.h5" --overwrite)
echo "sweep configs/fig12.yaml   warm $warm  cold $coldc  cold/warm $(ratio "$coldc" "$warm") (target <= 2.5)"
AT="radius=7.3mm,wall_thickness=2.2mm,length=80mm,coil_index=1.37,wrap_angle=9deg"
read -r warm _ < <(median "$RUNS" "$NF" query "$WORK/fig12/cube.h5" --at "$AT")
read -r coldc _ < <(median "$COLD_RUNS" "$COLD" "$NF" query "$WORK/fig12/cube.h5" --at "$AT")
echo "query --at (off the grid)  warm $warm  cold $coldc  cold/warm $(ratio "$coldc" "$warm") (target <= 3)"
echo "cold compile per kernel (wall s and CPU-s, one empty cache, nylonflex warmup):"
"$COLD" "$NF" warmup 2>/dev/null | sed 's/^/  /'

echo "== 2. info on the 20 M cube (CPU s, peak MB)"
read -r cpu mem < <(median "$RUNS" "$NF" info "$BIG")
echo "info (this)  $cpu s  $mem MB   (targets: <= 40 % of the base's CPU, <= 250 MB)"
if [ -n "${BASE:-}" ]; then
    read -r bcpu bmem < <(median "$RUNS" "$BASE/.venv/bin/nylonflex" info "$BIG")
    echo "info (base)  $bcpu s  $bmem MB   this/base CPU $(ratio "$cpu" "$bcpu"), memory $(ratio "$mem" "$bmem")"
fi

echo "== 3. light commands: heavy modules loaded (each its own process, the console script)"
for argv in "info $BIG" "query $WORK/fig12/cube.h5 --where tip_force_max>0.5 --limit 3" \
            "chart --help" "list materials" "init $WORK/init-dir"; do
    rm -rf "$WORK/init-dir"
    # shellcheck disable=SC2086
    "$PY" -c '
import atexit, sys
heavy = ("numba", "dask", "xarray", "matplotlib", "scipy", "pandas")
atexit.register(lambda: print(f"  {sys.argv[1]:<7} loads: " + (", ".join(
    m for m in heavy if sys.modules.get(m) is not None) or "none of " + "/".join(heavy))))
from nylonflex.cli import run
run()' $argv | grep "loads:"
done
for c in "info $BIG" "query $WORK/fig12/cube.h5 --where tip_force_max>0.5 --limit 3" "list materials"; do
    # shellcheck disable=SC2086
    read -r cpu _ < <(median "$RUNS" "$NF" $c)
    echo "  start-up CPU  ${c%% *}: $cpu s"
done

echo "== 4. pointwise: one design against a batch design (CPU, median of $RUNS processes)"
for _ in $(seq "$RUNS"); do "$PY" - <<'PY'
import time, numpy as np, nylonflex as nf
rng = np.random.default_rng(1); n = 20_000
d = dict(radius=rng.uniform(5e-3, 20e-3, n), wall_thickness=rng.uniform(1e-3, 4e-3, n),
         length=np.full(n, 90e-3), coil_index=rng.uniform(1.1, 1.7, n), wrap_angle=np.full(n, 0.14))
nf.evaluate(**d); one = {k: float(v[0]) for k, v in d.items()}; nf.evaluate(**one)
t0 = time.process_time(); [nf.evaluate(**d) for _ in range(3)]; batch = (time.process_time() - t0) / 3 / n
t0 = time.process_time(); [nf.evaluate(**one) for _ in range(2000)]; single = (time.process_time() - t0) / 2000
print(f"{single / batch:.1f} {single * 1e6:.1f} {batch * 1e6:.2f}")
PY
done | sort -n | awk '{r[NR]=$0} END {split(r[int((NR+1)/2)], x, " ");
    printf "single %s us, batch %s us a design (CPU): single/batch %s (target <= 20)\n", x[2], x[3], x[1]}'

if [ -z "${SKIP_SAMPLED:-}" ]; then
echo "== 5. the sampled path: fig12 x 256 samples (CPU-us per evaluation)"
EVALS=$((41 * 6 * 3 * 4 * 4 * 256))
read -r cpu _ < <(median "$RUNS" "$NF" sweep configs/fig12_uncertain.yaml --out "$WORK/unc/cube.h5" --no-charts --quiet --overwrite)
echo "sampled (this)  $cpu s for $EVALS evaluations: $(awk -v c="$cpu" -v n="$EVALS" 'BEGIN {printf "%.2f", c / n * 1e6}') CPU-us each"
if [ -n "${BASE:-}" ]; then
    read -r bcpu _ < <(median "$RUNS" "$BASE/.venv/bin/nylonflex" sweep configs/fig12_uncertain.yaml --out "$WORK/unc_base/cube.h5" --no-charts --quiet --overwrite)
    echo "sampled (base)  $bcpu s: this/base $(ratio "$cpu" "$bcpu") (target <= 0.5)"
fi
fi

echo "== 6. whole sweeps against the kernel's own CPU on the same grid (CPU s)"
"$PY" -c "import sys, yaml; sys.path.insert(0, '.'); from benchmarks.suite import bench_config, FULL
print(yaml.safe_dump(dict(bench_config(FULL).raw)))" > "$WORK/bench2m.yaml"
for pair in "2 M bench grid:$WORK/bench2m.yaml:2" "20 M cube:configs/big20m.yaml:1.2"; do
    IFS=: read -r label cfg target <<< "$pair"
    read -r sweep _ < <(median "$RUNS" "$NF" sweep "$cfg" --out "$WORK/whole/cube.h5" --no-charts --quiet --overwrite)
    kernel=$(for _ in $(seq "$RUNS"); do "$PY" benchmarks/kernel_cpu.py "$cfg"; done | sort -n | awk '{c[NR] = $1} END {print c[int((NR + 1) / 2)]}')
    echo "$label: whole sweep $sweep, kernel $kernel: $(ratio "$sweep" "$kernel")x (target <= $target)"
done

if [ -z "${SKIP_BENCH:-}" ]; then
    echo "== 7. kernel headroom: nylonflex bench (one process, side by side)"
    "$NF" bench | sed 's/^/  /'
fi
