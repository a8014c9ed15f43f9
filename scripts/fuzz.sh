#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ (clang, ASan+UBSan) and runs each for N seconds
# (default 60). Any crash, leak, timeout (>10 s per input) or sanitizer report fails the run;
# the reproducer is saved as build-fuzz/artifacts/<target>-crash-* (replay it with
# build-fuzz/fuzz/<target> FILE). Seeds: fuzz/corpus/ (valid inputs, e.g. with a byte-order
# mark), assets/example/ and assets/bad/.
# Usage: scripts/fuzz.sh [seconds] [target...]    (targets: layout_fuzzer mesh_fuzzer
# quads_fuzzer). QS_FUZZ_BUILD_DIR moves the build folder (default: build-fuzz).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
shift || true
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(layout_fuzzer mesh_fuzzer quads_fuzzer)
build="${QS_FUZZ_BUILD_DIR:-build-fuzz}"
generator=()
command -v ninja >/dev/null 2>&1 && generator=(-G Ninja)

if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S . -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
    -DQS_BUILD_FUZZERS=ON -DQS_BUILD_APP=OFF -DQS_BUILD_TESTS=OFF
fi
cmake --build "$build" -j"$(nproc)" --target "${targets[@]}"

seeds() {  # target -> seed files
  local f
  case "$1" in
    layout_fuzzer)
      printf '%s\n' assets/example/*.layout.json assets/bad/*.layout.json fuzz/corpus/layout/*
      ;;
    mesh_fuzzer)
      for f in assets/bad/* fuzz/corpus/mesh/* fuzz/corpus/quads/*; do
        case "$f" in *.json | *README*) ;; *) echo "$f" ;; esac
      done
      ;;
    quads_fuzzer) printf '%s\n' fuzz/corpus/quads/* assets/bad/*.obj assets/bad/*.off ;;
  esac
}

export ASAN_OPTIONS="detect_leaks=1:allocator_may_return_null=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
mkdir -p "$build/artifacts"
failed=()
for t in "${targets[@]}"; do
  corpus="$build/corpus/$t"
  mkdir -p "$corpus"
  # shellcheck disable=SC2046
  cp -n $(seeds "$t") "$corpus/" 2>/dev/null || true
  log="$build/artifacts/$t.log"
  echo "fuzz: $t for $seconds s (log: $log)"
  if "$build/fuzz/$t" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    -max_len=8192 -print_final_stats=1 -artifact_prefix="$build/artifacts/$t-" \
    "$corpus" >"$log" 2>&1; then
    execs=$(grep -o 'number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
    echo "fuzz: $t ok, $execs executions"
  else
    echo "fuzz: $t FAILED:" >&2
    grep -E 'ERROR|SUMMARY|fuzz:|Test unit written|deadly signal' "$log" | head -20 >&2 || true
    failed+=("$t")
  fi
done
if [ ${#failed[@]} -ne 0 ]; then
  echo "fuzz: failures in ${failed[*]}" >&2
  exit 1
fi
echo "fuzz: all targets ran $seconds s without a finding"
