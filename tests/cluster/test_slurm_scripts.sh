#!/usr/bin/env bash
# The Slurm scripts of docs/cluster/ on a one-node Slurm that this test starts
# (slurm_one_node.sh): a render over 2 MPI ranks equals the one-process render; an array
# of Monte Carlo chunks in which one task dies is merged only after re-running that task,
# the merge naming it; the merged reference equals the one-process render.
#   tests/cluster/test_slurm_scripts.sh LVOX_BINARY WORKDIR
# Exits 77 (ctest: skipped) when Slurm or munge is not installed or not run as root.
set -euo pipefail
lvox=$(realpath "$1")
work=$(realpath -m "$2")
repo=$(cd "$(dirname "$0")/../.." && pwd)
for tool in slurmctld slurmd sbatch munged; do
  if ! command -v "$tool" >/dev/null && [ ! -x "/usr/sbin/$tool" ]; then
    echo "SKIP: $tool is not installed (Debian: slurm-wlm munge; .ci/setup installs them)"
    exit 77
  fi
done
if [ "$(id -u)" -ne 0 ]; then
  echo "SKIP: a one-node Slurm needs root (slurmd starts jobs as their user)"
  exit 77
fi
if ! "$lvox" --version | grep -q ", MPI"; then
  echo "SKIP: $lvox was built without MPI"
  exit 77
fi
rm -rf "$work"
mkdir -p "$work/run"
cat >"$work/scene.json" <<'SCENE'
{
  "camera": {"position": [0, 1.5, 4], "look_at": [0, 0.3, 0], "vfov_deg": 45, "width": 32, "height": 24},
  "render": {"mode": "mc", "spp": 6, "max_bounces": 3},
  "materials": {"white": {"albedo": 0.7}},
  "shapes": [{"type": "quad", "corners": [[-2,0,-2],[2,0,-2],[2,0,2],[-2,0,2]], "material": "white"},
             {"type": "box", "min": [-0.4,0,-0.4], "max": [0.4,0.8,0.4], "material": "white"}],
  "lights": [{"type": "directional", "direction": [0.3, -1, -0.2], "irradiance": 3},
             {"type": "environment", "radiance": 0.2}],
  "media": [{"type": "homogeneous", "min": [-2, 0, -2], "max": [2, 1.2, 2], "sigma_a": 0.1, "sigma_s": 0.3}],
  "pointcloud": {"target_surfels": 3000, "lvoxel_spacing": 0.2, "bounces": 3}
}
SCENE
# The one-process renders everything is compared with.
"$lvox" render "$work/scene.json" -o "$work/alone-mc.exr" --threads 1 -q
"$lvox" render "$work/scene.json" -o "$work/alone-pcb.exr" --mode pcb --threads 1 -q

# max |a - b| over every channel of every pixel (lvox compare's max_abs) within a bound.
# The radiance here is of order 1 and the samples non-negative, so a difference of float
# summation order stays below 1e-6; a missing or repeated chunk changes pixels by 0.1.
check_close() {
  /usr/bin/python3 - "$lvox" "$1" "$2" "$3" <<'PY'
import json, subprocess, sys
lvox, a, b, tol = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])
out = subprocess.run([lvox, "compare", a, b, "--json"], capture_output=True, text=True, check=True)
e = json.loads(out.stdout)
print(f"{a} vs {b}: max_abs {e['max_abs']:.3g}, delta {e['delta_percent']:.3g} %")
sys.exit(0 if e["max_abs"] <= tol else 1)
PY
}

# The scripts, submitted as a user would, from the run directory.
cd "$work/run"
export LVOX="$lvox"
"$repo/tests/cluster/slurm_one_node.sh" "$work/slurm" bash -euo pipefail -c '
  repo=$1 work=$2
  # sbatch --wait polls with a backoff of seconds: poll the job state every 0.1 s instead.
  # Succeeds when the job (every task of an array) completed with exit code 0.
  run() {
    local id
    id=$(sbatch --parsable "$@")
    echo "submitted job $id: $*" >&2
    while squeue -h -j "$id" 2>/dev/null | grep -q .; do sleep 0.1; done
    ! scontrol -o show job "$id" | grep -qv "JobState=COMPLETED"
  }
  # 1. A render over two ranks (pcb: the image of one process, exactly).
  run --ntasks=2 --cpus-per-task=1 "$repo/docs/cluster/render.sbatch" \
    "$work/scene.json" "$work/ranks-pcb.exr" --mode pcb
  cat lvox-render-*.log
  test -f "$work/ranks-pcb.json"
  # 2. Three chunks of 2 spp; task 1 is killed (its lvox is a wrapper that kills itself).
  cat >"$work/dying-lvox" <<WRAP
#!/usr/bin/env bash
if [ "\${SLURM_ARRAY_TASK_ID:-}" = 1 ]; then kill -9 \$\$; fi
exec "$LVOX" "\$@"
WRAP
  chmod +x "$work/dying-lvox"
  array=$(LVOX="$work/dying-lvox" sbatch --parsable --array=0-2 \
    "$repo/docs/cluster/reference-chunks.sbatch" "$work/scene.json" "$work/chunks" 2)
  if run --dependency=afterany:$array "$repo/docs/cluster/merge-chunks.sbatch" \
      "$work/chunks" 3 2 "$work/merged.exr"; then
    echo "FAIL: the merge succeeded with a chunk missing"; exit 1
  fi
  cat lvox-merge-*.log
  grep -q "array tasks 1 left no chunk" lvox-merge-*.log
  grep -q "samples \[2, 4) (--first-sample 2 --spp 2)" lvox-merge-*.log
  test ! -f "$work/merged.exr"
  test -f "$work/chunks/chunk-0.exr" && test -f "$work/chunks/chunk-2.exr"
  # 3. Only the missing task again, then the merge.
  run --array=1 "$repo/docs/cluster/reference-chunks.sbatch" \
    "$work/scene.json" "$work/chunks" 2
  rm -f lvox-merge-*.log
  run "$repo/docs/cluster/merge-chunks.sbatch" "$work/chunks" 3 2 "$work/merged.exr"
  cat lvox-merge-*.log
' _ "$repo" "$work"
check_close "$work/ranks-pcb.exr" "$work/alone-pcb.exr" 0
check_close "$work/merged.exr" "$work/alone-mc.exr" 1e-5
echo "PASS"
