#!/usr/bin/env bash
# Fuzzes every target for SECONDS (default 600) each, one after another, and prints each
# target's time, executions and crashes. Needs a nightly toolchain and cargo-fuzz
# (`cargo install cargo-fuzz`); the seeds need a built `meshslim` (`cargo build --release`
# at the project root) and use ../shared/models when present.
#   bash run.sh [SECONDS] [TARGET...]
set -euo pipefail
cd "$(dirname "$0")"
seconds=${1:-600}
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(read_obj read_ply read_stl read_gltf read_mslod simplify)
models=${MESHSLIM_MODELS:-../../shared/models}
binary=../target/release/meshslim
[ -x "$binary" ] || (cd .. && cargo build --release)
[ -d corpus ] || python3 seeds.py "$binary" "$models" corpus
cargo +nightly fuzz build
mkdir -p logs
for t in "${targets[@]}"; do
    # 128 KiB inputs at most (seeds.py keeps its seeds under it); 2 GB of RSS, 10 s per input:
    # past either, libFuzzer reports the input as a crash, which is what a reader must never do.
    cargo +nightly fuzz run "$t" corpus/"$t" -- -max_total_time="$seconds" \
        -max_len=131072 -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 \
        >"logs/$t.log" 2>&1 || echo "$t: libFuzzer exited with $? (see logs/$t.log, artifacts/$t)"
    runs=$(grep -oE 'stat::number_of_executed_units: *[0-9]+' "logs/$t.log" | grep -oE '[0-9]+$' || echo "?")
    time=$(grep -oE 'Done [0-9]+ runs in [0-9]+ second' "logs/$t.log" | grep -oE '[0-9]+ second' || echo "?")
    crashes=$(ls artifacts/"$t" 2>/dev/null | wc -l)
    echo "$t: $runs executions in ${time:-?}s, $crashes crash artifacts"
done
