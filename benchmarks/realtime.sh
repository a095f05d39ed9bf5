#!/bin/sh
# Does the default scene play in real time? (issue 15: "`sph2d run assets/scenes/dam_break.json
# --realtime` reports no dropped frame").
#
# Runs `sph2d run SCENE --realtime` ROUNDS times (images written, as a user runs it) and prints,
# per round, the load average before it, the frames dropped (stepped but not rendered, to keep
# up) and late (the simulation fell behind the wall clock), the wall, simulation and rendering
# seconds, and which frames were dropped; then the rounds as CSV. With OTHER=path/to/sph2d it
# alternates that binary with this build's (A B, B A, ...), so that two builds meet the same load
# (paths without spaces).
# A benchmark, not a test: the machine is shared, and a busy machine drops frames that a quiet
# one does not (the load average says which it was).
#
# With BUSY=1 a busy loop holds the last core (taskset) for every round, as another program on a
# player's machine would; the CSV's `busy` column says which.
#
# Usage: [BUSY=1] [OTHER=...] benchmarks/realtime.sh [ROUNDS] [SCENE]   (defaults 3, assets/scenes/dam_break.json)
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
rounds=${1:-3}
scene=${2:-$root/assets/scenes/dam_break.json}
app=$root/build/app/sph2d
work=$(mktemp -d)
busy_pid=""
trap 'rm -rf "$work"; [ -n "$busy_pid" ] && kill "$busy_pid" 2>/dev/null' EXIT INT TERM
busy=${BUSY:-0}
if [ "$busy" = 1 ]; then
  last=$(($(nproc) - 1))
  taskset -c "$last" sh -c 'while :; do :; done' &
  busy_pid=$!
fi

csv="binary,busy,round,load1,dropped,late,wall_s,simulation_s,rendering_s"
i=0
while [ "$i" -lt "$rounds" ]; do
  i=$((i + 1))
  # With OTHER, the order alternates (A B, B A, ...) so that a load trend within a round favours neither.
  order="$app ${OTHER:-}"
  [ -n "${OTHER:-}" ] && [ $((i % 2)) -eq 0 ] && order="$OTHER $app"
  for bin in $order; do
    load=$(cut -d' ' -f1 /proc/loadavg)
    rm -rf "$work/out"
    "$bin" run "$scene" --realtime --quiet --out "$work/out" > "$work/log" 2>&1 || { cat "$work/log"; exit 1; }
    dropped=$(sed -n 's/.*realtime at [0-9.]* fps: \([0-9]*\) frames dropped.*/\1/p' "$work/log")
    late=$(sed -n 's/.* \([0-9]*\) frames late .*/\1/p' "$work/log")
    times=$(sed -n 's/.* \([0-9.]*\) wall s (simulation \([0-9.]*\) s, rendering \([0-9.]*\) s).*/\1,\2,\3/p' "$work/log")
    # Kept frames that have no PNG were dropped.
    which=$(ls "$work/out" | sed -n 's/^frame_0*\([0-9][0-9]*\)\.png$/\1/p' | sort -n |
      awk 'NR == 1 && $1 > 0 { for (k = 0; k < $1; ++k) printf "%d ", k }
           NR > 1 { for (k = prev + 1; k < $1; ++k) printf "%d ", k } { prev = $1 }')
    echo "$bin round $i: load $load, dropped ${dropped:-?}, late ${late:-?}, wall/simulation/rendering ${times:-?} s${which:+; dropped frames: $which}"
    csv="$csv
$bin,$busy,$i,$load,$dropped,$late,$times"
  done
done
echo "$csv"
