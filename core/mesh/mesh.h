// Mesh types used everywhere in QuadSketch: OpenMesh with double-precision points.
#pragma once

// MeshIO must be included before the mesh kernels.
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

namespace qs {

struct MeshTraits : public OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
  using Normal = OpenMesh::Vec3d;
  VertexAttributes(OpenMesh::Attributes::Status);
  HalfedgeAttributes(OpenMesh::Attributes::PrevHalfedge);
  EdgeAttributes(OpenMesh::Attributes::Status);
  FaceAttributes(OpenMesh::Attributes::Status);
};

//! Triangle mesh. Vertex and face indices (idx()) are those of the input file.
using TriMesh = OpenMesh::TriMesh_ArrayKernelT<MeshTraits>;
//! Polygon mesh (quad meshes for import).
using PolyMesh = OpenMesh::PolyMesh_ArrayKernelT<MeshTraits>;
using Vec3 = OpenMesh::Vec3d;

}  // namespace qs
