#!/usr/bin/env bash
# A large reference as a Slurm job array: one array task per range of sample indices
# (`strata render --samples A..B`), then one merge job that starts when every task succeeded
# (`--dependency=afterok`). The merged OUT.exr is bit-identical to a one-machine
# `strata render SCENE --spp SPP` with the same flags, and its metadata records the total spp,
# the total CPU seconds and the parts.
#
#   SCENE=$PWD/scene.test SPP=65536 SHARDS=64 CPUS=32 OUT=$PWD/ref examples/cluster/slurm-submit.sh
#
# Tasks are requeued on preemption or node failure and resume from their checkpoint: Slurm's
# SIGTERM makes strata finish the current pass, write its checkpoint and exit; a SIGKILL loses
# at most CHECKPOINT_EVERY seconds (default 600). Use absolute paths (tasks run on other nodes).
# Every variable here (and CHECKPOINT_EVERY, QUIET of slurm-part.sbatch) reaches the jobs through
# --export=ALL. If a task fails, the merge job is cancelled (--kill-on-invalid-dep) rather than
# left pending. scripts/test-slurm.sh runs this on a one-node Slurm and requeues a task.
set -euo pipefail
: "${SCENE:?set SCENE to a .test file (absolute path)}"
export SCENE SPP=${SPP:-65536} SHARDS=${SHARDS:-64} OUT=${OUT:-$PWD/ref} FLAGS=${FLAGS:-}
export STRATA=${STRATA:-strata} PARTS=${PARTS:-$OUT.parts}
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$PARTS"
array=$(sbatch --parsable --export=ALL --array=0-$(( SHARDS - 1 )) --cpus-per-task="${CPUS:-32}" \
    --output="$PARTS/slurm-%A_%a.log" "$here/slurm-part.sbatch")
array=${array%%;*}  # --parsable prints JOBID;CLUSTER on a multi-cluster setup
merge=$(sbatch --parsable --export=ALL --dependency=afterok:"$array" --kill-on-invalid-dep=yes \
    --output="$PARTS/slurm-merge-%j.log" "$here/slurm-merge.sbatch")
merge=${merge%%;*}
echo "submitted array $array ($SHARDS parts) and merge $merge -> $OUT.exr"
