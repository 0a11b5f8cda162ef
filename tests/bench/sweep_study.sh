#!/usr/bin/env bash
# The speed-against-error study of docs/results.md: `lvox sweep` over every hard case
# (128x128, 2 spp, direct mode, against a fine RK4 render with the same camera rays) and
# over the atrium with smoke (direct mode, 128x128; and pcb mode at 512x512 with the
# Monte Carlo curve, against the converged MC reference when one is given).
#   tests/bench/sweep_study.sh [OUT_DIR] [ATRIUM_MC_REFERENCE.exr]
# After .ci/setup; about 25 minutes on 2 cores without the pcb part.
set -euo pipefail
cd "$(dirname "$0")/../.."
out=${1:-docs/images/sweep}
mcref=${2:-}
mkdir -p "$out"
lvox=${LVOX:-build/lvox}
common=(--width 128 --height 128 --spp 2 -q)
# The fine reference must resolve what the coarse renders miss: the thin beam is 0.05
# units wide near the spot, so its reference takes 1/128 of the scene's step; in the noise
# field every camera evaluation costs a shadow solve, so 1/8 there (checked: GK at tol 1e-3
# agrees with it to 0.008 %). The thick medium at 1/16 is itself 0.024 % off: 1/64 there.
# The fog slab gives no step: its own is 0.6 optical depths (4 units), so 1/128 of it.
declare -A refscale=([thin_beam]=0.0078125 [sharp_shadow]=0.03125 [thick_medium]=0.015625
  [high_frequency]=0.125 [fog_slab]=0.0078125)
for scene in scenes/hard/*.json; do
  name=$(basename "$scene" .json)
  mkdir -p "$out/$name"
  extra=()
  # GK and adaptive pairs through the busy noise field cost minutes per point: keep 3 tols.
  if [ "$name" = high_frequency ]; then extra=(--tols 0.1,0.01,0.001); fi
  $lvox sweep "$scene" -o "$out/$name" "${common[@]}" \
    --reference-step-scale "${refscale[$name]:-0.0625}" "${extra[@]}"
  echo "$name done" >&2
done
mkdir -p "$out/atrium_smoke_direct"
$lvox sweep scenes/atrium_smoke.json -o "$out/atrium_smoke_direct" --mode direct "${common[@]}" \
  --methods auto,euler,rk2,rk4,dopri5,bs23,simpson,rectangle --tols 0.1,0.01,0.001
if [ -n "$mcref" ]; then
  mkdir -p "$out/atrium_smoke_pcb"
  $lvox sweep scenes/atrium_smoke.json -o "$out/atrium_smoke_pcb" --mode pcb -q \
    --reference "$mcref" --methods auto,euler,rk4,dopri5,mc --step-scales 4,1 \
    --tols 0.1,0.001 --mc-spp 4,16,64
fi
# The sweeps keep their images only while they run: docs/ holds the CSVs, the plots and one
# report of all of them (docs/results.md), not megabytes of point images per scene.
rm -rf "$out"/*/points "$out"/*/reference.exr "$out"/*/report.html
$lvox report --title "lvox sweep study" --sweep "$out"/*/ -o "$out/report.html" -q
for f in "$out"/*/sweep.csv; do echo "== $f"; cat "$f"; done
