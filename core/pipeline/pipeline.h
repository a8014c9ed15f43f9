// The QuadSketch pipeline, stage by stage (mesh → layout → field → …), shared by the CLI and
// the editor's worker thread.
#pragma once

#include <future>
#include <memory>
#include <string>
#include <vector>

#include "core/extract/metrics.h"
#include "core/extract/quads.h"
#include "core/extract/tracing.h"
#include "core/field/cross_field.h"
#include "core/layout/layout.h"
#include "core/layout/validate.h"
#include "core/mesh/geometry.h"
#include "core/mesh/mesh.h"
#include "core/mesh/mesh_io.h"
#include "core/param/parameterization.h"

namespace qs {

struct PipelineOptions {
  CrossFieldOptions field;
  ParamOptions param;
  //! With ParamOptions::second_thread, work that runs beside the main thread's only on meshes
  //! of at least this many faces: a continued pipeline's parameterization set-up while the field
  //! is solved (Pipeline(mesh, layout, previous)) and the node optimizer's Voronoi cells while
  //! the gradients are computed. Smaller meshes do it in sequence: there a thread per re-layout
  //! costs more than it overlaps.
  int second_thread_min_faces = 10000;
  //! With ParamOptions::second_thread on meshes of at least second_thread_min_faces faces, and
  //! unless ParamOptions::vertex_order is given: the Pipeline orders the mesh's vertices by
  //! nested dissection (vertex_nested_dissection) on a second thread from its construction,
  //! beside the field, and its parameterization solvers (and those of the pipelines continued
  //! from it) take their fill-reducing ordering from that order (ParamOptions::vertex_order).
  //! The order depends on the connectivity only. A solver built before it is ready waits for it,
  //! so the results never depend on timing. The stage's symbolic analysis then needs no AMD
  //! ordering (its effect on the stage time: docs/benchmarks.md, "Design measurements").
  bool order_vertices = true;
};

//! Whether a Pipeline with \p options on a mesh of \p n_faces faces orders the vertices itself
//! (PipelineOptions::order_vertices).
bool pipeline_orders_vertices(const PipelineOptions& options, int n_faces);

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
  //! With \p validate false the caller guarantees a valid layout (e.g. node optimization's
  //! re-routed layouts, checked structurally by move_node_and_reroute); validation() is empty.
  Pipeline(TriMesh mesh, Layout layout, PipelineOptions options = {}, bool validate = true);
  //! A Pipeline for \p layout on \p previous's mesh connectivity after nodes moved to other
  //! vertices (node optimization; same options, \p layout not validated: re-routing keeps the
  //! structure). It reuses \p previous's work instead of starting over:
  //! - the geometry continues \p previous's (κ continued, as update_positions);
  //! - the cross field is a copy of \p previous's solver (sharing its factorizations) re-solved
  //!   for the new layout by CrossFieldSolver::update_layout: the constraints of this geometry
  //!   and layout (curvature recomputed), new period jumps, every constraint back in force, warm
  //!   start and drop passes as in a fresh construction. No factorization unless a drop pass
  //!   needs one or the constraint set changed (then one numeric factorization with the kept
  //!   analysis). θ equals a fresh Pipeline's up to solver round-off.
  //! The parameterization solver is built anew: its combinatorial setup and symbolic analysis
  //! on the second thread while the field is re-solved (ParamOptions::second_thread, meshes of
  //! at least PipelineOptions::second_thread_min_faces faces), kept when the new field gives the
  //! same constraint rows. Without a field in \p previous the field is
  //! built as in a fresh Pipeline. \p previous is not changed.
  //! \throw InvalidInputError when the vertex or face count differs.
  Pipeline(TriMesh mesh, Layout layout, const Pipeline& previous);
  ~Pipeline();

  const TriMesh& mesh() const { return mesh_; }
  const Layout& layout() const { return layout_; }
  const LayoutTopology& topology() const { return topology_; }
  const GeometryCache& geometry() const { return geometry_; }
  const ValidationResult& validation() const { return validation_; }

