#!/usr/bin/env bash
# The hard-case study: renders every scene of scenes/hard with three representative
# solvers (euler = classic ray marching, rk4, dopri5) at 128x128, measures each against a
# fine reference (rk4 at a quarter of the scene's step) with `lvox compare`, and writes
# docs/images/hard_cases.png (a montage) and docs/images/hard_cases.csv.
#   tests/bench/hard_cases.sh        (after .ci/setup; about a minute on 2 cores)
set -euo pipefail
cd "$(dirname "$0")/../.."
out=${1:-docs/images}
mkdir -p "$out"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
lvox=build/lvox
size="--width 128 --height 128 --spp 2 -q"
echo "scene,solver,step_or_tol,seconds,medium_evals,delta_percent,rmse" > "$work/hard_cases.csv"
images=()
for scene in scenes/hard/*.json; do
  name=$(basename "$scene" .json)
  step=$(/usr/bin/python3 -c "import json,sys; print(json.load(open('$scene'))['volume_integrator']['step'])")
  fine=$(/usr/bin/python3 -c "print($step / 4)")
  $lvox render "$scene" $size --solver rk4 --step "$fine" -o "$work/$name-ref.exr"
  for solver in euler rk4 dopri5; do
    $lvox render "$scene" $size --solver $solver --step "$step" --tol 1e-3 \
      -o "$work/$name-$solver.exr" --report "$work/$name-$solver.json"
    metrics=$($lvox compare "$work/$name-$solver.exr" "$work/$name-ref.exr" --json)
    /usr/bin/python3 - "$work/$name-$solver.json" "$name" "$solver" "$step" "$metrics" >> "$work/hard_cases.csv" <<'PY'
import json, sys
report = json.load(open(sys.argv[1])); m = json.loads(sys.argv[5])
print(f"{sys.argv[2]},{sys.argv[3]},{sys.argv[4]},{report['times']['render']:.3f},"
      f"{report['counts']['medium_evals']},{m['delta_percent']:.4f},{m['rmse']:.6g}")
PY
    images+=("$work/$name-$solver.png")
  done
done
/usr/bin/python3 - "$out/hard_cases.png" "${images[@]}" <<'PY'
import sys, matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt, matplotlib.image as mpimg
out, files = sys.argv[1], sys.argv[2:]
rows = len(files) // 3
fig, axes = plt.subplots(rows, 3, figsize=(7.5, 2.5 * rows))
for ax, f in zip(axes.flatten(), files):
    ax.imshow(mpimg.imread(f), interpolation="nearest")
    ax.set_title(f.split("/")[-1][:-4], fontsize=8)
    ax.axis("off")
plt.tight_layout()
plt.savefig(out, dpi=80)
PY
cp "$work/hard_cases.csv" "$out/hard_cases.csv"
cat "$out/hard_cases.csv"
