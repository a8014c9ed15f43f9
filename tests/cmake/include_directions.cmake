# Include directions of core/ (docs/design.md, "Code layers"): scripts/check_includes.py fails
# with file:line when a folder of core/ includes a higher layer, or a core file includes app/,
# render/ or OpenGL/GUI headers. Included by tests/CMakeLists.txt.
find_package(Python3 COMPONENTS Interpreter)
if(Python3_Interpreter_FOUND)
  add_test(NAME include_directions
    COMMAND ${Python3_EXECUTABLE} ${PROJECT_SOURCE_DIR}/scripts/check_includes.py
            --root ${PROJECT_SOURCE_DIR})
else()
  message(STATUS "python3 not found: the include_directions test is not registered")
endif()
