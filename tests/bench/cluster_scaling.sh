#!/usr/bin/env bash
# 1 -> N MPI ranks with one thread each, mc and pcb, each phase's time (docs/cluster.md):
#   tests/bench/cluster_scaling.sh [SCENE] [WIDTH HEIGHT] [MC_SPP] [RANKS]
# Renders the scene alone and under mpirun -np RANKS (one after the other, same flags),
# checks the images agree, and prints each phase's seconds (the slowest rank's, then each
# rank's) with the ratio, each phase's CPU seconds (the work, apart from waiting for a
# core on a shared machine), and each rank's share of the point cloud's build ("work").
set -euo pipefail
cd "$(dirname "$0")/../.."
scene=${1:-scenes/atrium_smoke.json}
width=${2:-200}
height=${3:-150}
mc_spp=${4:-16}
ranks=${5:-2}
lvox=${LVOX:-build/lvox}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
mpirun=(mpirun -np "$ranks" --oversubscribe --mca btl_vader_single_copy_mechanism none)
if [ "$(id -u)" -eq 0 ]; then mpirun+=(--allow-run-as-root); fi
echo "scene $scene ${width}x${height}, $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg)"
for mode in ${MODES:-mc pcb}; do
  flags=(--mode "$mode" --threads 1 --width "$width" --height "$height" -q)
  if [ "$mode" = mc ]; then flags+=(--spp "$mc_spp"); fi
  start=$(date +%s.%N)
  "$lvox" render "$scene" -o "$out/$mode-1.exr" --report "$out/$mode-1.json" "${flags[@]}"
  middle=$(date +%s.%N)
  "${mpirun[@]}" "$lvox" render "$scene" -o "$out/$mode-n.exr" --report "$out/$mode-n.json" \
    "${flags[@]}"
  end=$(date +%s.%N)
  /usr/bin/python3 - "$mode" "$ranks" "$out/$mode-1.json" "$out/$mode-n.json" "$start" "$middle" \
    "$end" <<'PY'
import json, sys
mode, ranks, one, many = sys.argv[1], int(sys.argv[2]), *[json.load(open(p)) for p in sys.argv[3:5]]
start, middle, end = map(float, sys.argv[5:8])
print(f"\n{mode}: phase            1 rank   {ranks} ranks (rank 0 .. {ranks - 1})   speed-up"
      f"   CPU s: 1 rank, {ranks} ranks (rank 0 .. {ranks - 1})")
phases = [p for p in ["scene_load", "bvh_build", "media_load", "surfel_sampling",
                      "cloud_exchange", "lvoxel_sampling", "octree_build", "direct_cache",
                      "lvoxel_direct", "interreflection", "interreflection_trace",
                      "interreflection_exchange", "gather_grid", "render", "render_wait",
                      "render_exchange", "total"]
          if p in one["times"] or p in many["times"]]
for p in phases:
    a = one["times"].get(p, 0.0)
    per_rank = [r["times"].get(p, 0.0) for r in many["ranks"]]
    b = max(per_rank)
    ratio = f"{a / b:6.2f}x" if b > 0 and a > 0 else "      -"
    cpu = ""
    if p in one.get("cpu_times", {}) or any(p in r.get("cpu_times", {}) for r in many["ranks"]):
        cpu_ranks = " ".join(f"{r.get('cpu_times', {}).get(p, 0.0):.2f}" for r in many["ranks"])
        cpu = f"   {one.get('cpu_times', {}).get(p, 0.0):6.2f}  ({cpu_ranks})"
    print(f"  {p:18s} {a:8.2f} s {b:8.2f} s ({' '.join(f'{t:.2f}' for t in per_rank)})  {ratio}{cpu}")
if "work" in one:
    for key, whole in one["work"].items():
        shares = " + ".join(str(r.get("work", {}).get(key, 0)) for r in many["ranks"])
        print(f"  work {key}: {whole} alone, {shares} over the ranks")
a, b = middle - start, end - middle
print(f"  {'wall, with launch':18s} {a:8.2f} s {b:8.2f} s {'':{6 * ranks}s} {a / b:6.2f}x")
PY
  "$lvox" compare "$out/$mode-n.exr" "$out/$mode-1.exr" --json |
    /usr/bin/python3 -c 'import json,sys; e=json.load(sys.stdin); print("  image: max |difference| %.3g against the one-rank render" % e["max_abs"])'
done
