#!/bin/sh
# What five dynamic bodies cost a solver (the game solver unless QUALITY says) at 20k particles (issue 16: "the cost per
# frame with 5 bodies at 20k particles").
#
# Makes two scenes from assets/scenes/dam_break.json with spacing 0.01 (about 20,000
# particles): the dam break as it is, and the same with five dynamic crates standing on the
# tank's floor in the water's way (boxes and a circle, densities 300 to 2500: some float up,
# some stay down, all are hit by the surge). Runs `sph2d run --no-images` of each for
# FRAMES frames at THREADS threads, alternating A B B A ... PAIRS times, and prints each
# run's wall time per frame and, per pair, what the crates added. A benchmark, not a test:
# the machine is shared, so only the interleaved difference means much.
#
# QUALITY picks the solver by solver.quality (game, balanced: wcsph, accurate: dfsph).
#
# Usage: benchmarks/bodies_cost.sh [PAIRS] [FRAMES] [THREADS] [QUALITY]   (defaults 3, 120, 2, game)
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
pairs=${1:-3}
frames=${2:-120}
threads=${3:-2}
quality=${4:-game}
app=$root/build/app/sph2d
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
[ -n "${KEEP:-}" ] && trap - EXIT && echo "scenes in $work"

duration=$(awk -v f="$frames" 'BEGIN { printf "%.6f", f / 60 }')
sed -e 's/"spacing": 0.014/"spacing": 0.01/' -e "s/\"duration\": 4.0/\"duration\": $duration/" \
  -e "s/\"quality\": \"game\"/\"quality\": \"$quality\"/" \
  "$root/assets/scenes/dam_break.json" > "$work/plain.json"
# The crates go in after the static tank (its closing "] }" line, then "],").
awk '
  { print }
  /"center": \[2.0, 3.1\]/ { tank = 1; next }
  tank == 1 && /^    }$/ {
    print "    ,{ \"type\": \"dynamic\", \"position\": [1.6, 0.1], \"fixtures\": [ { \"shape\": \"box\", \"half_size\": [0.15, 0.1], \"density\": 500 } ] },"
    print "    { \"type\": \"dynamic\", \"position\": [2.1, 0.12], \"fixtures\": [ { \"shape\": \"circle\", \"radius\": 0.12, \"density\": 300 } ] },"
    print "    { \"type\": \"dynamic\", \"position\": [2.6, 0.15], \"fixtures\": [ { \"shape\": \"box\", \"half_size\": [0.15, 0.15], \"density\": 800 } ] },"
    print "    { \"type\": \"dynamic\", \"position\": [3.1, 0.1], \"fixtures\": [ { \"shape\": \"box\", \"half_size\": [0.1, 0.1], \"density\": 2500 } ] },"
    print "    { \"type\": \"dynamic\", \"position\": [3.6, 0.08], \"angle\": 0.3, \"fixtures\": [ { \"shape\": \"box\", \"half_size\": [0.2, 0.08], \"density\": 400 } ] }"
    tank = 2
  }
' "$work/plain.json" > "$work/crates.json"
"$app" info "$work/crates.json" > /dev/null  # refuses a scene it cannot read, naming why

run() {  # prints wall ms per frame of scene $1
  start=$(date +%s.%N)
  "$app" run "$1" --no-images --quiet --threads "$threads" > /dev/null
  end=$(date +%s.%N)
  awk -v s="$start" -v e="$end" -v f="$frames" 'BEGIN { printf "%.2f", 1000 * (e - s) / f }'
}

echo "dam break ($quality) at spacing 0.01, $frames frames, $threads threads: wall ms per frame"
echo "pair  plain  crates  added"
i=1
while [ "$i" -le "$pairs" ]; do
  if [ $((i % 2)) -eq 1 ]; then a=$(run "$work/plain.json"); b=$(run "$work/crates.json")
  else b=$(run "$work/crates.json"); a=$(run "$work/plain.json"); fi
  awk -v i="$i" -v a="$a" -v b="$b" 'BEGIN { printf "%4d  %5.2f  %6.2f  %+5.2f ms (%+.1f %%)\n", i, a, b, b - a, 100 * (b - a) / a }'
  i=$((i + 1))
done
