#!/usr/bin/env bash
# The real-GPU benchmark: one prepared run for a machine with a Vulkan driver and no Rust
# toolchain. It runs a prebuilt release binary, makes its inputs with the binary itself and
# prints one table (every QEM backend, cluster and hybrid on cpu-parallel and gpu, hybrid also
# on cpu, its default: the greedy queue after the clusters; meshopt; time, rounds, faces, mean
# error), the GPU's stage times from timestamp queries and the time spent outside the rounds
# (pipelines, upload and read-back, preparation; `qem` on the GPU with the preparation on the
# device and on the host); the same as JSON.
#
#   bash benches/gpu.sh [--quick] [--out DIR] [--repeat N] [MESH...]
#
#   MESHSLIM=path   the binary [target/release/meshslim]; strip it so it travels:
#                   strip -o .dev/meshslim target/release/meshslim
#   MESH            files or builtin:NAME[:FACES] [builtin:bumpy-sphere:1000000 (1.3M faces) and
#                   builtin:bumpy-sphere:4000000 (5.2M faces)]
#   --quick         the first mesh at 1% only, one repeat: minutes on lavapipe
#   --out DIR       where bench.json, the simplify reports and gpu.json go [a temporary folder]
#
# Needs bash, python3 (the standard library only) and the binary. With no GPU adapter the gpu
# rows fail loudly rather than vanish.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
bin=${MESHSLIM:-$here/../target/release/meshslim}
quick=0
out=""
repeat=""
meshes=()
while [ $# -gt 0 ]; do
    case $1 in
        --quick) quick=1 ;;
        --out) out=$2; shift ;;
        --repeat) repeat=$2; shift ;;
        -h|--help) sed -n '2,18p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
        -*) echo "gpu.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
        *) meshes+=("$1") ;;
    esac
    shift
