#!/usr/bin/env bash
# Whole-command time and peak memory of `supervisor-gen synth --mode monolithic` on transfer lines (the family
# of `supervisor_gen::families::transfer_line`): N machines, N-1 buffers of capacity K. Each figure is the median
# of R runs of the whole command: reading the models, the products, SupC, minimisation, and writing the
# supervisor's XML and report.json.
#
# With COMPARE set to a command that takes "N K" (another tool's synthesis of the same line), that command runs
# alternately with ours and gets its own columns.
#
# usage: supervisor-gen/benches/transfer_line.sh [-r R] N:K [N:K ...]
#   e.g. supervisor-gen/benches/transfer_line.sh -r 3 6:3 6:5 6:7
set -euo pipefail

repeat=3
if [[ "${1:-}" == "-r" ]]; then
    repeat="$2"
    shift 2
fi
if [[ $# -eq 0 ]]; then
    sed -n '2,12p' "$0" >&2
    exit 2
fi
command -v /usr/bin/time >/dev/null || { echo "error: /usr/bin/time (Debian package time) is needed" >&2; exit 1; }

root="$(cd "$(dirname "$0")/../.." && pwd)"
cargo build --release --quiet --manifest-path "$root/Cargo.toml" -p supervisor-gen \
    --bin supervisor-gen --example transfer_line
bin="$root/target/release"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

# Runs a command under /usr/bin/time and appends "seconds peak_kB" to $1.
timed() {
    local into="$1"
    shift
    /usr/bin/time -f "%e %M" -o "$work/time" "$@" >/dev/null 2>"$work/stderr" || {
        echo "error: $* failed:" >&2
        cat "$work/stderr" >&2
        exit 1
    }
    cat "$work/time" >>"$into"
}

header="| machines | capacity | supervisor states | ours: wall (s) | ours: peak (MB) |"
rule="|---|---|---|---|---|"
if [[ -n "${COMPARE:-}" ]]; then
    header="$header other: wall (s) | other: peak (MB) |"
    rule="$rule---|---|"
fi
echo "$header"
echo "$rule"
for case in "$@"; do
    n="${case%%:*}"
    k="${case##*:}"
    models="$work/models_${n}_$k"
    "$bin/examples/transfer_line" "$n" "$k" "$models"
    plants=("$models"/m*.xml)
    specs=("$models"/b*.xml)
    : >"$work/ours" && : >"$work/other"
    for ((r = 0; r < repeat; r++)); do
        timed "$work/ours" "$bin/supervisor-gen" synth --mode monolithic --plant "${plants[@]}" \
            --spec "${specs[@]}" --out "$work/out"
        if [[ -n "${COMPARE:-}" ]]; then
            # shellcheck disable=SC2086 # COMPARE is a command line.
            timed "$work/other" $COMPARE "$n" "$k"
        fi
    done
    states="$(grep -o '"states": [0-9]*' "$work/out/report.json" | head -1 | grep -o '[0-9]*')"
    wall="$(cut -d' ' -f1 "$work/ours" | median)"
    peak="$(cut -d' ' -f2 "$work/ours" | median)"
    row="| $n | $k | $states | $wall | $((${peak%.*} / 1000)) |"
    if [[ -n "${COMPARE:-}" ]]; then
        other_wall="$(cut -d' ' -f1 "$work/other" | median)"
        other_peak="$(cut -d' ' -f2 "$work/other" | median)"
        row="$row $other_wall | $((${other_peak%.*} / 1000)) |"
    fi
    echo "$row"
    rm -rf "$work/out" "$models"
done
