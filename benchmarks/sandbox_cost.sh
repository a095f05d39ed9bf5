#!/bin/sh
# What sand and particle groups cost the sandbox: assets/scenes/sandbox.json (sand poured onto a
# slope into water, a jelly block, a rigid wooden blob, a floating crate) against the same scene
# without them (its water and crate alone: no granular material, no emitter, no groups), both
# through `sph2d run --no-images`, alternating A B B A ... PAIRS times in one run on THREADS
# threads. Prints and writes one CSV row per run (wall seconds for the scene's frames, frames a
# second, the particles at the end) and the median of each; the sandbox's frames a second over
# its 60 is its margin over real time. A benchmark, not a test: only ratios within one run mean
# much on a shared machine.
#
# Usage: benchmarks/sandbox_cost.sh [PAIRS] [THREADS] [OUT.csv]  (defaults 3, 2, stdout only)
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
pairs=${1:-3}
threads=${2:-2}
out=${3:-}
app=$root/build/app/sph2d
build=$(git -C "$root" describe --always --dirty 2>/dev/null || echo unknown)
[ -x "$app" ] || { echo "build the app first (./test.sh or cmake --build build --target sph2d)" >&2; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
python3 - "$root/assets/scenes/sandbox.json" "$tmp/plain.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
s["name"] = "sandbox_plain"
s["materials"] = [m for m in s["materials"] if m["name"] == "water"]
s.pop("groups", None)
s.pop("effects", None)
json.dump(s, open(sys.argv[2], "w"), indent=1)
PY
run() {  # scene label
  "$app" run "$1" --no-images --threads "$threads" > "$tmp/log" 2>&1 || { cat "$tmp/log"; exit 1; }
  line=$(grep -E '^sph2d: [0-9]+ frames' "$tmp/log")
  frames=$(echo "$line" | sed -E 's/^sph2d: ([0-9]+) frames.*/\1/')
  particles=$(echo "$line" | sed -E 's/.* frames, ([0-9]+) particles.*/\1/')
  wall=$(echo "$line" | sed -E 's/.*simulated s, ([0-9.]+) wall s.*/\1/')
  fps=$(python3 -c "print(f'{$frames / $wall:.1f}')")
  echo "$2,$threads,$frames,$particles,$wall,$fps,$build" | tee -a "$tmp/rows"
}
echo "scene,threads,frames,particles_at_end,wall_s,frames_per_s,build"
: > "$tmp/rows"
i=0
while [ $i -lt "$pairs" ]; do
  if [ $((i % 2)) -eq 0 ]; then run "$root/assets/scenes/sandbox.json" sandbox; run "$tmp/plain.json" plain
  else run "$tmp/plain.json" plain; run "$root/assets/scenes/sandbox.json" sandbox; fi
  i=$((i + 1))
done
python3 - "$tmp/rows" <<'PY'
import statistics, sys
rows = [l.strip().split(",") for l in open(sys.argv[1]) if l.strip()]  # scene, ..., frames_per_s, build
med = {k: statistics.median(float(r[5]) for r in rows if r[0] == k) for k in ("sandbox", "plain")}
print(f"# median frames/s: sandbox {med['sandbox']:.1f}, plain {med['plain']:.1f}; "
      f"sandbox/plain time ratio {med['plain'] / med['sandbox']:.2f}; sandbox over real time {med['sandbox'] / 60:.2f}x")
PY
if [ -n "$out" ]; then
  { echo "scene,threads,frames,particles_at_end,wall_s,frames_per_s,build"; cat "$tmp/rows"; } > "$out.tmp" && mv "$out.tmp" "$out"
fi
