#!/bin/sh
# Does the default scene play in real time, with room to spare? Three measurements per round:
#
#   demo      `sph2d run SCENE --out DIR` as ./demo.sh runs it (no --realtime, images written),
#             no busy loop: the wall seconds for the frames;
#   realtime  `sph2d run SCENE --realtime --out DIR`, with a busy loop holding the last core
#             (taskset) for the whole run, as another program on a player's machine would: the
#             frames dropped (stepped but not rendered, to keep up) and late (the simulation fell
#             behind the wall clock), with the wall, simulation and rendering seconds;
#   serve     `sph2d serve SCENE` with the same busy loop and one WebSocket client
#             (`sph2d bench serve`, SERVE_SECONDS of frames, a few drops for the latency): the
#             frames per second it delivers.
#
# With BUSY=0 the realtime and serve rows run without the busy loop (the demo row never has it).
# With OTHER=path/to/sph2d every measurement alternates that binary with this build's (A B,
# B A, ...), so that two builds meet the same load (paths without spaces). Prints each
# measurement as it goes, then the rounds as CSV; with CSV=FILE it also writes them to FILE
# (whole, or not at all; never over a file that exists).
# A benchmark, not a test: the machine is shared, and a busy machine drops frames that a quiet
# one does not (the load average before each measurement says which it was).
#
# Usage: [BUSY=0] [OTHER=...] [SERVE_SECONDS=10] [CSV=FILE] benchmarks/realtime.sh [ROUNDS] [SCENE]
#        (defaults 3 rounds, assets/scenes/dam_break.json; build/ must be built with the serve
#        command for the serve rows: ./test.sh builds it)
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
rounds=${1:-3}
scene=${2:-$root/assets/scenes/dam_break.json}
app=$root/build/app/sph2d
busy=${BUSY:-1}
serve_seconds=${SERVE_SECONDS:-10}
csv_file=${CSV:-}
if [ -n "$csv_file" ] && [ -e "$csv_file" ]; then
  echo "realtime.sh: $csv_file exists; name a new file" >&2
  exit 2
fi
work=$(mktemp -d)
busy_pid=""
server=""
stop_busy() {
  if [ -n "$busy_pid" ]; then
    kill "$busy_pid" 2>/dev/null || true
    wait "$busy_pid" 2>/dev/null || true
    busy_pid=""
  fi
}
start_busy() {
  [ "$busy" = 1 ] || return 0
  last=$(($(nproc) - 1))
  taskset -c "$last" sh -c 'while :; do :; done' &
  busy_pid=$!
}
cleanup() {
  # Each step may fail (a server that already exited): under set -e a failing step would end
  # the cleanup there and leave the busy loop running.
  if [ -n "$server" ]; then kill "$server" 2>/dev/null || true; fi
  stop_busy
  rm -rf "$work"
}
trap cleanup EXIT
trap 'exit 130' INT TERM
serve_ok=1
for bin in "$app" ${OTHER:-}; do
  if ! "$bin" serve --help > /dev/null 2>&1; then
    serve_ok=0
    echo "realtime.sh: $bin has no serve command (configure with -DSPH2D_APP_SERVE=ON): no serve rows" >&2
  fi
done

csv="measure,binary,busy,round,load1,dropped,late,wall_s,simulation_s,rendering_s,fps"

# run_once BINARY MEASURE [FLAGS...]: one `sph2d run` of the scene into a fresh folder.
run_once() {
  bin=$1
  measure=$2
  shift 2
  load=$(cut -d' ' -f1 /proc/loadavg)
  rm -rf "$work/out"
  "$bin" run "$scene" --quiet --out "$work/out" "$@" > "$work/log" 2>&1 || { cat "$work/log"; exit 1; }
  dropped=$(sed -n 's/.*realtime at [0-9.]* fps: \([0-9]*\) frames dropped.*/\1/p' "$work/log")
  late=$(sed -n 's/.* \([0-9]*\) frames late .*/\1/p' "$work/log")
  times=$(sed -n 's/.* \([0-9.]*\) wall s (simulation \([0-9.]*\) s, rendering \([0-9.]*\) s).*/\1,\2,\3/p' "$work/log")
  b=0
  [ -n "$busy_pid" ] && b=1
  echo "$measure $bin round $i: load $load, dropped ${dropped:--}, late ${late:--}, wall/simulation/rendering ${times:-?} s"
  csv="$csv
$measure,$bin,$b,$i,$load,$dropped,$late,$times,"
}

# serve_once BINARY: `sph2d serve` with one client for serve_seconds.
serve_once() {
  bin=$1
  load=$(cut -d' ' -f1 /proc/loadavg)
  "$bin" serve "$scene" --port 0 --quiet > "$work/serve.log" 2>&1 &
  server=$!
  port=""
  for _ in $(seq 1 600); do
    port=$(sed -n 's|.*http://127\.0\.0\.1:\([0-9]*\)/.*|\1|p' "$work/serve.log" | head -n 1)
    [ -n "$port" ] && break
    kill -0 "$server" 2>/dev/null || break # it exited without serving
    sleep 0.1
  done
  [ -n "$port" ] || { cat "$work/serve.log"; exit 1; }
  sleep 3 # the first frames compile the shaders; the dam starts to break
  "$bin" bench serve --port "$port" --seconds "$serve_seconds" --drops 5 > "$work/bench.log"
  kill -TERM "$server"
  wait "$server" || true
  server=""
  fps=$(tail -n 1 "$work/bench.log" | cut -d, -f1)
  b=0
  [ -n "$busy_pid" ] && b=1
  echo "serve $bin round $i: load $load, $fps frames/s to one client"
  csv="$csv
serve,$bin,$b,$i,$load,,,,,,$fps"
}

i=0
while [ "$i" -lt "$rounds" ]; do
  i=$((i + 1))
  # With OTHER, the order alternates (A B, B A, ...) so that a load trend within a round favours neither.
  order="$app ${OTHER:-}"
  [ -n "${OTHER:-}" ] && [ $((i % 2)) -eq 0 ] && order="$OTHER $app"
  for bin in $order; do run_once "$bin" demo; done
  start_busy
  for bin in $order; do run_once "$bin" realtime --realtime; done
  if [ "$serve_ok" = 1 ]; then
    for bin in $order; do serve_once "$bin"; done
  fi
  stop_busy
done
echo "$csv"
if [ -n "$csv_file" ]; then
  # Written beside the target and renamed (whole or absent); -n: a file made meanwhile stays.
  part="$csv_file.part.$$"
  printf '%s\n' "$csv" > "$part"
  mv -n "$part" "$csv_file"
  if [ -e "$part" ]; then
    rm -f "$part"
    echo "realtime.sh: $csv_file appeared during the run; left as it was" >&2
    exit 2
  fi
fi
