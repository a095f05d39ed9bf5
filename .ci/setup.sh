# Sourced by ./demo.sh and ./test.sh: install what a fresh Debian 12 machine
# lacks (apt-get, sudo when not root) and build the Release tree in build/.
# clang-14 + libclang-rt-14-dev: libFuzzer for the scene-loader fuzz smoke test
# that ./test.sh runs through CTest (docs/STABILITY.md).
# libboost-dev (Boost.Beast, header-only) + libturbojpeg0-dev: `sph2d serve`; chromium: its
# browser test (tests/serve, label browser), which fails when chromium is missing.
# libegl-dev + libopengl-dev + libegl-mesa0: tests/egl, the renderer in a game's EGL context
# (surfaceless Mesa) with gl* from libglvnd; configuring fails without them. libopengl-dev also
# serves tests/glvnd: the renderer's own OSMesa context with libOpenGL first in the link.
# parallel (GNU parallel): the bench tests run `sph2d bench accuracy --list` and `bench game --list`
# through it and compare the merged report with a one-process run (tests/app/test_bench_sweep.cpp).
SPH2D_PACKAGES="g++ cmake make pkg-config libbox2d-dev libosmesa6-dev libpng-dev libeigen3-dev doctest-dev nlohmann-json3-dev clang-14 libclang-rt-14-dev libboost-dev libturbojpeg0-dev chromium libegl-dev libopengl-dev libegl-mesa0 parallel"

sph2d_install() {
  local missing=() p sudo=""
  for p in $SPH2D_PACKAGES; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ "${#missing[@]}" -gt 0 ]; then
    echo "installing: ${missing[*]}"
    [ "$(id -u)" -ne 0 ] && sudo="sudo"
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
  fi
}

sph2d_build() {
  cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build build -j"$(nproc)"
}
