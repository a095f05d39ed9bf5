#!/bin/sh
# What the effect machinery costs a scene that uses no effect (issue 7: "a scene
# with only gravity and pressure costs within 3 % of a build with no effect
# modules at all").
#
# Builds the app twice from this source tree (Release, -j2):
#   with     build/overhead-with     the normal engine (SPH2D_NO_EFFECT_MODULES=OFF)
#   without  build/overhead-without  SPH2D_NO_EFFECT_MODULES=ON: no effect modules,
#                                    an empty registry, applyEffects compiled to nothing
# then runs `sph2d bench effects --effects none --clock cpu` (the dam break with
# gravity and pressure only, timed in process CPU time) with each, alternating
# A B B A ... PAIRS times, and prints every run's best round, the ratio
# with/without of each pair, and the median ratio. A benchmark, not a test: the
# machine is shared, so only the interleaved ratio means much. CPU time leaves
# out the time other processes hold the core, and the best of several rounds
# the rounds they slowed most (shared caches, a busy sibling hyperthread).
#
# Usage: benchmarks/effects_overhead.sh [PAIRS] [PARTICLES] [STEPS] [THREADS]
#        (defaults 10, 20000, 30, 1; each run: 50 warm-up substeps, then 10 rounds
#        of STEPS substeps, the best round counts)
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
pairs=${1:-10}
particles=${2:-20000}
steps=${3:-30}
threads=${4:-1}
with=$root/build/overhead-with
without=$root/build/overhead-without

for pair in "$with OFF" "$without ON"; do
  set -- $pair
  cmake -S "$root" -B "$1" -DCMAKE_BUILD_TYPE=Release -DSPH2D_NO_EFFECT_MODULES="$2" \
    -DSPH2D_BUILD_TESTS=OFF -DSPH2D_BUILD_EXAMPLES=OFF -DSPH2D_INSTALL=OFF > "$1.configure.log" 2>&1 ||
    { cat "$1.configure.log"; exit 1; }
  cmake --build "$1" --target sph2d -j2 > "$1.build.log" 2>&1 || { tail -40 "$1.build.log"; exit 1; }
done

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# CPU ms per substep of the "none" configuration (best of 10 rounds), one process run.
run() {
  "$1/app/sph2d" bench effects --scene "$root/assets/scenes/dam_break.json" --effects none --clock cpu \
    --particles "$particles" --threads "$threads" --warmup 50 --steps "$steps" --rounds 10 \
    --csv "$tmp/run.csv" > /dev/null
  awk -F, '$1 == "none" { print $8 }' "$tmp/run.csv"
}

echo "effects overhead: dam break, $particles particles, $threads thread(s), best of 10 rounds of $steps substeps per run (CPU time), $pairs pairs"
echo "pair  with_ms  without_ms  ratio"
: > "$tmp/ratios"
i=1
while [ "$i" -le "$pairs" ]; do
  if [ $((i % 2)) -eq 1 ]; then
    a=$(run "$with"); b=$(run "$without")
  else
    b=$(run "$without"); a=$(run "$with")
  fi
  r=$(awk -v a="$a" -v b="$b" 'BEGIN { printf "%.4f", a / b }')
  echo "$r" >> "$tmp/ratios"
  printf '%4d  %7.3f  %10.3f  %s\n' "$i" "$a" "$b" "$r"
  i=$((i + 1))
done
sort -n "$tmp/ratios" | awk '{ v[NR] = $1 } END {
  m = NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2
  printf "median ratio with/without effect modules: %.4f (min %.4f, max %.4f, %d pairs)\n", m, v[1], v[NR], NR }'