  //! Moves the mesh vertices to \p mesh's positions (same connectivity, same layout): updates
  //! the geometry in place (docs/design.md, "Continuing κ") and drops the curvature and the
  //! extraction. The field and parameterization solvers are kept (their combinatorial setup
  //! and factorization patterns do not depend on positions); call compute_parameterization()
  //! to re-solve. \throw InvalidInputError when the vertex or face count differs.
  void update_positions(const TriMesh& mesh);
  //! Gives this Pipeline its own copy of every factorization it shares with the Pipeline it
  //! was continued from (copies share them until one side factorizes): afterwards the two can
  //! be solved on different threads at the same time.
  void unshare_solvers();

  //! Computes (or re-solves) the cross field. \throw TopologyError, SolverError.
  const CrossField& compute_field();
  const CrossField* field() const;
  //! The field's solver when the field is current (compute_field), else nullptr.
  const CrossFieldSolver* field_solver() const {
    return field_current() ? field_solver_.get() : nullptr;
  }
  //! Singular vertices measured on the current field (interior vertices only).
  std::vector<Singularity> singularities() const;

  //! Computes (or re-solves) the parameterization; computes the field first if needed.
  const Parameterization& compute_parameterization();
  const Parameterization* parameterization() const;
  const ParamSolver* param_solver() const { return param_solver_.get(); }
  //! Whether the current parameterization solver was set up ahead and adopted (the reference
  //! rotation's solver of a fresh field, or the one set up beside update_layout), not built
  //! after the field.
  bool param_solver_prepared() const { return param_prepared_; }
  //! Sets ParamOptions::vertex_order for the parameterization solvers built from now on, here
  //! and in the Pipelines continued from this one (the current solver keeps its analysis).
  void set_param_vertex_order(std::shared_ptr<const std::vector<int>> order) {
    options_.param.vertex_order = std::move(order);
  }
  const PipelineOptions& options() const { return options_; }
  //! Traces the arcs on the current parameterization.
  const Extraction& extract();
  //! Metrics of the current parameterization (curvature computed once).
  ParamMetrics metrics();
  //! The layout with traced arcs, node positions and patches filled in (after extract()).
  Layout output_layout() const;

 private:
  TriMesh mesh_;
  Layout layout_;
  PipelineOptions options_;
  ValidationResult validation_;
  LayoutTopology topology_;
  GeometryCache geometry_;
  std::unique_ptr<CrossFieldSolver> field_solver_;
  bool field_layout_stale_ = false;  //!< field_solver_ is a copy still to be update_layout'ed
  //! A field solved for this pipeline's layout exists (not a copy awaiting update_layout).
  bool field_current() const { return field_solver_ && !field_layout_stale_; }
  std::unique_ptr<ParamSolver> param_solver_;
  //! The parameterization solver set up ahead by compute_field (a fresh field: the reference
  //! rotation's; a continued one: the one set up beside update_layout from the previous field),
  //! until compute_parameterization adopts or drops it.
  std::unique_ptr<ParamSolver> prepared_param_;
  bool param_prepared_ = false;  //!< param_solver_ was prepared_param_ (param_solver_prepared)
  std::unique_ptr<Extraction> extraction_;
  std::unique_ptr<Curvature> curvature_;
  //! The vertex order being computed (PipelineOptions::order_vertices) until
  //! take_vertex_order() moves it into options_.param.vertex_order; shared with the pipelines
  //! continued from this one before that.
  std::shared_future<std::shared_ptr<const std::vector<int>>> vertex_order_;
  //! Waits for vertex_order_ (if any) and sets options_.param.vertex_order from it. Called on
  //! the owner's thread before a parameterization solver is built.
  void take_vertex_order();
};

//! The quad mesh (build_quad_mesh, core/extract/quads.h) of a pipeline that has a field, a
//! parameterization and \p extraction (the result of its last extract()). For the GUI and the
//! CLI. \throw InvalidInputError when a stage is missing.
QuadMesh build_quad_mesh(const Pipeline& pipeline, const Extraction& extraction,
                         const QuadMeshOptions& options);

//! Writes param.obj: the mesh (same vertex and face order) with one texture coordinate per
//! face corner ("f v/vt"), atomically.
void write_param_obj(const TriMesh& mesh, const std::vector<std::array<double, 2>>& corner_uv,
                     const std::string& path);

//! Writes field.txt: one line per face, "x y z", the first field direction (unit, in-plane).
void write_field_txt(const GeometryCache& geometry, const std::vector<double>& theta,
                     const std::string& path);

}  // namespace qs
