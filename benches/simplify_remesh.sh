#!/usr/bin/env bash
# The simplify-then-remesh pipeline (`simplify --remesh K`) against plain simplification: for
# each model and ratio, faces, seconds (simplify's report, remeshing included), the mean
# two-sided Metro distance relative to the diagonal (`meshslim compare`), the mean smallest
# angle and the share of faces under 30 degrees (`meshslim info`).
#
# Usage (after `cargo build --release`):
#   bash benches/simplify_remesh.sh target/release/meshslim K MODEL...
#   bash benches/simplify_remesh.sh target/release/meshslim 1 ../shared/models/horse.ply
set -euo pipefail
bin=$1
k=$2
shift 2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
py='import json,sys; print(eval(sys.argv[1], {"j": json.load(sys.stdin)}))'
echo "| model | ratio | pipeline | faces | seconds | mean distance | mean min angle | < 30 deg |"
echo "|---|---|---|---|---|---|---|---|"
for model in "$@"; do
  name=$(basename "${model%.*}")
  for ratio in 0.1 0.01; do
    for remesh in 0 "$k"; do
      out="$tmp/$name-$ratio-$remesh.ply"
      secs=$("$bin" simplify "$model" "$out" --ratio "$ratio" --remesh "$remesh" --json |
        python3 -c "$py" 'j["seconds"]["simplify"]')
      dist=$("$bin" compare "$model" "$out" --json |
        python3 -c "$py" '"%.3e" % j["distance"]["two_sided"]["mean_rel"]')
      read -r faces angle under < <("$bin" info "$out" --json |
        python3 -c "$py" '"%d %.2f %.2f" % (j["faces"], j["quality"]["mean_min_angle_deg"], 100 * j["quality"]["share_under_30_deg"])')
      what="qem"
      [ "$remesh" != 0 ] && what="qem + remesh $remesh"
      printf '| %s | %s | %s | %s | %.3f | %s | %s | %s%% |\n' \
        "$name" "$ratio" "$what" "$faces" "$secs" "$dist" "$angle" "$under"
    done
  done
done
