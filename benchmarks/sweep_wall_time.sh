#!/bin/sh
# The `sph2d bench accuracy` sweep on this machine two ways: in one process (--threads N, all
# cores) and split into its runs (--list, --threads 1 each) run by GNU parallel -jN, then
# merged (--merge). Prints both wall times (the second includes listing and merging) and
# whether the two reports agree in every column but the wall times and the settings (the
# thread count differs), and appends both to benchmarks/results/sweep_wall_time.csv with the
# machine (nproc, CPU model, load average before each) and the commands; the two accuracy.csv
# files go to benchmarks/results/sweep_wall_time/KIND_one_process.csv and
# KIND_parallel_merged.csv (KIND: quick, or full for the default sweep, levelsK, ...).
# Exits 1 when the reports differ. A benchmark, not a test: a shared machine's load moves both
# wall times; compare them as a ratio measured in one run.
#
# Usage: benchmarks/sweep_wall_time.sh [WORK_DIR] [bench accuracy flags, e.g. --quick or --levels 2]
#        WORK_DIR: default a fresh temporary folder. JOBS=N: the parallel jobs and the one
#        process's threads (default nproc). SPH2D=PATH: the executable (default build/app/sph2d).
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
app=${SPH2D:-$root/build/app/sph2d}
work=${1:-$(mktemp -d)}
[ $# -gt 0 ] && shift
n=${JOBS:-$(nproc)}
command -v parallel >/dev/null || { echo "GNU parallel is missing (Debian: apt-get install parallel)" >&2; exit 2; }
[ -x "$app" ] || { echo "$app: not built (cmake --build build --target sph2d)" >&2; exit 2; }
[ ! -e "$work/one" ] && [ ! -e "$work/runs" ] && [ ! -e "$work/merged" ] ||
  { echo "$work already holds one/, runs/ or merged/: give a fresh WORK_DIR" >&2; exit 2; }
mkdir -p "$work"
kind=full
for a in "$@"; do
  case $a in
    --quick) kind=quick ;;
    --levels) kind=levels ;;
    [0-9]*) [ "$kind" = levels ] && kind=levels$a ;;
  esac
done
results=$root/benchmarks/results
mkdir -p "$results/sweep_wall_time"
cpu=$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -1)
now() { date +%s.%N; }
secs() { awk "BEGIN { printf \"%.1f\", $2 - $1 }"; }

one="$app bench accuracy --threads $n --assets $root/assets --out $work/one $*"
load1=$(cut -d' ' -f1 /proc/loadavg)
t0=$(now)
$one > "$work/one.log" 2>&1
wall_one=$(secs "$t0" "$(now)")

list="$app bench accuracy --list --threads 1 --assets $root/assets --out $work/runs $*"
merge="$app bench accuracy --merge $work/runs --out $work/merged"
load2=$(cut -d' ' -f1 /proc/loadavg)
t0=$(now)
$list > "$work/commands.txt"
parallel -j"$n" --halt now,fail=1 --joblog "$work/joblog.txt" < "$work/commands.txt" > "$work/parallel.log" 2>&1
$merge > "$work/merge.log" 2>&1
wall_par=$(secs "$t0" "$(now)")

# Every column but wall_s_per_sim_s (13), ms_per_step (14) and settings (17): the header names them.
head -1 "$work/one/accuracy.csv" | cut -d, -f13,14,17 | grep -qx 'wall_s_per_sim_s,ms_per_step,settings' ||
  { echo "accuracy.csv's columns moved: update the cut in $0" >&2; exit 2; }
cut -d, -f1-12,15,16,18 "$work/one/accuracy.csv" > "$work/one.cut"
cut -d, -f1-12,15,16,18 "$work/merged/accuracy.csv" > "$work/merged.cut"
if cmp -s "$work/one.cut" "$work/merged.cut"; then same=yes; else same=no; fi
runs=$(wc -l < "$work/commands.txt")
rows_one=$(($(wc -l < "$work/one/accuracy.csv") - 1))
rows_par=$(($(wc -l < "$work/merged/accuracy.csv") - 1))
build=$(sed -n 2p "$work/one/accuracy.csv" | cut -d, -f16)
cp "$work/one/accuracy.csv" "$results/sweep_wall_time/${kind}_one_process.csv"
cp "$work/merged/accuracy.csv" "$results/sweep_wall_time/${kind}_parallel_merged.csv"

# The commands as recorded: paths relative to the repository, the work folder as WORK.
shown() { echo "$1" | sed "s|$work|WORK|g; s|$root/||g"; }
csv=$results/sweep_wall_time.csv
[ -f "$csv" ] || echo "build,nproc,cpu_model,load1_before,kind,mode,runs,rows,wall_s,accuracy_columns_identical,command" > "$csv"
echo "$build,$(nproc),\"$cpu\",$load1,$kind,one process --threads $n,$runs,$rows_one,$wall_one,$same,\"$(shown "$one")\"" >> "$csv"
echo "$build,$(nproc),\"$cpu\",$load2,$kind,parallel -j$n (--threads 1 each),$runs,$rows_par,$wall_par,$same,\"$(shown "$list | parallel -j$n; $merge")\"" >> "$csv"
echo "$kind sweep, $runs runs: one process (--threads $n) $wall_one s; --list | parallel -j$n + --merge $wall_par s; accuracy columns identical: $same"
echo "appended to $csv; the two accuracy.csv in $results/sweep_wall_time/"
[ "$same" = yes ] || { diff "$work/one.cut" "$work/merged.cut" | head -20; exit 1; }
