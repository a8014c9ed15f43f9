# Quad mesh exports (issues #8, #44) read by an independent reader: `assimp info` on quads.obj and
# layout_curves.obj of the bundled example (raw import: quads stay polygons; every line segment
# of every arc read, one mesh per arc group). Skipped (77) when assimp is not on PATH (Debian:
# assimp-utils, listed in scripts/install-deps.sh). Included by tests/CMakeLists.txt.

# quads_test runs the command line too: build it first.
if(TARGET quads_test AND TARGET quadsketch-cli)
  add_dependencies(quads_test quadsketch-cli)
endif()
if(NOT TARGET quadsketch-cli)
  return()
endif()

find_program(QS_SH sh)
if(NOT QS_SH)
  return()
endif()
set(QS_QUADS_ASSIMP_DIR ${CMAKE_CURRENT_BINARY_DIR}/quads_assimp)
add_test(NAME quads_assimp_info
  COMMAND ${QS_SH} -c [=[
set -u
command -v assimp >/dev/null 2>&1 || { echo "assimp not on PATH: skipped"; exit 77; }
rm -rf "$4" && mkdir -p "$4" || exit 1
"$1" -q optimize --mesh "$2" --layout "$3" --out "$4" --no-node-opt --quad-size 0.1 || exit 1
for f in quads.obj layout_curves.obj; do
  assimp info "$4/$f" -r > "$4/$f.assimp.txt" 2>&1 || { cat "$4/$f.assimp.txt"; exit 1; }
done
want=$(grep -c '^f ' "$4/quads.obj")
got=$(sed -n 's/^ *Faces: *\([0-9][0-9]*\).*/\1/p' "$4/quads.obj.assimp.txt" | head -n 1)
cat "$4/quads.obj.assimp.txt"
[ "$got" = "$want" ] || { echo "assimp reads $got faces, quads.obj has $want"; exit 1; }
want=$(grep -c '^g patch_' "$4/quads.obj")
got=$(sed -n 's/^ *Meshes: *\([0-9][0-9]*\).*/\1/p' "$4/quads.obj.assimp.txt" | head -n 1)
[ "$got" = "$want" ] || { echo "assimp reads $got groups, quads.obj has $want"; exit 1; }
grep -q 'line' "$4/layout_curves.obj.assimp.txt" || { echo "no polylines in layout_curves.obj"; exit 1; }
# Every arc segment read (one 2-vertex l record per segment), one mesh per arc group.
cat "$4/layout_curves.obj.assimp.txt"
want=$(awk '$1 == "l" { n += NF - 2 } END { print n + 0 }' "$4/layout_curves.obj")
got=$(sed -n 's/^ *[0-9][0-9]* (arc_[0-9]*): \[[0-9]* \/ [0-9]* \/ \([0-9]*\) | line\]$/\1/p' "$4/layout_curves.obj.assimp.txt" | awk '{ n += $1 } END { print n + 0 }')
[ "$want" -gt 0 ] && [ "$got" = "$want" ] || { echo "assimp reads $got line segments, layout_curves.obj has $want"; exit 1; }
want=$(grep -c '^g arc_' "$4/layout_curves.obj")
got=$(grep -c '^ *[0-9][0-9]* (arc_[0-9]*): .* line\]$' "$4/layout_curves.obj.assimp.txt")
[ "$got" = "$want" ] || { echo "assimp reads $got arcs, layout_curves.obj has $want"; exit 1; }
bad=$(awk '$1 == "l" && NF != 3' "$4/layout_curves.obj" | wc -l)
[ "$bad" -eq 0 ] || { echo "$bad l records with other than 2 vertices"; exit 1; }
]=] quads_assimp_info
    $<TARGET_FILE:quadsketch-cli>
    ${QS_ASSETS_DIR}/example/ellipsoid.obj
    ${QS_ASSETS_DIR}/example/ellipsoid.layout.json
    ${QS_QUADS_ASSIMP_DIR})
set_tests_properties(quads_assimp_info PROPERTIES SKIP_RETURN_CODE 77 TIMEOUT 300)
