#!/usr/bin/env bash
# Builds QuadSketch and runs the whole test suite with CTest, then the outcome tests (label
# "outcome") a second time on inputs jittered by 1e-9 of their bounding-box diagonal
# (QS_TEST_JITTER, tests/jitter.h): an outcome that flips under such a jitter was a trajectory.
# Tests that need ../shared/data (real meshes) skip with a message when it is absent.
# Extra arguments go to both ctest runs (e.g. -R Cli).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
export LIBGL_ALWAYS_SOFTWARE=1
ctest --test-dir build --output-on-failure -j"$(nproc)" "$@"
echo "test.sh: the outcome tests again on jittered inputs (QS_TEST_JITTER=1e-9)"
QS_TEST_JITTER=1e-9 ctest --test-dir build --output-on-failure -j"$(nproc)" -L outcome "$@"
