#!/bin/bash
# A Slurm job array for a sweep of `sph2d bench accuracy` (or `bench game`): task K runs line K
# of a file of commands that `--list` printed, each writing its own CSV into DIR/RUN_ID; a last
# job merges them (docs/ACCURACY.md, "Running a sweep on many cores or machines"). The commands
# hold absolute paths: the build, the assets and DIR must be on a file system every node sees.
#
#   ./build/app/sph2d bench accuracy --list --threads 2 --out "$PWD/out/sweep" > out/sweep.commands
#   job=$(sbatch --parsable --array=1-$(wc -l < out/sweep.commands) benchmarks/sweep_slurm.sh out/sweep.commands)
#   sbatch --dependency=afterany:$job --wrap "./build/app/sph2d bench accuracy --merge out/sweep --out out/sweep"
#
# --threads in the listed commands should match --cpus-per-task below. `%N` after the array
# range (--array=1-120%16) caps how many tasks run at once. The longest run of the full sweep
# (wcsph, 80k particles) takes about 5 minutes on one 2-core machine.
#SBATCH --job-name=sph2d-sweep
#SBATCH --cpus-per-task=2
#SBATCH --time=00:30:00
#SBATCH --output=slurm-%A_%a.out
set -euo pipefail
commands=${1:?usage: sbatch --array=1-N benchmarks/sweep_slurm.sh COMMANDS_FILE}
line=$(sed -n "${SLURM_ARRAY_TASK_ID:?not a Slurm array task}p" "$commands")
if [ -z "$line" ]; then
  echo "no line ${SLURM_ARRAY_TASK_ID} in $commands (it has $(wc -l < "$commands"))" >&2
  exit 2
fi
echo "$line"
exec bash -c "$line"
