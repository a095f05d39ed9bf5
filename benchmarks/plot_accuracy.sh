#!/bin/sh
# Redraws the charts of `sph2d bench accuracy` from an accuracy.csv that is already there: a
# sweep's, or a merged one (`bench accuracy --merge`). Writes per case CASE.gp and CASE.dat and,
# through gnuplot, CASE.svg and CASE.png (docs/ACCURACY.md, "Charts"), beside the CSV or into OUT.
#
# Usage: benchmarks/plot_accuracy.sh DIR_OR_CSV [OUT]
#        DIR_OR_CSV: a folder holding accuracy.csv, or the CSV itself. SPH2D=PATH: the
#        executable (default build/app/sph2d). Needs gnuplot (Debian: apt-get install gnuplot-nox).
set -eu
[ $# -ge 1 ] && [ $# -le 2 ] || { echo "usage: $0 DIR_OR_CSV [OUT]" >&2; exit 2; }
root=$(cd "$(dirname "$0")/.." && pwd)
app=${SPH2D:-$root/build/app/sph2d}
[ -x "$app" ] || { echo "$app: not built (cmake --build build --target sph2d)" >&2; exit 2; }
command -v gnuplot >/dev/null || { echo "gnuplot is missing (Debian: apt-get install gnuplot-nox)" >&2; exit 2; }
csv=$1
[ -d "$csv" ] && csv=$csv/accuracy.csv
[ -f "$csv" ] || { echo "$csv: no such file" >&2; exit 2; }
out=${2:-$(dirname "$csv")}
exec "$app" bench accuracy --charts-only "$csv" --out "$out"
