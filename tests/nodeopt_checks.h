// Checks shared by the node optimization tests (tests/nodeopt_test.cpp,
// tests/recovery_families_test.cpp): an observer that records every step, monotone descent, and
// a relocated mesh that stays on the original surface. GoogleTest assertions, header only
// (tests/fixtures.cpp is also built into the benchmarks without GoogleTest).
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "core/base/progress.h"
#include "core/mesh/geometry.h"
#include "core/mesh/mesh.h"
#include "core/nodeopt/optimizer.h"

namespace qs::test {

//! Records every step report; with QS_NODEOPT_VERBOSE set also prints it.
struct Recorder : Observer {
  std::vector<StepReport> steps;
  void on_step(const StepReport& r) override {
    steps.push_back(r);
    if (std::getenv("QS_NODEOPT_VERBOSE"))
      std::printf("  step %d %s E=%.6g accepted=%d alpha=%.4g moved=%d folds=%d\n", r.step,
                  r.phase.c_str(), r.E, r.accepted, r.step_size, r.moved_nodes, r.foldovers);
  }
};

//! Every accepted descent or hop step of \p rec lowered E (from r.E_init on), and the last one
//! is r.E_descent.
inline void expect_monotone(const NodeOptResult& r, const Recorder& rec) {
  double last = r.E_init;
  for (const auto& s : rec.steps) {
    if ((s.phase != "descent" && s.phase != "hop") || !s.accepted) continue;
    EXPECT_LE(s.E, last * (1 + 1e-12))
        << "accepted " << s.phase << " step " << s.step << " raised E";
    last = s.E;
  }
  EXPECT_NEAR(r.E_descent, last, 1e-12 * last);
}

//! The mesh stays valid: no 3D normal flipped w.r.t. \p original, each relocated vertex lies on
//! a face of its original 1-ring (so it moved at most one ring).
inline void expect_valid_mesh(const TriMesh& original, const TriMesh& mesh) {
  const GeometryCache g0 = build_geometry(original), g1 = build_geometry(mesh);
  for (int f = 0; f < g0.n_faces; ++f)
    EXPECT_GT(g0.face_normal[f] | g1.face_normal[f], 0.0) << "face " << f << " flipped";
  for (auto v : original.vertices()) {
    const Vec3 p0 = original.point(v), p1 = mesh.point(v);
    if ((p1 - p0).norm() == 0) continue;
    bool in_ring = false;
    for (auto fh : original.vf_range(v)) {
      Vec3 q[3];
      int k = 0;
      for (auto w : original.fv_range(fh)) q[k++] = original.point(w);
      const Vec3 n = ((q[1] - q[0]) % (q[2] - q[0])).normalized();
      if (std::abs((p1 - q[0]) | n) > 1e-9) continue;
      bool inside = true;
      for (int i = 0; i < 3; ++i) inside &= (((q[(i + 1) % 3] - q[i]) % (p1 - q[i])) | n) >= -1e-12;
      in_ring |= inside;
    }
    EXPECT_TRUE(in_ring) << "vertex " << v.idx() << " left its original 1-ring";
  }
}

}  // namespace qs::test
