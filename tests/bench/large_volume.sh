#!/usr/bin/env bash
# The large-volume benchmark (issue 15): makes a production-sized VDB on demand (never
# committed: build/make_large_vdb upsamples the WDAS 1/16 cloud x10 per axis with noise
# detail, 3.6e8 active voxels, 1.1 GB on disk, about a minute), renders it in mc, direct and
# pcb with the cloud_wdas camera and lights, and prints each run's peak RSS against the
# grids' own memory (OpenVDB's memUsage, the report's memory.media).
#   tests/bench/large_volume.sh [FACTOR]     (after .ci/setup; about 2 minutes on 2 cores)
set -euo pipefail
cd "$(dirname "$0")/../.."
factor=${1:-10}
source_vdb=../shared/assets/vdb/wdas_cloud_sixteenth.vdb
work=build/large
mkdir -p "$work"
vdb=$work/wdas_x$factor.vdb
[ -f "$vdb" ] || build/make_large_vdb "$source_vdb" "$vdb" "$factor"
scene=$work/cloud_x$factor.json
sed "s|\"file\": \"../../shared/assets/vdb/wdas_cloud_sixteenth.vdb\"|\"file\": \"$(basename "$vdb")\"|" \
  scenes/cloud_wdas.json > "$scene"
printf '%-7s %-22s %9s %9s %12s %12s %7s\n' mode size seconds load_s grids_MB peak_rss_MB ratio
for run in "mc --spp 4 --width 128 --height 128" "direct --spp 1 --width 32 --height 32" \
           "pcb --spp 1 --width 128 --height 128"; do
  set -- $run
  mode=$1
  shift
  build/lvox render "$scene" --mode "$mode" "$@" -q -o "$work/large_$mode.exr" \
    --report "$work/large_$mode.json"
  /usr/bin/python3 - "$work/large_$mode.json" "$mode" "$*" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
grids, rss = r["memory"]["media"], r["memory"]["peak_rss"]
size = sys.argv[3].replace("--", "")
print(f"{sys.argv[2]:<7} {size:<22} {r['times']['total']:9.1f} {r['times']['media_load']:9.1f} "
      f"{grids / 1e6:12.1f} {rss / 1e6:12.1f} {rss / grids:7.2f}")
PY
done
