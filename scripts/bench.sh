#!/usr/bin/env bash
# Evaluation harness (issue #9), not part of the test suite. Builds the CLI and the bench
# executables if needed, runs every model with a real layout through quadsketch-cli (each run
# capped with `timeout`), then writes out/bench/results.json, docs/benchmarks.md and
# docs/bench/*.svg from that run only.
#
#   scripts/bench.sh [--models "spot fandisk ..."] [--steps N] [--no-micro] [--no-build]
#
# Environment: QS_BENCH_BUILD (build folder, default build), QS_BENCH_OUT (default out/bench),
# QS_SHARED_DIR (default ../shared). Models (all by default): ellipsoid spot fandisk pig cow cat
# joint. Caps in seconds: QS_BENCH_OPT_CAP (node optimization, default 150),
# QS_BENCH_DISCRETE_CAP (discrete relocation, default 120), QS_BENCH_CAP (other runs, 120).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
command_line="$( (env | grep -E '^(QS_(BENCH_[A-Z_]+|SHARED_DIR)|OMP_NUM_THREADS|OMP_THREAD_LIMIT|OPENBLAS_NUM_THREADS)=' || true) | sort | tr '\n' ' ')scripts/bench.sh $*"
models="ellipsoid spot fandisk pig cow cat joint"
steps=10
micro=1
do_build=1
while [ $# -gt 0 ]; do
  case "$1" in
    --models) models="$2"; shift 2 ;;
    --steps) steps="$2"; shift 2 ;;
    --no-micro) micro=0; shift ;;
    --no-build) do_build=0; shift ;;
    -h|--help) sed -n 2,15p "$0"; exit 0 ;;
    *) echo "bench.sh: unknown argument $1" >&2; exit 1 ;;
  esac
done
build=${QS_BENCH_BUILD:-build}
out=${QS_BENCH_OUT:-out/bench}
shared=${QS_SHARED_DIR:-../shared}/data/meshes
opt_cap=${QS_BENCH_OPT_CAP:-150}
disc_cap=${QS_BENCH_DISCRETE_CAP:-120}
cap=${QS_BENCH_CAP:-120}
t_start=$(date +%s)
# The commit is taken before the build: the binaries are built from this working tree.
commit="$(git rev-parse --short HEAD 2>/dev/null || echo unknown)"
[ -n "$(git status --porcelain --untracked-files=no 2>/dev/null)" ] &&
  commit="$commit (with uncommitted changes)"

if [ ! -x /usr/bin/time ]; then
  echo "bench.sh: /usr/bin/time is missing (Debian package 'time'); peak memory not measured" >&2
fi

# --- build ---------------------------------------------------------------------------------
cmake_args=(-DCMAKE_BUILD_TYPE=Release)
if [ "$do_build" = 0 ]; then
  :
elif [ ! -f "$build/CMakeCache.txt" ]; then
  generator=()
  command -v ninja >/dev/null 2>&1 && generator=(-G Ninja)
  cmake -S . -B "$build" "${generator[@]}" -DQS_BUILD_APP=OFF "${cmake_args[@]}" >/dev/null
else
  cmake -S . -B "$build" "${cmake_args[@]}" >/dev/null
fi
targets=(quadsketch-cli)
[ "$micro" = 1 ] && targets+=(qs_micro_bench qs_bench_gradient)
[ "$do_build" = 1 ] && cmake --build "$build" -j"$(nproc --all)" --target "${targets[@]}"
cli="$(cd "$build" && pwd)/app/quadsketch-cli"

mkdir -p "$out"
rm -rf "${out:?}"/runs
mkdir -p "$out/runs"

# run NAME CAP CMD...: one capped run in $out/runs/NAME (log.txt, time.txt, run.json).
run() {
  local name=$1 limit=$2
  shift 2
  local dir="$out/runs/$name"
  mkdir -p "$dir"
  local t0 t1 rc=0
  t0=$(date +%s.%N)
  if [ -x /usr/bin/time ]; then
    /usr/bin/time -v -o "$dir/time.txt" timeout "$limit" "$@" >"$dir/log.txt" 2>&1 || rc=$?
  else
    timeout "$limit" "$@" >"$dir/log.txt" 2>&1 || rc=$?
  fi
  t1=$(date +%s.%N)
  printf '{"name": "%s", "exit_code": %d, "cap_s": %s, "wall_s": %s, "command": "%s"}\n' \
    "$name" "$rc" "$limit" "$(awk "BEGIN{print $t1 - $t0}")" "$*" >"$dir/run.json"
  echo "bench: $name: exit $rc, $(awk "BEGIN{printf \"%.1f\", $t1 - $t0}") s" >&2
}

