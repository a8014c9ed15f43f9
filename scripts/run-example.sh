#!/usr/bin/env bash
# Runs the main job on the bundled example (assets/example): the GUI editor when a display is
# available, otherwise the headless pipeline, writing its results to out/example/.
set -euo pipefail
cd "$(dirname "$0")/.."
mesh=assets/example/ellipsoid.obj
layout=assets/example/ellipsoid.layout.json
if [ -n "${DISPLAY:-}${WAYLAND_DISPLAY:-}" ] && [ -x build/app/quadsketch ]; then
  echo "run-example: opening the editor on $mesh"
  exec build/app/quadsketch --mesh "$mesh" --layout "$layout"
fi
out=out/example
mkdir -p "$out"
echo "run-example: no display; running the headless pipeline on $mesh"
build/app/quadsketch-cli optimize --mesh "$mesh" --layout "$layout" --out "$out"
echo "run-example: results written to $out/ (report.json, param.obj, field.txt, layout.json)"
