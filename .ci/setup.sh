# Sourced by ./demo.sh and ./test.sh: install what a fresh Debian 12 machine
# lacks (apt-get, sudo when not root) and build the Release tree in build/: the demo
# installs and builds only what it runs, the tests the rest.
# clang-14 + libclang-rt-14-dev: libFuzzer for the scene-loader fuzz smoke test
# that ./test.sh runs through CTest (docs/STABILITY.md).
# libboost-dev (Boost.Beast, header-only) + libturbojpeg0-dev: `sph2d serve`; chromium: its
# browser test (tests/serve, label browser), which fails when chromium is missing.
# libegl-dev + libopengl-dev + libegl-mesa0: tests/egl, the renderer in a game's EGL context
# (surfaceless Mesa) with gl* from libglvnd; configuring fails without them. libopengl-dev also
# serves tests/glvnd: the renderer's own OSMesa context with libOpenGL first in the link.
# parallel (GNU parallel): the bench tests run `sph2d bench accuracy --list` and `bench game --list`
# through it and compare the merged report with a one-process run (tests/app/test_bench_sweep.cpp).
# gnuplot-nox: `sph2d bench accuracy` draws its charts with it; tests/app/test_bench_accuracy_charts.cpp
# checks the SVG and PNG it draws (the bench itself runs without it: it writes the scripts).
# What the demo needs (the engine, the renderer and the `sph2d` app's run commands; serve and
# bench come with the tests):
SPH2D_DEMO_PACKAGES="g++ cmake make pkg-config libbox2d-dev libosmesa6-dev libpng-dev libdeflate-dev libeigen3-dev nlohmann-json3-dev"
# What the tests add (libboost-dev and libturbojpeg0-dev for `sph2d serve`):
SPH2D_TEST_PACKAGES="libboost-dev libturbojpeg0-dev doctest-dev clang-14 libclang-rt-14-dev chromium libegl-dev libopengl-dev libegl-mesa0 parallel gnuplot-nox"
SPH2D_PACKAGES="$SPH2D_DEMO_PACKAGES $SPH2D_TEST_PACKAGES"

# sph2d_install [PACKAGES]: installs those of PACKAGES (default: all) that are missing.
sph2d_install() {
  local missing=() p sudo="" want="${1:-$SPH2D_PACKAGES}"
  for p in $want; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ "${#missing[@]}" -gt 0 ]; then
    echo "installing: ${missing[*]}"
    [ "$(id -u)" -ne 0 ] && sudo="sudo"
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
  fi
}

# Everything: the engine, renderer, app, examples and every test.
sph2d_build() {
  cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DSPH2D_BUILD_TESTS=ON -DSPH2D_BUILD_EXAMPLES=ON \
    -DSPH2D_APP_SERVE=ON -DSPH2D_APP_BENCH=ON >/dev/null
  cmake --build build -j"$(nproc)"
}

# The demo's executable alone (target sph2d). The same build tree as sph2d_build: a later
# ./test.sh builds the rest and reuses what this built. A first configure leaves the tests, the
# examples, `serve` and `bench` out (their packages may be missing); a tree ./test.sh configured
# keeps them.
sph2d_build_demo() {
  local first=()
  [ -f build/CMakeCache.txt ] ||
    first=(-DSPH2D_BUILD_TESTS=OFF -DSPH2D_BUILD_EXAMPLES=OFF -DSPH2D_APP_SERVE=OFF -DSPH2D_APP_BENCH=OFF)
  cmake -S . -B build -DCMAKE_BUILD_TYPE=Release "${first[@]}" >/dev/null
  cmake --build build -j"$(nproc)" --target sph2d
}
