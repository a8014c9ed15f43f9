#!/usr/bin/env bash
# Sanitizer CI (issue #10): every unit test under ASan+UBSan (build-asan, no GUI), the
# threading tests (worker, SpdSolver, the parameterization's second thread, the parameterization
# set up beside the field) under TSan
# (build-tsan). Tests labelled "slow" are left out; the benchmark executables are not built
# (nothing of the test suite runs them; the main build compiles them).
# Usage: scripts/ci-sanitizers.sh [asan|tsan]...   (default: both)
# QS_SANITIZER_BUILD_ROOT puts the build folders elsewhere (default: the repository).
set -euo pipefail
cd "$(dirname "$0")/.."
root="${QS_SANITIZER_BUILD_ROOT:-.}"
jobs="$(nproc)"
generator=()
command -v ninja >/dev/null 2>&1 && generator=(-G Ninja)
steps=("$@")
[ ${#steps[@]} -eq 0 ] && steps=(asan tsan)

# Any report fails the run; leaks are errors too.
export ASAN_OPTIONS="detect_leaks=1:detect_stack_use_after_return=1:strict_init_order=1:abort_on_error=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1"
export LIBGL_ALWAYS_SOFTWARE=1

configure() {  # dir, extra cmake args
  local dir="$1"
  shift
  if [ ! -f "$dir/CMakeCache.txt" ]; then
    cmake -S . -B "$dir" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DQS_BUILD_APP=OFF \
      -DQS_BUILD_BENCH=OFF "$@"
  else
    cmake -S . -B "$dir" "$@" >/dev/null
  fi
}

for step in "${steps[@]}"; do
  t0=$SECONDS
  case "$step" in
    asan)
      configure "$root/build-asan" -DQS_SANITIZE=address
      cmake --build "$root/build-asan" -j"$jobs"
      ctest --test-dir "$root/build-asan" --output-on-failure -j"$jobs" -LE slow --timeout 600
      ;;
    tsan)
      configure "$root/build-tsan" -DQS_SANITIZE=thread
      cmake --build "$root/build-tsan" -j"$jobs" \
        --target worker_test spd_solver_test param_test param_elimination_test nodeopt_test \
        reuse_test
      "$root/build-tsan/tests/worker_test" --gtest_brief=1
      "$root/build-tsan/tests/spd_solver_test" --gtest_brief=1
      "$root/build-tsan/tests/param_test" --gtest_brief=1 \
        --gtest_filter='Parameterization.SecondThread*'
      "$root/build-tsan/tests/param_elimination_test" --gtest_brief=1 \
        --gtest_filter='ReducedAssembly.TwoThread*'
      "$root/build-tsan/tests/nodeopt_test" --gtest_brief=1 \
        --gtest_filter='NodeOptimizer.Parallel*:DiscreteRelocation.Parallel*'
      "$root/build-tsan/tests/reuse_test" --gtest_brief=1 \
        --gtest_filter='ReuseParam.*:ReuseField.ContinuedField*'
      ;;
    *)
      echo "ci-sanitizers: unknown step '$step' (asan or tsan)" >&2
      exit 1
      ;;
  esac
  echo "ci-sanitizers: $step passed in $((SECONDS - t0)) s"
done
