# Tests of the Python helpers (tests/python/*_test.py, unittest), e.g. the benchmark report
# that regenerates docs/benchmarks.md. Included by tests/CMakeLists.txt.
find_package(Python3 COMPONENTS Interpreter)
if(Python3_Interpreter_FOUND)
  file(GLOB QS_PYTHON_TESTS CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/python/*_test.py)
  foreach(script ${QS_PYTHON_TESTS})
    get_filename_component(name ${script} NAME_WE)
    add_test(NAME Python.${name} COMMAND ${Python3_EXECUTABLE} ${script})
  endforeach()
else()
  message(STATUS "python3 not found: the tests of tests/python are not registered")
endif()
