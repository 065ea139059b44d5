#!/usr/bin/env bash
# Our cluster DAG (`meshslim dag build`) beside meshoptimizer's clusterlod.h on the same inputs:
# build time, triangles per level, the DAG's size, and at five object-space errors the mean
# two-sided distance (`meshslim compare`) of clusterlod's cut against ours cut to at most as many
# triangles (`dag cut --triangles N`), and of that cut of ours against clusterlod's finest cut with
# at most as many as ours has (the driver's --cut-triangles): the two ways of pairing cuts of the
# same size when a DAG has no cut of exactly that size. Prints a Markdown table per input.
#
#   bash benches/dag_vs_clusterlod.sh INPUT...
#   bash benches/dag_vs_clusterlod.sh .dev/scan-1m.ply .dev/torus-1m.ply
#
# The inputs: `target/release/examples/write_scan_1m .dev/scan-1m.ply` and
# `target/release/examples/write_big_scan 1000000 .dev/torus-1m.ply` make the two dense scans.
# clusterlod is built by benches/clusterlod.sh (which says where meshoptimizer's source comes
# from); MESHSLIM names our binary [target/release/meshslim]; ERRORS the thresholds.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
bin=${MESHSLIM:-$here/../target/release/meshslim}
errors=${ERRORS:-0.0005,0.001,0.002,0.005,0.01}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
[ $# -gt 0 ] || { sed -n '2,13p' "$0"; exit 2; }

# A field of the JSON on stdin (a whole document, or the last line of a log).
field() {
  python3 -c "import json,sys
t=sys.stdin.read().strip()
try: d=json.loads(t)
except ValueError: d=json.loads(t.splitlines()[-1])
print($1)"
}
mean_rel() { "$bin" compare "$1" "$2" --json | field 'd["distance"]["two_sided"]["mean_rel"]'; }

for input in "$@"; do
  name=$(basename "$input")
  clod=$(bash "$here/clusterlod.sh" "$input" -- --cut "$errors" --out-prefix "$work/clod")
  ours=$("$bin" dag build "$input" "$work/ours.mslod" --json)
  echo "### $name"
  echo
  echo "| | clusterlod (1 thread) | meshslim dag (cpu, $(nproc) threads) |"
  echo "|---|---|---|"
  echo "| build s | $(echo "$clod" | field 'round(d["seconds_build"],3)') | $(echo "$ours" | field 'round(d["seconds"]["build"],3)') |"
  echo "| levels | $(echo "$clod" | field 'd["levels"]') | $(echo "$ours" | field 'd["levels"]') |"
  echo "| worst level / previous | $(echo "$clod" | field 'round(max(b/a for a,b in zip(d["triangles_per_level"],d["triangles_per_level"][1:])),3)') | $(echo "$ours" | field 'round(max(b/a for a,b in zip(d["triangles_per_level"],d["triangles_per_level"][1:])),3)') |"
  echo "| last level triangles | $(echo "$clod" | field 'd["triangles_per_level"][-1]') | $(echo "$ours" | field 'd["triangles_per_level"][-1]') |"
  echo "| DAG / input triangles | $(echo "$clod" | field 'round(d["dag_triangles"]/d["input_triangles"],3)') | $(echo "$ours" | field 'round(d["dag_triangles"]/d["triangles_per_level"][0],3)') |"
  echo "| clusters, groups | $(echo "$clod" | field 'str(d["clusters"])+", "+str(d["groups"])') | $(echo "$ours" | field 'str(d["clusters"])+", "+str(d["groups"])') |"
  echo "| stuck groups | | $(echo "$ours" | field 'd["stuck_groups"]') |"
  echo
  ours_counts=()
  for e in ${errors//,/ }; do
    n=$(echo "$clod" | field "[c['triangles'] for c in d['cuts'] if abs(c['error']-$e)<1e-12][0]")
    "$bin" dag cut "$work/ours.mslod" "$work/ours-$e.ply" --triangles "$n" --json > "$work/cut.json"
    ours_counts+=("$(field 'd["triangles"]' < "$work/cut.json")")
  done
  counts=$(IFS=,; echo "${ours_counts[*]}")
  again=$(bash "$here/clusterlod.sh" "$input" -- --cut-triangles "$counts" --out-prefix "$work/clod")
  echo "| error (of the diagonal) | clusterlod triangles | its distance | ours at most as many | our distance | ours / clusterlod | clusterlod at most as many as ours | its distance | ours / it |"
  echo "|---|---|---|---|---|---|---|---|---|"
  i=0
  for e in ${errors//,/ }; do
    n=$(echo "$clod" | field "[c['triangles'] for c in d['cuts'] if abs(c['error']-$e)<1e-12][0]")
    ours_n=${ours_counts[$i]}
    back_n=$(echo "$again" | field "[c['triangles'] for c in d['triangle_cuts'] if c['triangles_max']==$ours_n][0]")
    a=$(mean_rel "$input" "$work/clod-$e.ply")
    b=$(mean_rel "$input" "$work/ours-$e.ply")
    c=$(mean_rel "$input" "$work/clod-t$ours_n.ply")
    echo "| $e | $n | $(printf %.3e "$a") | $ours_n | $(printf %.3e "$b") | $(python3 -c "print(round($b/$a,3))") | $back_n | $(printf %.3e "$c") | $(python3 -c "print(round($b/$c,3))") |"
    i=$((i+1))
  done
  echo
done
