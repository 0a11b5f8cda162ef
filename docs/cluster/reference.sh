#!/usr/bin/env bash
# Submits a Monte Carlo reference as a Slurm array of chunks plus the merge that waits
# for it (docs/cluster.md):
#   docs/cluster/reference.sh SCENE.json DIR TASKS SPP OUT.exr [lvox render flags]
# renders TASKS x SPP samples per pixel into DIR/chunk-*.exr and merges them into OUT.exr.
set -euo pipefail
if [ $# -lt 5 ]; then
  echo "usage: $0 SCENE.json DIR TASKS SPP OUT.exr [lvox render flags]" >&2
  exit 2
fi
here=$(dirname "$0")
scene=$1
dir=$2
tasks=$3
spp=$4
out=$5
shift 5
array=$(sbatch --parsable --array=0-$((tasks - 1)) "$here/reference-chunks.sbatch" \
  "$scene" "$dir" "$spp" "$@")
merge=$(sbatch --parsable --dependency=afterany:"$array" "$here/merge-chunks.sbatch" \
  "$dir" "$tasks" "$spp" "$out")
echo "chunks: job $array (array 0-$((tasks - 1))), merge: job $merge"
