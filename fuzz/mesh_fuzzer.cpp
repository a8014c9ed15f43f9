// Fuzz target: the mesh readers and checks. Each input is written to a temporary file with
// every supported extension (.obj, .off, .ply, .stl) and loaded as a triangle mesh and as a
// polygon mesh. Refusing an input must be an InvalidInputError; nothing else may escape.
#include <cstdint>
#include <string>

#include "core/mesh/mesh_io.h"
#include "fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  for (const char* ext : {".obj", ".off", ".ply", ".stl"}) {
    const std::string path = qs::fuzz::write_temp(data, size, ext);
    qs::fuzz::expect_clean("load_mesh", [&] {
      qs::MeshReport report;
      (void)qs::load_mesh(path, &report);
    });
    qs::fuzz::expect_clean("load_poly_mesh", [&] {
      qs::MeshReport report;
      (void)qs::load_poly_mesh(path, &report);
    });
  }
  return 0;
}
