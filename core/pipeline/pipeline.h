// The QuadSketch pipeline, stage by stage (mesh → layout → field → …), shared by the CLI and
// the editor's worker thread.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/field/cross_field.h"
#include "core/layout/layout.h"
#include "core/layout/validate.h"
#include "core/mesh/geometry.h"
#include "core/mesh/mesh.h"
#include "core/mesh/mesh_io.h"

namespace qs {

struct PipelineOptions {
  CrossFieldOptions field;
};

//! A singular vertex of the cross field.
struct Singularity {
  int vertex = -1;
  int quarter_index = 0;  //!< index in quarter turns (+1 for a valence-3 node)
};

//! Holds the mesh, the layout and every stage's state. Not thread-safe: one owner (the CLI or
//! the worker thread).
class Pipeline {
 public:
  //! \throw InvalidInputError when the layout is invalid (the message lists every error).
  Pipeline(TriMesh mesh, Layout layout, PipelineOptions options = {});
  ~Pipeline();

  const TriMesh& mesh() const { return mesh_; }
  const Layout& layout() const { return layout_; }
  const LayoutTopology& topology() const { return topology_; }
  const GeometryCache& geometry() const { return geometry_; }
  const ValidationResult& validation() const { return validation_; }

  //! Computes (or re-solves) the cross field. \throw TopologyError, SolverError.
  const CrossField& compute_field();
  const CrossField* field() const;
  //! Singular vertices measured on the current field (interior vertices only).
  std::vector<Singularity> singularities() const;

 private:
  TriMesh mesh_;
  Layout layout_;
  PipelineOptions options_;
  ValidationResult validation_;
  LayoutTopology topology_;
  GeometryCache geometry_;
  std::unique_ptr<CrossFieldSolver> field_solver_;
};

//! Writes field.txt: one line per face, "x y z", the first field direction (unit, in-plane).
void write_field_txt(const GeometryCache& geometry, const std::vector<double>& theta,
                     const std::string& path);

}  // namespace qs
