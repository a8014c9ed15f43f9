# Finds every dependency. All of them come from Debian 12 packages (scripts/install-deps.sh).
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(OpenMesh REQUIRED) # Debian's OpenMesh has no version file: no version here.
find_package(nlohmann_json 3 REQUIRED)
find_package(CLI11 REQUIRED)
find_package(Threads REQUIRED)

# CHOLMOD (SuiteSparse 5.x) has no CMake config and no pkg-config file on Debian 12.
find_package(CHOLMOD CONFIG QUIET)
if(NOT TARGET SuiteSparse::CHOLMOD)
  find_path(CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse REQUIRED)
  find_library(CHOLMOD_LIBRARY cholmod REQUIRED)
  add_library(SuiteSparse::CHOLMOD UNKNOWN IMPORTED)
  set_target_properties(SuiteSparse::CHOLMOD PROPERTIES
    IMPORTED_LOCATION "${CHOLMOD_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${CHOLMOD_INCLUDE_DIR}")
endif()

if(QS_BUILD_APP)
  find_package(glfw3 3.3 REQUIRED)
  find_package(glm REQUIRED)
  set(OpenGL_GL_PREFERENCE GLVND)
  find_package(OpenGL REQUIRED COMPONENTS OpenGL EGL)
  find_package(PkgConfig REQUIRED)
  # Debian's libimgui-dev: static library with the GLFW and OpenGL3 backends, pkg-config only.
  pkg_check_modules(IMGUI REQUIRED IMPORTED_TARGET imgui)
endif()

if(QS_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
