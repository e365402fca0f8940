#!/usr/bin/env bash
# The cluster examples' study on one machine: every shard as its own process, all at
# once, then the merge. `bash examples/cluster/local.sh [SHARDS] [RUNS]` from the
# repository's root; host/tests/cluster_shards.rs runs the same steps and checks the
# merged numbers against one process.
set -euo pipefail
SHARDS=${1:-4}
RUNS=${2:-2000}
MODEL=${MODEL:-examples/museum-guide}
SEED=${SEED:-1}
HINDSIGHT=${HINDSIGHT:-target/release/hindsight}
PARTS=${PARTS:-$(mktemp -d)}
pids=()
for ((i = 0; i < SHARDS; i++)); do
    "$HINDSIGHT" verify "$MODEL" --seed "$SEED" --runs "$RUNS" --shard "$i/$SHARDS" \
        --threads 1 --partial "$PARTS/part-$i.json" 2>"$PARTS/shard-$i.log" &
    pids+=($!)
done
for p in "${pids[@]}"; do wait "$p"; done
"$HINDSIGHT" merge "$PARTS"/part-*.json
echo "parts in $PARTS"
