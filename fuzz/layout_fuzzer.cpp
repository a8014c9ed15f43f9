// Fuzz target: layout JSON reader and validator on a fixed mesh (assets/example/ellipsoid.obj).
// parse_layout_json may refuse the text with InvalidInputError; validate_layout must never
// throw; a valid layout must give a topology; a parsed layout must serialize and read back to
// the same text.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/layout/layout.h"
#include "core/layout/layout_io.h"
#include "core/layout/validate.h"
#include "core/mesh/mesh_io.h"
#include "fuzz/fuzz_common.h"

namespace {

const qs::TriMesh& fixed_mesh() {
  static const qs::TriMesh mesh = qs::load_mesh(QS_ASSETS_DIR "/example/ellipsoid.obj");
  return mesh;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const qs::TriMesh& mesh = fixed_mesh();
  const std::string text(reinterpret_cast<const char*>(data), size);
  qs::Layout layout;
  try {
    layout = qs::parse_layout_json(text, "fuzz.layout.json");
  } catch (const qs::InvalidInputError&) {
    return 0;
  }
  qs::fuzz::expect_clean("layout_to_json round trip", [&] {
    const std::string once = qs::layout_to_json(layout);
    const std::string twice = qs::layout_to_json(qs::parse_layout_json(once, "round-trip"));
    if (once != twice) {
      std::fprintf(stderr, "fuzz: layout_to_json does not round-trip\n%s\n---\n%s\n", once.c_str(),
                   twice.c_str());
      std::abort();
    }
  });
  try {
    const qs::ValidationResult result = qs::validate_layout(mesh, layout);
    for (const auto& issue : result.issues) (void)qs::format_issue(issue);
    if (result.valid()) (void)qs::build_topology(mesh, layout);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz: validate_layout/build_topology threw: %s\n", e.what());
    std::abort();
  }
  return 0;
}
