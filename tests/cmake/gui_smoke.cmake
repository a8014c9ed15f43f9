# GUI tests: the layout editor unit and the editor's state (GL-free app code), the editor end to
# end under Xvfb (gui_app_test, driven by --script), and smoke tests of the quadsketch
# executable (screenshots, exit codes). Included by tests/CMakeLists.txt.

# layout_editor_test.cpp is picked up by the *_test.cpp glob, which links qs_core only: add
# the app sources it exercises (all GL-free).
if(TARGET layout_editor_test)
  target_sources(layout_editor_test PRIVATE
    ${PROJECT_SOURCE_DIR}/app/gui/layout_editor.cpp
    ${PROJECT_SOURCE_DIR}/app/gui/autosave.cpp
    ${PROJECT_SOURCE_DIR}/app/gui/recent_files.cpp)
endif()

# gui_job_test.cpp: the editor's worker job (GL-free) on the bundled example.
if(TARGET gui_job_test)
  target_sources(gui_job_test PRIVATE ${PROJECT_SOURCE_DIR}/app/gui/pipeline_job.cpp)
endif()

# gui_field_test.cpp: the job's field snapshot and pipeline options (GL-free), plus the glyph
# sampling of render/ when the app (and with it qs_render) is built.
if(TARGET gui_field_test)
  target_sources(gui_field_test PRIVATE ${PROJECT_SOURCE_DIR}/app/gui/pipeline_job.cpp)
  if(TARGET qs_render)
    target_link_libraries(gui_field_test PRIVATE qs_render)
    target_compile_definitions(gui_field_test PRIVATE QS_TEST_RENDER)
  endif()
endif()

# gui_frame_test.cpp: frame statistics, solver thread priority (GL-free), plus the scene-cache
# key of render/ when the app (and with it qs_render) is built.
if(TARGET gui_frame_test)
  target_sources(gui_frame_test PRIVATE
    ${PROJECT_SOURCE_DIR}/app/gui/frame_stats.cpp
    ${PROJECT_SOURCE_DIR}/app/gui/thread_priority.cpp)
  if(TARGET qs_render)
    target_link_libraries(gui_frame_test PRIVATE qs_render)
    target_compile_definitions(gui_frame_test PRIVATE QS_TEST_RENDER)
  endif()
endif()

# gui_editor_test.cpp: the editor's state (GL-free) with its real pipeline job; with the render
# library also the key map, the camera views and the state dump.
if(TARGET gui_editor_test)
  foreach(src editor job_control pipeline_job autosave recent_files layout_editor document
      thread_priority file_browser plot_ticks ui_text sketch_edits symmetry_state field_hints)
    target_sources(gui_editor_test PRIVATE ${PROJECT_SOURCE_DIR}/app/gui/${src}.cpp)
  endforeach()
  if(TARGET qs_render)
    target_sources(gui_editor_test PRIVATE ${PROJECT_SOURCE_DIR}/app/gui/actions.cpp
      ${PROJECT_SOURCE_DIR}/app/gui/tools.cpp ${PROJECT_SOURCE_DIR}/app/gui/state_dump.cpp)
    target_link_libraries(gui_editor_test PRIVATE qs_render)
    target_compile_definitions(gui_editor_test PRIVATE QS_TEST_RENDER)
  endif()
endif()

# gui_sketch_test.cpp: mirrored sketching, edge-loop edits and field hints through the editor's
# state (GL-free); with the render library also the mirror plane's section curve.
if(TARGET gui_sketch_test)
  foreach(src editor job_control pipeline_job autosave recent_files layout_editor document
      thread_priority file_browser plot_ticks ui_text sketch_edits symmetry_state field_hints)
    target_sources(gui_sketch_test PRIVATE ${PROJECT_SOURCE_DIR}/app/gui/${src}.cpp)
  endforeach()
  if(TARGET qs_render)
    target_link_libraries(gui_sketch_test PRIVATE qs_render)
    target_compile_definitions(gui_sketch_test PRIVATE QS_TEST_RENDER)
  endif()
endif()

# gui_drag_test.cpp: live solves while a node is dragged, through the editor's state (GL-free).
if(TARGET gui_drag_test)
  foreach(src editor job_control pipeline_job autosave recent_files layout_editor document
      thread_priority file_browser plot_ticks ui_text sketch_edits symmetry_state field_hints)
    target_sources(gui_drag_test PRIVATE ${PROJECT_SOURCE_DIR}/app/gui/${src}.cpp)
  endforeach()
endif()

if(NOT QS_BUILD_APP)
  return()
endif()

# gui_app_test.cpp: the editor end to end under Xvfb, driven by --script, checked on its
# --state-json dumps.
if(TARGET gui_app_test)
  add_dependencies(gui_app_test quadsketch)
  target_compile_definitions(gui_app_test PRIVATE QS_GUI_APP="$<TARGET_FILE:quadsketch>")
endif()

add_executable(gui_smoke_check ${CMAKE_CURRENT_LIST_DIR}/../gui_smoke_check.cpp)
target_link_libraries(gui_smoke_check PRIVATE PkgConfig::IMGUI)  # brings libstb (stb_image)
add_dependencies(gui_smoke_check quadsketch)

set(QS_GUI_SMOKE_DIR ${CMAKE_CURRENT_BINARY_DIR}/gui_smoke)
file(MAKE_DIRECTORY ${QS_GUI_SMOKE_DIR})
# Keep the tests away from the user's ~/.config and ~/.cache.
set(QS_GUI_TEST_ENV
  "LIBGL_ALWAYS_SOFTWARE=1"
  "QS_AUTOSAVE_DIR=${QS_GUI_SMOKE_DIR}/autosave"
  "XDG_CONFIG_HOME=${QS_GUI_SMOKE_DIR}/config")

