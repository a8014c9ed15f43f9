# Sanitizer and fuzzer builds (issue #10). Included from the top-level CMakeLists.txt before
# the subdirectories, so the flags apply to every target of the project (not to the system
# libraries: OpenMesh, CHOLMOD and BLAS are used as installed).
#
#   -DQS_SANITIZE=address   AddressSanitizer + UndefinedBehaviorSanitizer (any UB aborts)
#   -DQS_SANITIZE=thread    ThreadSanitizer
#   -DQS_BUILD_FUZZERS=ON   libFuzzer targets of fuzz/ (clang only; implies ASan + UBSan)
#
# scripts/ci-sanitizers.sh and scripts/fuzz.sh drive these builds.

set(QS_SANITIZE "" CACHE STRING "Sanitizer build: empty, address (ASan+UBSan) or thread (TSan)")
set_property(CACHE QS_SANITIZE PROPERTY STRINGS "" address thread)
option(QS_BUILD_FUZZERS "Build the libFuzzer targets of fuzz/ (needs clang)" OFF)

if(QS_BUILD_FUZZERS)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "QS_BUILD_FUZZERS needs clang (-DCMAKE_CXX_COMPILER=clang++ "
                        "-DCMAKE_C_COMPILER=clang; Debian: clang libclang-rt-14-dev)")
  endif()
  if(QS_SANITIZE STREQUAL "thread")
    message(FATAL_ERROR "QS_BUILD_FUZZERS runs with ASan+UBSan; do not combine with thread")
  endif()
  set(QS_SANITIZE address CACHE STRING "" FORCE)
  # Coverage instrumentation everywhere; only the fuzz targets link libFuzzer's main.
  add_compile_options(-fsanitize=fuzzer-no-link)
endif()

if(QS_SANITIZE STREQUAL "address")
  set(_qs_san_flags -fsanitize=address,undefined -fno-sanitize-recover=undefined)
elseif(QS_SANITIZE STREQUAL "thread")
  set(_qs_san_flags -fsanitize=thread)
elseif(NOT QS_SANITIZE STREQUAL "")
  message(FATAL_ERROR "QS_SANITIZE must be empty, 'address' or 'thread' (got '${QS_SANITIZE}')")
endif()

# ASan builds compile at -O1 (the level the sanitizer's documentation recommends): GCC's
# ASan+UBSan instrumentation at -O2 made the CI's sanitizer build three times the Release build.
set(QS_SANITIZER_OPT_FLAGS "-O1" CACHE STRING "Optimization flags of an ASan build (Release)")
if(QS_SANITIZE STREQUAL "address")
  set(CMAKE_CXX_FLAGS_RELEASE "${QS_SANITIZER_OPT_FLAGS} -DNDEBUG")
  set(CMAKE_C_FLAGS_RELEASE "${QS_SANITIZER_OPT_FLAGS} -DNDEBUG")
endif()

if(_qs_san_flags)
  message(STATUS "QuadSketch: sanitizers ${_qs_san_flags}")
  # -g1: line tables for readable reports without the full debug-info build cost.
  add_compile_options(${_qs_san_flags} -fno-omit-frame-pointer -g1)
  add_link_options(${_qs_san_flags})
endif()

if(QS_BUILD_FUZZERS)
  add_subdirectory(${CMAKE_CURRENT_LIST_DIR}/../fuzz ${CMAKE_BINARY_DIR}/fuzz)
endif()