# optimize runs of one model: MODEL MESH LAYOUT PERTURBED_LAYOUT NODE_OPT, where NODE_OPT is
# full (both layouts, and discrete relocation on the perturbed one), perturbed (continuous
# relocation of the perturbed layout only) or none (--no-node-opt only).
bench_model() {
  local model=$1 mesh=$2 layout=$3 perturbed=$4 node_opt=$5
  local r="$out/runs"
  run "$model.align" "$cap" "$cli" optimize --mesh "$mesh" --layout "$layout" \
    --out "$r/$model.align" --no-node-opt
  run "$model.noalign" "$cap" "$cli" optimize --mesh "$mesh" --layout "$layout" \
    --out "$r/$model.noalign" --no-node-opt --no-align
  if [ "$node_opt" = full ]; then
    run "$model.opt" "$opt_cap" "$cli" optimize --mesh "$mesh" --layout "$layout" \
      --out "$r/$model.opt" --steps "$steps"
    if [ -n "$perturbed" ]; then
      run "$model.perturbed.opt" "$opt_cap" "$cli" optimize --mesh "$mesh" \
        --layout "$perturbed" --out "$r/$model.perturbed.opt" --steps "$steps"
      run "$model.perturbed.discrete" "$disc_cap" "$cli" optimize --mesh "$mesh" \
        --layout "$perturbed" --out "$r/$model.perturbed.discrete" --steps "$steps" \
        --discrete-relocation
    fi
  elif [ "$node_opt" = perturbed ] && [ -n "$perturbed" ]; then
    run "$model.perturbed.opt" "$opt_cap" "$cli" optimize --mesh "$mesh" --layout "$perturbed" \
      --out "$r/$model.perturbed.opt" --steps "$steps"
  elif [ -n "$perturbed" ]; then
    run "$model.perturbed.align" "$cap" "$cli" optimize --mesh "$mesh" --layout "$perturbed" \
      --out "$r/$model.perturbed.align" --no-node-opt
  fi
}

# import MODEL ARGS...: import-quads into $out/runs/MODEL.import, then perturb --rings 2 --seed 1.
import_model() {
  local model=$1
  shift
  local dir="$out/runs/$model.import"
  run "$model.import" "$cap" "$cli" import-quads "$@" --out "$dir"
  [ -f "$dir/layout.json" ] || return 1
  run "$model.perturb" "$cap" "$cli" perturb --mesh "$dir/mesh.obj" --layout "$dir/layout.json" \
    --rings 2 --seed 1 --out "$dir/perturbed.layout.json"
}

for model in $models; do
  case "$model" in
    ellipsoid)  # bundled example: exact corners and the displaced sketch
      bench_model ellipsoid assets/example/ellipsoid.obj assets/example/ellipsoid_exact.layout.json \
        assets/example/ellipsoid.layout.json full ;;
    spot) import_model spot --quads "$shared/spot/spot_quadrangulated.obj" || continue ;;
    fandisk)
      import_model fandisk --quads "$shared/fandisk/fandisk_quads.off" \
        --onto "$shared/fandisk/fandisk.off" || continue ;;
    pig|cow|cat)
      import_model "$model" --quads "$shared/animals_basemesh/${model}_${model}.obj" --refine 3 ||
        continue ;;
    joint)
      import_model joint --quads "$shared/quadwild_joint/joint_rem_p_quadrangulation.obj" ||
        continue ;;
    *) echo "bench.sh: unknown model $model" >&2; continue ;;
  esac
  if [ "$model" != ellipsoid ]; then
    dir="$out/runs/$model.import"
    pert="$dir/perturbed.layout.json"
    [ -f "$pert" ] || pert=""
    # Node optimization where it fits the caps on a 2-core machine: the animals (--refine 3,
    # ~40K faces, ~1K nodes) only on their perturbed layout; joint (43K faces, 3751 nodes) not.
    case "$model" in
      spot|fandisk) node_opt=full ;;
      pig|cow|cat) node_opt=perturbed ;;
      *) node_opt=none ;;
    esac
    bench_model "$model" "$dir/mesh.obj" "$dir/layout.json" "$pert" "$node_opt"
  fi
done

# --- micro-benchmarks and gradient statistics ------------------------------------------------
if [ "$micro" = 1 ]; then
  run micro 300 "$build/bench/qs_micro_bench" --benchmark_min_time=0.2 \
    --benchmark_out="$out/runs/micro/micro.json" --benchmark_out_format=json
  run gradient_stats 300 "$build/bench/qs_bench_gradient" --json "$out/runs/gradient_stats/stats.json"
fi

t_end=$(date +%s)
machine_json=$(
  python3 - "$t_start" "$t_end" "$command_line" "$commit" <<'EOF'
import json, subprocess, sys
def sh(c):
    try:
        return subprocess.run(c, shell=True, capture_output=True, text=True).stdout.strip()
    except Exception:
        return ""
print(json.dumps({
    "nproc": sh("nproc --all"),
    "cpu": sh("lscpu | grep 'Model name' | sed 's/Model name: *//'"),
    "memory": sh("free -h | awk '/^Mem:/ {print $2}'"),
    "load": sh("cut -d' ' -f1-3 /proc/loadavg"),
    "date": sh("date -u -d @" + sys.argv[1] + " '+%Y-%m-%d %H:%M UTC'"),
    "commit": sys.argv[4],
    "command": sys.argv[3],
    "runtime_s": int(sys.argv[2]) - int(sys.argv[1]),
}))
EOF
)
python3 bench/make_report.py --runs "$out/runs" --machine "$machine_json" \
  --json "$out/results.json" --markdown docs/benchmarks.md --svg-dir docs/bench
echo "bench: wrote $out/results.json, docs/benchmarks.md, docs/bench/*.svg in $((t_end - t_start)) s" >&2
