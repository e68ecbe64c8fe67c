#!/usr/bin/env bash
# Whole `swarm run`s with each record choice, alternated: what the records cost a user who times the run.
#
#   runtime/records/benches/whole_runs.sh CONFIG TICKS ROUNDS [CHOICES...]
#
# CHOICES are values of `swarm run --records` (default: parquet csv). Each round runs CONFIG once per choice, in
# that order, into a scratch folder, timed from the start of `swarm run` to its exit; every run prints one line
# with its wall time and the launcher's own figures. Build first: cargo build --release --workspace --bins.
set -euo pipefail
cd "$(dirname "$0")/../../.."

if [ $# -lt 3 ]; then
    sed -n '4,8p' "$0"
    exit 2
fi
config=$1 ticks=$2 rounds=$3
shift 3
if [ $# -eq 0 ]; then choices=(parquet csv); else choices=("$@"); fi
swarm=target/release/swarm
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT

for round in $(seq 1 "$rounds"); do
    for records in "${choices[@]}"; do
        out=$scratch/$records
        rm -rf "$out"
        started=$(date +%s.%N)
        "$swarm" run "$config" --ticks "$ticks" --out "$out" --no-progress --records "$records" \
            > "$scratch/stdout" 2> "$scratch/stderr"
        ended=$(date +%s.%N)
        figures=$(grep -o '[0-9.]* s ([0-9.]* s to the first tick), [0-9]* robot-steps/s' "$scratch/stdout")
        printf '%s %-8s wall %.3f s; %s\n' "$round" "$records" "$(echo "$ended - $started" | bc)" "$figures"
    done
done
