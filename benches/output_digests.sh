#!/usr/bin/env bash
# Prints a SHA-256 of every simplification `cpu` and `cpu-parallel` write, for every shared model
# and built-in mesh at 50%, 10% and 1%: a restructuring must leave this list unchanged.
#   bash benches/output_digests.sh [BINARY] > digests.txt   (BINARY: target/release/meshslim)
# Compare two lists with `diff`. Uses ../shared/models when present (MESHSLIM_MODELS overrides).
set -euo pipefail
bin=${1:-target/release/meshslim}
models=${MESHSLIM_MODELS:-../shared/models}
inputs=()
[ -d "$models" ] && while IFS= read -r f; do inputs+=("$f"); done \
    < <(find "$models" -name '*.obj' -o -name '*.ply' | sort)
inputs+=(builtin:sphere builtin:uv-sphere builtin:torus builtin:double-torus builtin:cube
         builtin:grid builtin:noisy-sphere builtin:bumpy-sphere)
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for m in "${inputs[@]}"; do
    for b in cpu cpu-parallel; do
        for r in 0.5 0.1 0.01; do
            "$bin" simplify "$m" "$out/o.ply" --ratio "$r" --backend "$b" --quiet
            echo "$(sha256sum <"$out/o.ply" | cut -c1-16) $b $r ${m#"$models"/}"
        done
    done
done
