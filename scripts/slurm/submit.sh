#!/usr/bin/env bash
# Submits a smithwalk run to Slurm as a job array of N shards plus a dependent merge job.
#
#   scripts/slurm/submit.sh CONFIG.toml OUT_DIR N [extra sbatch options...]
#
# OUT_DIR/shard-I holds each shard's accumulators, OUT_DIR/merged the run's tables
# (bit-identical to an unsplit `smithwalk run`). SMITHWALK names the binary (default: the
# one on PATH). Prints the merge job's id.
set -euo pipefail
if [ $# -lt 3 ]; then
    echo "usage: $0 CONFIG.toml OUT_DIR N [sbatch options...]" >&2
    exit 2
fi
config=$(realpath "$1")
out=$(realpath -m "$2")
n=$3
shift 3
case "$n" in '' | *[!0-9]* | 0) echo "N must be a positive integer, got '$n'" >&2; exit 2 ;; esac
here=$(dirname "$(realpath "$0")")
smithwalk=${SMITHWALK:-$(command -v smithwalk || true)}
[ -x "$smithwalk" ] || { echo "set SMITHWALK to the smithwalk binary" >&2; exit 2; }
mkdir -p "$out"
export CONFIG="$config" OUT="$out" SMITHWALK="$smithwalk" SHARDS="$n"
array=$(sbatch --parsable --chdir="$out" --array="0-$((n - 1))" "$@" "$here/shard.sbatch")
array=${array%%;*}
sbatch --parsable --chdir="$out" --dependency="afterok:$array" "$@" "$here/merge.sbatch"
