#!/usr/bin/env bash
# A bake split over a real scheduler equals the single-machine bake (docs/bake.md "Shards").
#
#   scheduler_test.sh slurm|parallel BIN_DIR BAKE_DIFF DATA_DIR SCRIPTS_DIR WORK_DIR
#
# slurm: starts a private one-node Slurm (scripts/slurm-local: munged, slurmctld, slurmd) and
# runs scripts/slurm-bake for a 4-shard bake of cow.off; the daemons it started are stopped on
# any exit (trap), and by a watchdog should this script be killed. parallel: the same bake
# through scripts/parallel-bake (GNU parallel, here on this machine). Exits 77 (skipped) when
# the scheduler cannot run here (not root, packages missing), saying why.
set -euo pipefail
mode="$1" bin="$2" bake_diff="$3" data="$4" scripts="$5" work="$6"
mesh="$data/meshes/cow.off"
args=(--rate 1 --grid 8x16 --order 3 --cache "")
rm -rf "$work"
mkdir -p "$work"

"$bin/shrefract-bake" "$mesh" -o "$work/single.shrefract.exr" "${args[@]}" -q --checkpoints 1

if [ "$mode" = slurm ]; then
  cluster=$(mktemp -d /tmp/shrefract-slurm.XXXXXX)
  trap '"$scripts/slurm-local" stop "$cluster"; rm -rf "$cluster"' EXIT
  set +e
  env=$("$scripts/slurm-local" start "$cluster" $$)
  status=$?
  set -e
  [ "$status" -eq 0 ] || exit "$status"
  eval "$env"
  SHREFRACT_BIN="$bin" SHREFRACT_SLURM_WAIT=1 \
    "$scripts/slurm-bake" "$mesh" "$work/sharded.shrefract.exr" 4 "${args[@]}"
  # Four array tasks and a merge ran as Slurm jobs.
  logs=$(ls "$work"/sharded.shrefract.exr.shards/slurm-*_*.log | wc -l)
  [ "$logs" -eq 4 ] || { echo "expected 4 array task logs, found $logs"; exit 1; }
else
  command -v parallel >/dev/null || { echo "skip: GNU parallel is not installed"; exit 77; }
  SHREFRACT_BIN="$bin" "$scripts/parallel-bake" "$mesh" "$work/sharded.shrefract.exr" 4 "${args[@]}"
fi

"$bake_diff" "$work/single.shrefract.exr" "$work/sharded.shrefract.exr"
# The shards are gone once merged.
if ls "$work"/sharded.shrefract.exr.shards/shard-* >/dev/null 2>&1; then
  echo "shards left behind after the merge"; exit 1
fi
echo "$mode: 4 shards merged into the single-machine bake"
