#!/usr/bin/env bash
# Builds QuadSketch and runs the whole test suite with CTest.
# Tests that need ../shared/data (real meshes) skip with a message when it is absent.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
export LIBGL_ALWAYS_SOFTWARE=1
ctest --test-dir build --output-on-failure -j"$(nproc)" "$@"
