#!/usr/bin/env bash
# Installs what the demo needs, builds the `sph2d` app alone (Release), and renders the default scene
# (the dam break) to out/dam_break/frame_NNNNN.png. Extra arguments go to
# `sph2d run` (e.g. ./demo.sh --frames 60 --threads 2).
set -euo pipefail
cd "$(dirname "$0")"
source .ci/setup.sh
sph2d_install "$SPH2D_DEMO_PACKAGES"
sph2d_build_demo
scene="assets/scenes/dam_break.json"
out="out/dam_break"
# No rm -rf: sph2d replaces only the frames an earlier run of it wrote there (their hashes are in
# its manifest) and refuses, with exit 2 and the file's name, a folder holding anything else of
# those names.
start=$(date +%s%N)
./build/app/sph2d run "$scene" --out "$out" "$@"
ms=$(( ($(date +%s%N) - start) / 1000000 ))
count=$(find "$out" -maxdepth 1 -name 'frame_*.png' | wc -l)
printf 'demo: %d frames in %s/ (frame_00000.png ...), %d.%03d s wall for simulation, rendering and PNG (build excluded)\n' \
  "$count" "$out" $((ms / 1000)) $((ms % 1000))
