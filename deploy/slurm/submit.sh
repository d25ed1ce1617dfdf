#!/bin/bash
# Submits a render as N shards (a job array) and the merge that waits for all of them.
#
#   deploy/slurm/submit.sh N SCENE PARTS_DIR OUTPUT [pathlab render flags...]
#
# Prints the two job ids. Example: deploy/slurm/submit.sh 16 scene.pbrt parts out.exr -s 4096
set -euo pipefail
if [ $# -lt 4 ]; then
    echo "usage: $0 N SCENE PARTS_DIR OUTPUT [render flags...]" >&2
    exit 2
fi
n=$1 scene=$2 parts=$3 output=$4
shift 4
here=$(cd "$(dirname "$0")" && pwd)
array=$(sbatch --parsable --array=0-$((n - 1)) "$here/render-array.sbatch" "$scene" "$parts" "$@")
merge=$(sbatch --parsable --dependency=afterok:"$array" "$here/merge.sbatch" "$parts" "$output")
echo "shards: job $array; merge: job $merge"
