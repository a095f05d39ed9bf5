#!/bin/sh
# What `sph2d serve` delivers to one browser-like client (issue 19: "≥ 30 frames/s and
# ≤ 100 ms from an input event to the first frame that shows it, at 10k particles on
# 2 cores").
#
# Starts `sph2d serve` on the dam break (10,082 particles, 960×540) with each live-frame
# format, waits WARMUP seconds, then runs `sph2d bench serve`: one WebSocket client reads
# frames for SECONDS seconds (frames/s delivered, frame size, gaps) while DROPS drops are
# POSTed to /event (latency from the POST to the first frame whose overlay data shows the
# new particle count). Prints each run's summary and one CSV line per format; the server's
# own summary line (frames encoded and the mean encoding time) follows each run.
# A benchmark, not a test: the machine is shared, so figures vary from run to run.
#
# Usage: benchmarks/serve.sh [SECONDS] [DROPS] [THREADS] [FORMATS] [SCENE]
#        (defaults 20, 10, 2, "jpeg png", assets/scenes/dam_break.json; build/ must be built)
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
seconds=${1:-20}
drops=${2:-10}
threads=${3:-2}
formats=${4:-jpeg png}
scene=${5:-$root/assets/scenes/dam_break.json}
sph2d=$root/build/app/sph2d
# A tree a first ./demo.sh configured has no `serve` (it says how to build it): stop here.
"$sph2d" serve --help > /dev/null 2>&1 || { "$sph2d" serve --help; exit 2; }
tmp=$(mktemp -d)
server=""
cleanup() {
  [ -n "$server" ] && kill "$server" 2>/dev/null
  rm -rf "$tmp"
}
trap cleanup EXIT

echo "format,threads,fps,latency_median_ms,latency_max_ms,frame_kb" > "$tmp/summary.csv"
for format in $formats; do
  "$sph2d" serve "$scene" --port 0 --threads "$threads" --format "$format" --quiet > "$tmp/serve.log" 2>&1 &
  server=$!
  port=""
  for _ in $(seq 1 600); do
    port=$(sed -n 's|.*http://127\.0\.0\.1:\([0-9]*\)/.*|\1|p' "$tmp/serve.log" | head -n 1)
    [ -n "$port" ] && break
    sleep 0.1
  done
  [ -n "$port" ] || { cat "$tmp/serve.log"; exit 1; }
  sleep 3  # the first frames compile the shaders; the dam starts to break
  echo "== $format, --threads $threads"
  "$sph2d" bench serve --port "$port" --seconds "$seconds" --drops "$drops" > "$tmp/bench.log"
  cat "$tmp/bench.log"
  kill -TERM "$server"
  wait "$server" || true
  server=""
  tail -n 1 "$tmp/serve.log"
  echo "$format,$threads,$(tail -n 1 "$tmp/bench.log")" >> "$tmp/summary.csv"
done
echo
cat "$tmp/summary.csv"