done
[ -x "$bin" ] || { echo "gpu.sh: no binary at $bin (set MESHSLIM)" >&2; exit 2; }
command -v python3 >/dev/null || { echo "gpu.sh: python3 is needed for the table" >&2; exit 2; }
if [ ${#meshes[@]} -eq 0 ]; then
    meshes=(builtin:bumpy-sphere:1000000)
    [ $quick -eq 1 ] || meshes+=(builtin:bumpy-sphere:4000000)
fi
if [ $quick -eq 1 ]; then
    meshes=("${meshes[0]}")
    ratios=(0.01)
    repeat=${repeat:-1}
else
    ratios=(0.1 0.01)
    repeat=${repeat:-3}
fi
keep=1
if [ -z "$out" ]; then
    keep=0
    out=$(mktemp -d)
    trap 'rm -rf "$out"' EXIT
fi
mkdir -p "$out"
# The error is measured on a fixed number of samples: the default (10 per face) would spend
# longer measuring a 5M-face scan than simplifying it.
samples=2000000
backends=cpu,cpu-parallel,gpu,cluster,cluster-gpu,hybrid,hybrid-parallel,hybrid-gpu,meshopt,meshopt-sloppy

echo "== $("$bin" --version) on $(nproc) cores; meshes: ${meshes[*]}; ratios: ${ratios[*]}" >&2
start=$SECONDS
# Time, faces and error of every backend, as `meshslim bench` measures them.
"$bin" bench "${meshes[@]}" --ratios "$(IFS=,; echo "${ratios[*]}")" --backends "$backends" \
    --repeat "$repeat" -n "$samples" --json "$out/bench.json" >&2
echo "== bench: $((SECONDS - start)) s" >&2
# Rounds, stage times and the time outside the rounds, from each rounds path's own report.
i=0
for m in "${meshes[@]}"; do
    for r in "${ratios[@]}"; do
        for method in qem cluster hybrid; do
            for b in cpu-parallel gpu; do
                "$bin" simplify "$m" "$out/o.ply" --ratio "$r" --method "$method" --backend "$b" \
                    --json --quiet >"$out/simplify-$i.json"
                i=$((i + 1))
            done
            # `qem` on the GPU once more with the host's preparation, to see what moving it
            # to the device saved (the `prep` column).
            if [ "$method" = qem ]; then
                MESHSLIM_PREPARE=host "$bin" simplify "$m" "$out/o.ply" --ratio "$r" \
                    --method qem --backend gpu --json --quiet >"$out/simplify-$i.json"
                i=$((i + 1))
            fi
        done
    done
done
rm -f "$out/o.ply"
echo "== reports: $((SECONDS - start)) s" >&2

KEEP=$keep python3 - "$out" <<'EOF'
import glob, json, os, sys

out = sys.argv[1]
bench = json.load(open(os.path.join(out, "bench.json")))
reports = [json.load(open(f)) for f in sorted(glob.glob(os.path.join(out, "simplify-*.json")),
                                               key=lambda f: int(f.rsplit("-", 1)[1][:-5]))]
adapter = next((r["rounds"]["adapter"] for r in reports
                if r.get("rounds") and r["rounds"].get("adapter")), "no adapter")
machine = bench.get("machine", {})
print(f"adapter: {adapter}; CPU: {machine.get('cpu')} ({machine.get('cores')} threads)")

def method_of(row):
    b = row["backend"]
    if b == "hybrid":
        return "hybrid", "cpu"
    for m in ("cluster", "hybrid"):
        if b.startswith(m):
            return m, ("gpu" if b.endswith("-gpu") else "cpu-parallel")
    return "qem", b

def report_for(row):
    method, backend = method_of(row)
    for r in reports:
        if (r["input"] == row["mesh"] and r["target_faces"] == row["target_faces"]
                and r["backend"] == backend
                and (method == "qem") == (r.get("clustering") is None)
                and (method != "hybrid" or (r["clustering"] or {}).get("intermediate_faces"))):
            return r
    return None

print()
print(f"{'mesh':<30} {'faces':>9} {'ratio':>5} {'backend':<15} {'s':>8} {'rounds':>6} "
      f"{'out faces':>9} {'mean err':>9}")
for row in bench["rows"]:
    rep = report_for(row)
    rounds = (rep or {}).get("rounds") or {}
    print(f"{row['mesh']:<30} {row['input_faces']:>9} {row['ratio']:>5} {row['backend']:<15} "
          f"{row['median_s']:>8.3f} {rounds.get('rounds', '-'):>6} {row['output_faces']:>9} "
          f"{(row.get('mean_err_rel') or float('nan')):>9.2e}")

print()
print("gpu runs: where the time goes (seconds). stages: every pass's GPU time (timestamp queries);")
print("waits: from each round's submission to its counters read back (the stages and the driver);")
print("prepare: the host's weld, Morton order and normalization; rest: recording passes, assembling")
print("the output")
print(f"{'mesh':<30} {'ratio':>5} {'method':<8} {'simplify':>8} {'stages':>7} {'waits':>7} "
      f"{'prepare':>7} {'pipeline':>8} {'transfer':>8} {'rest':>7}  slowest stages")
summary = []
for r in reports:
    if r["backend"] != "gpu":
        continue
    ratio = r["target_faces"] / max(r["input_faces"], 1)
    if not r.get("rounds"):
        # `cluster` runs no rounds: its one build's time is the clustering's.
        c = r.get("clustering") or {}
        print(f"{r['input']:<30} {ratio:>5.2f} {'cluster':<8} {r['seconds']['simplify']:>8.3f} "
              f"{'-':>7} {'-':>7} {'-':>7} {'-':>8} {'-':>8} {'-':>7}  "
              f"clustering {c.get('seconds', 0):.3f}")
        summary.append({"input": r["input"], "method": "cluster",
                        "target_faces": r["target_faces"],
                        "simplify_s": r["seconds"]["simplify"],
                        "clustering_s": c.get("seconds")})
        continue
    rr = r["rounds"]
    stages = rr["stage_seconds"]
    total = sum(t for _, t in stages)
    method = "qem" if r.get("clustering") is None else "hybrid"
    simplify = r["seconds"]["simplify"]
    waits = rr.get("wait_seconds", 0.0)
    prepare = rr.get("prepare_seconds", 0.0)
    rest = simplify - waits - prepare - rr["pipeline_seconds"] - rr["transfer_seconds"]
    if method == "hybrid":
        rest -= (r["clustering"] or {}).get("seconds", 0.0)
    top = sorted(stages, key=lambda s: -s[1])[:3]
    print(f"{r['input']:<30} {ratio:>5.2f} {method:<8} {simplify:>8.3f} {total:>7.3f} "
          f"{waits:>7.3f} {prepare:>7.3f} {rr['pipeline_seconds']:>8.3f} "
          f"{rr['transfer_seconds']:>8.3f} {rest:>7.3f}  "
          + ", ".join(f"{s} {t:.3f}" for s, t in top)
          + (f"; clustering {r['clustering']['seconds']:.3f}" if method == "hybrid" else ""))
    summary.append({"input": r["input"], "method": method, "target_faces": r["target_faces"],
                    "simplify_s": simplify, "stages_s": total, "waits_s": waits,
                    "prepare_s": prepare, "pipeline_s": rr["pipeline_seconds"],
                    "transfer_s": rr["transfer_seconds"], "rest_s": rest,
                    "gpu_timestamps": rr["gpu_timestamps"], "rounds": rr["rounds"],
                    "stage_seconds": stages})
print()
print("what each rounds run cost on the device's side: waits (round trips), submits, dispatches,")
print("bind groups made, bytes each way; host: the call less its time blocked on the device;")
print("cache: the pipelines from the on-disk cache (hit), compiled into it (miss), or neither;")
print("prep: where the mesh was welded, ordered and normalized (device, or host)")
print(f"{'mesh':<30} {'ratio':>5} {'method':<8} {'backend':<12} {'simplify':>8} {'waits':>5} "
      f"{'submits':>7} {'dispatch':>8} {'binds':>5} {'MB up':>7} {'MB back':>7} {'host s':>7} "
      f"{'cache':>11} {'prep':>6}")
for r in reports:
    rr = r.get("rounds")
    if not rr:
        continue
    ratio = r["target_faces"] / max(r["input_faces"], 1)
    method = "qem" if r.get("clustering") is None else "hybrid"
    print(f"{r['input']:<30} {ratio:>5.2f} {method:<8} {r['backend']:<12} "
          f"{r['seconds']['simplify']:>8.3f} {rr.get('device_waits', 0):>5} "
          f"{rr.get('submits', 0):>7} {rr.get('dispatches', 0):>8} "
          f"{rr.get('bind_groups_created', 0):>5} {rr.get('bytes_uploaded', 0) / 1e6:>7.1f} "
          f"{rr.get('bytes_read_back', 0) / 1e6:>7.2f} {rr.get('host_seconds', 0.0):>7.3f} "
          f"{rr.get('pipeline_cache') or '-':>11} {rr.get('prepared_on') or '-':>6}")
gpu_qem = [r for r in reports if r["backend"] == "gpu" and r.get("rounds")
           and r.get("clustering") is None and r["target_faces"] * 50 < r["input_faces"]]
for r in gpu_qem:
    s = r["seconds"]["simplify"]
    print(f"goal: {r['input']} at 1% in {s * 1000:.1f} ms on the gpu path "
          f"({'within' if s <= 0.030 else 'over'} the 30 ms goal)")
json.dump({"adapter": adapter, "bench": bench, "gpu_runs": summary, "reports": reports},
          open(os.path.join(out, "gpu.json"), "w"), indent=1)
print(f"\nJSON: {os.path.join(out, 'gpu.json')}" if os.environ.get("KEEP") == "1"
      else "\nJSON: give --out DIR to keep it")
EOF
