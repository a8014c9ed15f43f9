// Pins changed while the node optimization runs (NodeOptimizer::set_pinned): an arc pinned
// between two units keeps its route and its end nodes (vertex and position) until the end,
// fold-over removal included; wrong flag counts are refused.
#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

#include "core/nodeopt/optimizer.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

struct ArcState {
  std::vector<int> path;
  std::vector<int> end_vertices;
  std::vector<Vec3> end_positions;
};

ArcState arc_state(const TriMesh& mesh, const Layout& layout, int a) {
  ArcState s;
  const LayoutArc& arc = layout.arcs[a];
  s.path = arc.path;
  for (int id : {arc.from, arc.to}) {
    const int n = layout.node_index(id);
    if (n < 0) continue;
    const int v = layout.nodes[n].vertex;
    s.end_vertices.push_back(v);
    s.end_positions.push_back(mesh.point(mesh.vertex_handle(v)));
  }
  return s;
}

bool same(const ArcState& a, const ArcState& b) {
  return a.path == b.path && a.end_vertices == b.end_vertices && a.end_positions == b.end_positions;
}

NodeOptOptions few_steps() {
  NodeOptOptions no;
  no.descent.max_steps = 8;
  return no;
}

TEST(NodeOptimizerPins, ArcPinnedDuringTheRunKeepsItsRouteAndEnds) {
  const auto in = test::cube_sphere(8);
  const Layout start = test::displace_nodes(in.mesh, in.layout, 2, 3);

  // Without the pin: after the first unit, some arc's route or end nodes still change.
  NodeOptimizer free_run(in.mesh, start, PipelineOptions{}, few_steps());
  ASSERT_TRUE(free_run.step());
  const TriMesh mesh1 = free_run.mesh();
  const Layout layout1 = free_run.layout();
  while (free_run.step()) {
  }
  const NodeOptResult free_result = free_run.finish();
  int arc = -1;
  for (int a = 0; a < int(layout1.arcs.size()) && arc < 0; ++a)
    if (!same(arc_state(mesh1, layout1, a), arc_state(free_result.mesh, free_result.layout, a)))
      arc = a;
  ASSERT_GE(arc, 0) << "the case should move some arc after its first step";
  const ArcState held = arc_state(mesh1, layout1, arc);

  // The same run with that arc pinned after the first unit: it stays as it was then.
  NodeOptimizer pinned_run(in.mesh, start, PipelineOptions{}, few_steps());
  ASSERT_TRUE(pinned_run.step());
  ASSERT_TRUE(same(arc_state(pinned_run.mesh(), pinned_run.layout(), arc), held));
  std::vector<char> node_flags(pinned_run.layout().nodes.size(), 0);
  std::vector<char> arc_flags(pinned_run.layout().arcs.size(), 0);
  arc_flags[arc] = 1;
  pinned_run.set_pinned(node_flags, arc_flags);
  EXPECT_TRUE(pinned_run.layout().arcs[arc].pinned);
  int units = 1;
  while (pinned_run.step()) {
    ++units;
    EXPECT_TRUE(same(arc_state(pinned_run.mesh(), pinned_run.layout(), arc), held))
        << "arc " << arc << " changed in unit " << units;
  }
  const NodeOptResult r = pinned_run.finish();
  EXPECT_TRUE(same(arc_state(r.mesh, r.layout, arc), held));
  EXPECT_TRUE(r.layout.arcs[arc].pinned);
  EXPECT_LT(r.E_final, r.E_init);  // the other nodes still optimize
}

TEST(NodeOptimizerPins, WrongFlagCountsAreRefused) {
  const auto in = test::cube_sphere(6);
  NodeOptimizer opt(in.mesh, in.layout, PipelineOptions{}, few_steps());
  const std::vector<char> nodes(in.layout.nodes.size(), 0);
  EXPECT_THROW(opt.set_pinned(std::vector<char>(nodes.size() + 1, 0)), std::invalid_argument);
  EXPECT_THROW(opt.set_pinned(nodes, std::vector<char>(in.layout.arcs.size() - 1, 0)),
               std::invalid_argument);
  EXPECT_NO_THROW(opt.set_pinned(nodes));  // arcs keep their flags
  EXPECT_NO_THROW(opt.set_pinned(nodes, std::vector<char>(in.layout.arcs.size(), 1)));
  for (const auto& a : opt.layout().arcs) EXPECT_TRUE(a.pinned);
}

}  // namespace
}  // namespace qs
