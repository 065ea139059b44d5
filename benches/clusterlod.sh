#!/usr/bin/env bash
# Reference numbers from meshoptimizer's cluster-LOD builder (demo/clusterlod.h), to compare our
# own cluster DAG builder against: builds benches/clusterlod/driver.cpp against meshoptimizer's
# source and runs it on each input, printing one JSON object per input on stdout (build seconds,
# clusters, groups, triangles per DAG level, and optionally DAG cuts at given errors).
#
#   bash benches/clusterlod.sh INPUT... [-- DRIVER-OPTIONS]
#   bash benches/clusterlod.sh .dev/scan-1m.ply -- --cut 0.0005,0.001 --out-prefix /tmp/clod
#
#   INPUT            binary little-endian PLY or OBJ (triangles only)
#   --cut E1,E2,...  DAG cuts at these errors, as fractions of the input's bounding-box diagonal
#   --cut-triangles N1,N2,...
#                    the finest DAG cut with at most each many triangles (P-t<N>.ply)
#   --out-prefix P   write each cut as P-<E>.ply (only with a single INPUT: the names would clash)
#
#   MESHOPT_SRC      meshoptimizer source folder [/tmp/meshoptimizer-src]; a folder that already
#                    holds src/ and demo/clusterlod.h (a git clone, say) is used as it is, otherwise
#                    it is extracted there from the mirror below. Never inside this repository:
#                    meshoptimizer's source is not to be committed here.
#   MESHOPT_MIRROR   bare git mirror of github.com/zeux/meshoptimizer
#                    [/work/.mirror/zeux+meshoptimizer/repo]
#   CLUSTERLOD_BIN   the compiled driver [/tmp/clusterlod-driver]; rebuilt when driver.cpp is newer
#                    or the meshoptimizer source it was built from changed
#   CXX              the compiler [g++]
#
# Needs bash, git (for the mirror) and a C++17 compiler. The driver runs clodBuild on one thread.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
driver_src=$here/clusterlod/driver.cpp
src=${MESHOPT_SRC:-/tmp/meshoptimizer-src}
mirror=${MESHOPT_MIRROR:-/work/.mirror/zeux+meshoptimizer/repo}
bin=${CLUSTERLOD_BIN:-/tmp/clusterlod-driver}
cxx=${CXX:-g++}

inputs=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do
    case $1 in
        -h|--help) sed -n '2,24p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
        *) inputs+=("$1") ;;
    esac
    shift
done
[ $# -gt 0 ] && shift # the "--"
opts=("$@")
[ ${#inputs[@]} -gt 0 ] || { echo "clusterlod.sh: no input files (see --help)" >&2; exit 2; }
if [ ${#inputs[@]} -gt 1 ] && [[ " ${opts[*]-} " == *" --out-prefix "* ]]; then
    echo "clusterlod.sh: --out-prefix with several inputs would overwrite the cuts; run one input at a time" >&2
    exit 2
fi

# meshoptimizer's source: a folder we extracted carries .meshopt-commit; anything else that holds
# the sources is the user's own and is never touched. Either way it must be outside this repository.
case $(realpath -m "$src")/ in
    "$(realpath -m "$here/..")"/*)
        echo "clusterlod.sh: MESHOPT_SRC=$src is inside this repository; meshoptimizer's source must stay outside it" >&2
        exit 2 ;;
esac
marker=$src/.meshopt-commit
have_src() { [ -f "$src/src/meshoptimizer.h" ] && [ -f "$src/demo/clusterlod.h" ]; }
if have_src && [ ! -f "$marker" ]; then
    commit=${MESHOPT_COMMIT:-unknown}
    if [ -e "$src/.git" ]; then commit=$(git -C "$src" rev-parse HEAD 2>/dev/null || echo "$commit"); fi
elif git -C "$mirror" rev-parse --verify -q HEAD >/dev/null 2>&1; then
    commit=$(git -C "$mirror" rev-parse HEAD)
    if [ "$(cat "$marker" 2>/dev/null || true)" != "$commit" ]; then
        if [ -e "$src" ] && [ ! -f "$marker" ] && [ -n "$(ls -A "$src")" ]; then
            echo "clusterlod.sh: $src exists but holds no meshoptimizer source; set MESHOPT_SRC elsewhere" >&2
            exit 2
        fi
        echo "clusterlod.sh: extracting meshoptimizer ${commit:0:12} into $src" >&2
        rm -rf "$src"
        mkdir -p "$src"
        git -C "$mirror" archive HEAD src demo/clusterlod.h | tar -x -C "$src"
        echo "$commit" >"$marker"
    fi
elif have_src; then
    commit=$(cat "$marker") # extracted by an earlier run; the mirror has gone since
else
    cat >&2 <<EOF
clusterlod.sh: no meshoptimizer source: $src does not hold src/ and demo/clusterlod.h, and there
is no git mirror at $mirror. Get it one of these ways, then rerun:
  - an agent session: fetch github:zeux/meshoptimizer (it lands in /work/.mirror/zeux+meshoptimizer/repo)
  - by hand: git clone https://github.com/zeux/meshoptimizer $src   (or set MESHOPT_SRC to a clone)
EOF
    exit 2
fi
export MESHOPT_COMMIT=$commit

# Rebuild when driver.cpp is newer than the binary, or the binary was built from other sources.
stamp="$commit $src"
if [ ! -x "$bin" ] || [ "$driver_src" -nt "$bin" ] || [ "$(cat "$bin.stamp" 2>/dev/null || true)" != "$stamp" ]; then
    echo "clusterlod.sh: compiling $bin (meshoptimizer ${commit:0:12})" >&2
    "$cxx" -O3 -DNDEBUG -std=c++17 "$driver_src" "$src"/src/*.cpp -I"$src/src" -I"$src/demo" -o "$bin.tmp"
    mv "$bin.tmp" "$bin"
    echo "$stamp" >"$bin.stamp"
fi

for input in "${inputs[@]}"; do
    "$bin" "$input" ${opts[@]+"${opts[@]}"}
done
