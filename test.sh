#!/usr/bin/env bash
# Installs what is missing, builds (Release), and runs every test through CTest.
set -euo pipefail
cd "$(dirname "$0")"
source .ci/setup.sh
sph2d_install
sph2d_build
ctest --test-dir build --output-on-failure -j"$(nproc)" "$@"
