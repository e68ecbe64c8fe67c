#!/usr/bin/env bash
# Whole-run throughput of `swarm run` with and without a live viewer page open in headless Chromium, alternated
# runs of the same configuration; prints one line per run and the medians. Numbers go to BENCHMARKS.md.
#
#   runtime/viewer/benches/live_viewer.sh [config] [ticks] [pairs]
#
# Needs target/release/swarm (cargo build --release --workspace --bins) and Debian's chromium.
set -euo pipefail
cd "$(dirname "$0")/../../.."

config=${1:-configs/obstacle_avoidance/density_N1000.argos}
ticks=${2:-1000}
pairs=${3:-5}
swarm=target/release/swarm
work=$(mktemp -d)
trap 'pkill -P $$ || true; rm -rf "$work"' EXIT

# One run; prints its robot-steps/s. With "view", a headless browser keeps the live page open for the whole run.
run_once() {
    local mode=$1 out="$work/run"
    rm -rf "$out"
    if [ "$mode" = plain ]; then
        "$swarm" run "$config" --ticks "$ticks" --out "$out" --no-progress 2>/dev/null | sed -n 's/.* \([0-9]*\) robot-steps\/s.*/\1/p'
        return
    fi
    local fifo="$work/stdout"
    rm -f "$fifo"; mkfifo "$fifo"
    "$swarm" run "$config" --ticks "$ticks" --out "$out" --no-progress --view 2>/dev/null >"$fifo" &
    local launcher=$! browser=""
    while read -r line; do
        case $line in
        viewer:*)
            chromium --headless=new --no-sandbox --disable-gpu --disable-quic --no-first-run \
                --disable-background-networking --disable-component-update --disable-sync \
                --user-data-dir="$work/profile" --window-size=1280,800 \
                --remote-debugging-port=0 "${line#viewer: }" >/dev/null 2>&1 &
            browser=$!
            ;;
        finished*)
            echo "$line" | sed -n 's/.* \([0-9]*\) robot-steps\/s.*/\1/p'
            ;;
        "the run is over"*)
            kill -INT "$launcher"
            ;;
        esac
    done <"$fifo"
    wait "$launcher" || true
    [ -n "$browser" ] && { kill "$browser" 2>/dev/null || true; wait "$browser" 2>/dev/null || true; }
}

plain=() viewed=()
for pair in $(seq "$pairs"); do
    p=$(run_once plain); v=$(run_once view)
    echo "pair $pair: without viewer $p robot-steps/s, with viewer $v robot-steps/s"
    plain+=("$p"); viewed+=("$v")
done
median() { printf '%s\n' "$@" | sort -n | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'; }
echo "median without viewer: $(median "${plain[@]}") robot-steps/s; with viewer: $(median "${viewed[@]}") robot-steps/s"
