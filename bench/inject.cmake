# Used by scripts/bench.sh only while the top-level CMakeLists.txt lacks add_subdirectory(bench):
# passed as CMAKE_PROJECT_INCLUDE, it defers reading bench/CMakeLists.txt to the end of the
# top-level file, after qs_core and qs_test_support exist (deferred arguments are expanded when
# the call runs, hence the variable).
set(QS_BENCH_INJECTED_LIST "${CMAKE_CURRENT_LIST_DIR}/CMakeLists.txt")
cmake_language(DEFER DIRECTORY ${CMAKE_SOURCE_DIR} CALL include ${QS_BENCH_INJECTED_LIST})
