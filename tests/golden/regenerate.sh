#!/usr/bin/env bash
# Regenerates the golden manifests and frames with the app itself. Run it when a
# change to the engine or the renderer is meant to change pixels, then look at
# the new frames before committing them. Usage: tests/golden/regenerate.sh [build dir]
set -euo pipefail
# Pixels are bit-identical on CPUs with and without AVX, FMA or AVX-512 only when llvmpipe is
# limited to SSE4.1 code; the manifests record this and `sph2d check --adopt-env` adopts it.
export GALLIUM_OVERRIDE_CPU_CAPS=sse4.1
here="$(cd "$(dirname "$0")" && pwd)"
exe="$(cd "${1:-$here/../../build}" && pwd)/app/sph2d"
gen() {  # gen NAME [run flags...]
  # The run replaces the frames and manifest it can prove an earlier run wrote (by the
  # manifest's hashes) and stops, naming it, at a file it cannot (a frame edited by hand).
  local name=$1; shift
  (cd "$here/$name" && "$exe" run scene.json --out . --quiet "$@")
}
gen liquid_dam_break --frames 9 --every 4
gen particles_pressure --frames 7 --every 3 --color-by pressure
gen shapes_overlay --frames 6 --every 5 --overlay
# shapes_overlay also stands for a run made before manifests listed their files (tests/app/
# test_app_output_folder.cpp reruns into a copy of it): its manifest keeps no "files".
python3 - "$here/shapes_overlay/manifest.json" <<'PY'
import collections, json, sys
path = sys.argv[1]
raw = open(path).read()
m = json.loads(raw, object_pairs_hook=collections.OrderedDict)
m.pop("files", None)
open(path, "w").write(json.dumps(m, indent=1, ensure_ascii=False) + ("\n" if raw.endswith("\n") else ""))
PY
