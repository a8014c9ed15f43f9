// Robustness runs of the outcome tests: with the environment variable QS_TEST_JITTER set to a
// fraction of the bounding-box diagonal (CI uses 1e-9), every mesh a test reads or builds
// through these helpers has each vertex coordinate moved by a deterministic pseudo-random offset
// of at most that fraction of its bounding-box diagonal. An outcome that changes under such a
// jitter was a trajectory, not an outcome (tests/CMakeLists.txt runs the tests labelled
// "outcome" a second time with it). Without the variable nothing changes.
#pragma once

#include <string>

#include "core/mesh/mesh.h"

namespace qs::test {

//! QS_TEST_JITTER as a number (fraction of the bounding-box diagonal), 0 when unset.
//! Aborts the test program with a message when it is set but not a finite number in [0, 1e-3].
double jitter_scale();

//! Moves every vertex of \p mesh by the jitter (nothing when jitter_scale() is 0). The offsets
//! depend on the vertex index and the vertex count only, so a mesh is jittered the same way by
//! every test and on every machine.
void jitter(TriMesh& mesh);
void jitter(PolyMesh& mesh);

//! qs::load_mesh / qs::load_poly_mesh of \p path, jittered.
TriMesh load_mesh(const std::string& path);
PolyMesh load_poly_mesh(const std::string& path);

//! A mesh file to hand to the command line: \p path itself, or with jitter a jittered copy of
//! it (OBJ, full precision, same vertex and face order) in a temporary folder.
std::string mesh_file(const std::string& path);

}  // namespace qs::test
