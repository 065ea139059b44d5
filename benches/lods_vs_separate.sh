#!/usr/bin/env bash
# `meshslim lods` against five separate `meshslim simplify` runs: wall time, and each level's
# two-sided Metro mean by `meshslim compare` against the separate run's.
# Usage: bash benches/lods_vs_separate.sh MESH [METHOD] [BACKEND]  (meshslim built: cargo build --release)
# The 1M scan: cargo run --release --example write_scan_1m /tmp/scan-1m.ply
set -euo pipefail
mesh=$1; method=${2:-qem}; backend=${3:-cpu}
bin=${MESHSLIM:-target/release/meshslim}
out=$(mktemp -d)
ratios=(0.5 0.25 0.1 0.05 0.01)
stem=$(basename "${mesh%.*}"); ext=${mesh##*.}
t0=$(date +%s.%N)
"$bin" lods "$mesh" "$out/chain" --method "$method" --backend "$backend" --no-measure -q
t1=$(date +%s.%N)
for r in "${ratios[@]}"; do
  "$bin" simplify "$mesh" "$out/sep-$r.$ext" --ratio "$r" --method "$method" --backend "$backend" -q
done
t2=$(date +%s.%N)
echo "lods (5 levels, --no-measure): $(echo "$t1 - $t0" | bc) s; five simplify runs: $(echo "$t2 - $t1" | bc) s"
k=1
for r in "${ratios[@]}"; do
  a=$("$bin" compare "$mesh" "$out/chain/$stem.lod$k.$ext" --json | python3 -c 'import json,sys; print(json.load(sys.stdin)["distance"]["two_sided"]["mean_rel"])')
  b=$("$bin" compare "$mesh" "$out/sep-$r.$ext" --json | python3 -c 'import json,sys; print(json.load(sys.stdin)["distance"]["two_sided"]["mean_rel"])')
  python3 -c "print(f'ratio $r: chain {$a:.4e}  separate {$b:.4e}  chain/separate {$a/$b:.3f}')"
  k=$((k+1))
done
rm -rf "$out"
