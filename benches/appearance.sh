#!/usr/bin/env bash
# Appearance against geometry, ours against meshoptimizer's simplifyWithAttributes, in one run:
# the shared scans painted (examples/paint_scan.rs) and spot with its texture, at 10% and 1%.
#   cargo build --release --examples && bash benches/appearance.sh [OUTDIR]
# For each mesh and ratio it prints, per row, the mean two-sided distance (relative to the
# diagonal) and the mean colour error (vertex colours; on spot the texture's colour at the UVs,
# 'meshslim compare --texture'):
#   - meshslim `cpu` at several --color-weight (painted) or --uv-weight (spot) values, the
#     default among them, then the rounds (`cpu-parallel`, and `gpu` when BACKENDS names it)
#     and `hybrid` at the default weights;
#   - meshoptimizer's simplifyWithAttributes at weights 0.1, 0.3 and 1 ('meshslim bench'
#     backends meshopt-attr-*), and plain simplify.
# Uses ../shared/models (MESHSLIM_MODELS overrides); MESHSLIM=binary (target/release/meshslim).
set -euo pipefail
bin=${MESHSLIM:-target/release/meshslim}
# The other runs at the default weights: "--backend B" or "--method M", comma-separated.
IFS=, read -r -a others <<< "${BACKENDS:---backend cpu-parallel,--method hybrid}"
paint=${PAINT:-target/release/examples/paint_scan}
models=${MESHSLIM_MODELS:-../shared/models}
out=${1:-$(mktemp -d)}
mkdir -p "$out"
[ -x "$paint" ] || { echo "build the examples first: cargo build --release --examples" >&2; exit 1; }

figures() { # A B [compare options...] -> "distance colour"
    local a=$1 b=$2
    shift 2
    "$bin" compare "$a" "$b" --json "$@" | python3 -c '
import json, sys
d = json.load(sys.stdin)
look = d.get("appearance") or {}
c = (look.get("texture") or look.get("color") or {}).get("mean", float("nan"))
print("%.3e %.4f" % (d["distance"]["two_sided"]["mean_rel"], c))'
}

peers() { # MESH [bench options...]: the meshopt rows of one bench run, as "name distance colour"
    local mesh=$1
    shift
    "$bin" bench "$mesh" --ratios 0.1,0.01 --repeat 1 --json "$out/peers.json" "$@" \
        --backends meshopt,meshopt-attr-0.1,meshopt-attr-0.3,meshopt-attr-1 >/dev/null
    python3 - "$out/peers.json" <<'EOF'
import json, sys
for r in json.load(open(sys.argv[1]))["rows"]:
    c = r.get("texture_err", r.get("color_err"))
    print("%s %s %.3e %.4f" % (r["ratio"], r["backend"], r["mean_err_rel"], c))
EOF
}

printf '%-10s %5s %-22s %10s %8s\n' mesh ratio run distance colour
for name in horse igea; do
    src="$models/$name.ply"
    [ -f "$src" ] || continue
    painted="$out/$name-painted.ply"
    "$paint" "$src" "$painted" >/dev/null
    for r in 0.1 0.01; do
        for w in 0 0.01 0.02 0.04 0.1 0.3; do
            "$bin" simplify "$painted" "$out/o.ply" --ratio "$r" --color-weight "$w" --quiet
            read -r d c < <(figures "$painted" "$out/o.ply")
            printf '%-10s %5s %-22s %10s %8s\n' "$name" "$r" "cpu color-weight $w" "$d" "$c"
        done
        for o in "${others[@]}"; do
            # shellcheck disable=SC2086 # "--backend B": two words
            "$bin" simplify "$painted" "$out/o.ply" --ratio "$r" $o --quiet
            read -r d c < <(figures "$painted" "$out/o.ply")
            printf '%-10s %5s %-22s %10s %8s\n' "$name" "$r" "${o#--* }" "$d" "$c"
        done
    done
    peers "$painted" | while read -r r b d c; do
        printf '%-10s %5s %-22s %10s %8s\n' "$name" "$r" "$b" "$d" "$c"
    done
done
spot="$models/spot/spot_triangulated.obj"
tex="$models/spot/spot_texture.png"
if [ -f "$spot" ]; then
    for r in 0.1 0.01; do
        for w in 0 0.1 0.3 1 3; do
            "$bin" simplify "$spot" "$out/o.obj" --ratio "$r" --uv-weight "$w" --quiet
            read -r d c < <(figures "$spot" "$out/o.obj" --texture "$tex")
            printf '%-10s %5s %-22s %10s %8s\n' spot "$r" "cpu uv-weight $w" "$d" "$c"
        done
        for o in "${others[@]}"; do
            # shellcheck disable=SC2086 # "--backend B": two words
            "$bin" simplify "$spot" "$out/o.obj" --ratio "$r" $o --quiet
            read -r d c < <(figures "$spot" "$out/o.obj" --texture "$tex")
            printf '%-10s %5s %-22s %10s %8s\n' spot "$r" "${o#--* }" "$d" "$c"
        done
    done
    peers "$spot" --texture "$tex" | while read -r r b d c; do
        printf '%-10s %5s %-22s %10s %8s\n' spot "$r" "$b" "$d" "$c"
    done
fi