# Screenshot of the bundled example after 5 frames; skipped (77) without xvfb-run.
add_test(NAME gui_smoke_screenshot
  COMMAND gui_smoke_check screenshot --app $<TARGET_FILE:quadsketch>
    --mesh ${QS_ASSETS_DIR}/example/ellipsoid.obj
    --layout ${QS_ASSETS_DIR}/example/ellipsoid.layout.json
    --out ${QS_GUI_SMOKE_DIR}/example.png --width 1280 --height 800)
set_tests_properties(gui_smoke_screenshot PROPERTIES
  SKIP_RETURN_CODE 77 TIMEOUT 120 ENVIRONMENT "${QS_GUI_TEST_ENV}")

# The stroke tool and the cross-field glyph layer: the example layout without arc 10, the arc
# drawn back with a scripted free-hand stroke (--stroke-vertices, through the old path), then a
# run with the glyph layer on. Expected in the picture: the selected stroke arc's gold underlay
# and the blue field crosses. string(JSON) needs CMake 3.19.
if(CMAKE_VERSION VERSION_GREATER_EQUAL 3.19)
  file(READ ${QS_ASSETS_DIR}/example/ellipsoid.layout.json qs_example_layout)
  string(JSON qs_arc10_id GET "${qs_example_layout}" arcs 10 id)
  if(qs_arc10_id EQUAL 10)
    string(JSON qs_minus_arc10 REMOVE "${qs_example_layout}" arcs 10)
    file(WRITE ${QS_GUI_SMOKE_DIR}/ellipsoid_minus_arc10.layout.json "${qs_minus_arc10}")
    add_test(NAME gui_smoke_stroke_and_field
      COMMAND gui_smoke_check screenshot --app $<TARGET_FILE:quadsketch>
        --mesh ${QS_ASSETS_DIR}/example/ellipsoid.obj
        --layout ${QS_GUI_SMOKE_DIR}/ellipsoid_minus_arc10.layout.json
        --out ${QS_GUI_SMOKE_DIR}/stroke_field.png --width 1280 --height 800
        --expect-colors "255,219,38,150;102,31,158,1500"
        -- --stroke-vertices 464,466,844,835,837,839,841,842 --show-field --run)
    set_tests_properties(gui_smoke_stroke_and_field PROPERTIES
      SKIP_RETURN_CODE 77 TIMEOUT 300 ENVIRONMENT "${QS_GUI_TEST_ENV}")
  endif()
endif()

# Redraw on demand while the camera moves: every frame re-renders the scene (at the reduced
# motion resolution), and the picture must still show the surface with its wireframe and arcs.
add_test(NAME gui_smoke_orbit
  COMMAND gui_smoke_check screenshot --app $<TARGET_FILE:quadsketch>
    --mesh ${QS_ASSETS_DIR}/example/ellipsoid.obj
    --layout ${QS_ASSETS_DIR}/example/ellipsoid.layout.json
    --out ${QS_GUI_SMOKE_DIR}/orbit.png --width 1280 --height 800
    -- --bench-orbit)
set_tests_properties(gui_smoke_orbit PROPERTIES
  SKIP_RETURN_CODE 77 TIMEOUT 120 ENVIRONMENT "${QS_GUI_TEST_ENV}")

# Redraw on demand, end to end (the app's own bench line): with a still camera the scene is
# rendered during the warm-up only, so none of the timed frames re-renders it; orbiting
# re-renders every timed frame. Needs xvfb-run (not registered without it).
find_program(QS_XVFB_RUN xvfb-run)
if(QS_XVFB_RUN)
  foreach(qs_case still orbit)
    if(qs_case STREQUAL "orbit")
      set(qs_extra --bench-orbit)
      set(qs_expect "scene rendered in 20 frames")
    else()
      set(qs_extra)
      set(qs_expect "scene rendered in 0 frames")
    endif()
    add_test(NAME gui_bench_scene_cache_${qs_case}
      COMMAND ${QS_XVFB_RUN} -a -s "-screen 0 1280x800x24" $<TARGET_FILE:quadsketch>
        --mesh ${QS_ASSETS_DIR}/example/ellipsoid.obj
        --layout ${QS_ASSETS_DIR}/example/ellipsoid.layout.json
        --bench-frames 20 ${qs_extra} --quit)
    set_tests_properties(gui_bench_scene_cache_${qs_case} PROPERTIES
      PASS_REGULAR_EXPRESSION "bench: 20 frames.*${qs_expect}.*scene cache on"
      TIMEOUT 120 ENVIRONMENT "${QS_GUI_TEST_ENV}")
  endforeach()
endif()

# Bad input with --quit: message on stderr, exit code 2, no crash (and no display needed).
add_test(NAME gui_bad_mesh_exits_2
  COMMAND gui_smoke_check exit-code --app $<TARGET_FILE:quadsketch> --expect 2 --
    --mesh ${QS_ASSETS_DIR}/bad/nonmanifold_edge.obj --quit)
add_test(NAME gui_missing_mesh_exits_2
  COMMAND gui_smoke_check exit-code --app $<TARGET_FILE:quadsketch> --expect 2 --
    --mesh ${QS_GUI_SMOKE_DIR}/does_not_exist.obj --quit)
# A NaN or out-of-range numeric option: exit code 1 with the option named.
add_test(NAME gui_nan_option_exits_1
  COMMAND gui_smoke_check exit-code --app $<TARGET_FILE:quadsketch> --expect 1 --
    --motion-resolution nan --quit)
set_tests_properties(gui_bad_mesh_exits_2 gui_missing_mesh_exits_2 gui_nan_option_exits_1
  PROPERTIES TIMEOUT 60 ENVIRONMENT "${QS_GUI_TEST_ENV}")
