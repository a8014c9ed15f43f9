// The open files: mesh, layout (through the editor with its undo history), their paths and
// the last validation. GL-free; loading never throws, errors come back as text for the UI.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "app/gui/layout_editor.h"
#include "core/layout/validate.h"
#include "core/mesh/mesh.h"
#include "core/mesh/mesh_io.h"

namespace qs::app {

struct Document {
  //! Shared (read-only) with the pipeline worker; replaced, never modified, on load.
  std::shared_ptr<const TriMesh> mesh;
  MeshReport report;
  std::string mesh_path;
  std::string layout_path;  //!< "" for a new layout
  std::uint64_t mesh_version = 0;
  LayoutEditor editor;
  bool dirty = false;  //!< edited since the last load/save

  ValidationResult validation;
  std::uint64_t validated_layout_version = ~0ull;

  //! Loads a mesh and starts an empty layout on it. On failure the document is unchanged
  //! and the returned text lists every problem; "" on success.
  std::string open_mesh(const std::string& path);
  //! Loads a layout onto the current mesh (same failure contract).
  std::string open_layout(const std::string& path);
  //! Saves the layout (atomically) to \p path (or layout_path when empty).
  std::string save_layout_to(const std::string& path = {});
  //! Re-validates if the layout changed since the last call. Returns true when it did.
  bool refresh_validation();

  //! Bounding sphere of the mesh.
  void bounds(Vec3& center, double& radius) const;
};

}  // namespace qs::app
