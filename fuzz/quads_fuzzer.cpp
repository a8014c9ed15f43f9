// Fuzz target: import-quads on small quad meshes read as OFF or OBJ text (first byte: 'O' or
// '#'/'v' style inputs are tried as both). Base complex extraction, the split of non-quad
// faces and the layout on the triangulation must refuse bad input with InvalidInputError only,
// and an import that succeeds must give a valid layout.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/import/quad_import.h"
#include "core/layout/validate.h"
#include "core/mesh/mesh_io.h"
#include "fuzz/fuzz_common.h"

namespace {

constexpr int kMaxFaces = 400;  // keep each execution fast

void import_file(const std::string& path, bool all_edges) {
  qs::PolyMesh quads;
  try {
    qs::MeshReport report;
    quads = qs::load_poly_mesh(path, &report);
  } catch (const qs::InvalidInputError&) {
    return;
  }
  if (quads.n_faces() > kMaxFaces) return;
  qs::QuadImportOptions options;
  options.all_edges = all_edges;
  qs::QuadImportResult result;
  try {
    result = qs::import_quads(quads, nullptr, options);
  } catch (const qs::InvalidInputError&) {
    return;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz: import_quads threw a non-input error: %s\n", e.what());
    std::abort();
  }
  const qs::ValidationResult v = qs::validate_layout(result.mesh, result.layout);
  if (!v.valid()) {
    std::fprintf(stderr, "fuzz: import_quads (all_edges=%d) gave an invalid layout:\n", all_edges);
    for (const auto& issue : v.issues)
      std::fprintf(stderr, "  %s\n", qs::format_issue(issue).c_str());
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 16384) return 0;
  for (const char* ext : {".off", ".obj"}) {
    const std::string path = qs::fuzz::write_temp(data, size, ext);
    import_file(path, false);
    import_file(path, true);
  }
  return 0;
}
