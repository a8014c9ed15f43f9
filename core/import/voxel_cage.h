// Voxel cage of a closed triangle mesh: the boundary surface of its voxelization, made manifold,
// as a pure quad mesh (the first step of cage_layout, core/import/cage.h).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/mesh/mesh.h"

namespace qs {

//! Occupancy grid of a voxelization. Cell (i, j, k), 0 <= i < dims[0] etc., is the box
//! origin + h·[i, i+1] × [j, j+1] × [k, k+1] (mesh length units). The outermost layer of
//! cells is always empty.
struct VoxelGrid {
  std::array<int, 3> dims{{0, 0, 0}};  //!< cells per axis
  Vec3 origin{0, 0, 0};                //!< corner of cell (0, 0, 0)
  double h = 0;                        //!< cell edge length
  std::vector<uint8_t> occupied;       //!< per cell, index i + dims[0]·(j + dims[1]·k)

  int cell(int i, int j, int k) const { return i + dims[0] * (j + dims[1] * k); }
  bool at(int i, int j, int k) const { return occupied[cell(i, j, k)] != 0; }
};

//! What voxel_cage did.
struct VoxelCageInfo {
  VoxelGrid grid;         //!< final occupancy (after repairs)
  int inside_cells = 0;   //!< cells classified inside (ray parity, 2 of 3 axes)
  int filled_voids = 0;   //!< empty cells not reachable from outside, filled
  int flipped_cells = 0;  //!< cells filled or carved to make the surface manifold
  int genus = 0;          //!< of the cage surface
  int components = 0;     //!< of the cage surface
  //! Per cage vertex: its grid point (x, y, z), 0 <= x <= dims[0] etc.
  std::vector<std::array<int, 3>> grid_vertex;
};

//! The boundary surface of the voxelization of a closed triangle mesh as a pure quad mesh,
//! one quad per boundary face of the occupied cells, oriented outward, at the voxel
//! positions. A sample point is inside when it is inside for the ray parity along at least
//! two of the three axes (rays slightly offset from the sample points against exact hits); a
//! cell is occupied when at least half of its subsamples³ sample points (the centres of a
//! subsamples × subsamples × subsamples split of the cell; 1: the cell centre) are inside.
//! Empty cells enclosed by occupied ones are filled; then, until the surface is manifold at
//! every grid vertex (the occupied and the empty cells of its 2×2×2 block are each
//! face-connected in the block), the cell of a bad block whose centre lies closest to the
//! mesh surface is flipped (preferring flips that repair the block; each cell flips at most
//! once).
//! \param resolution cells along the longest bounding-box axis (2..200; memory grows with its
//! cube). \throw InvalidInputError for a mesh with boundary or without faces, a resolution or
//!        subsamples out of range, or a configuration that cannot be repaired.
//! \param shift offset of the grid along every axis, in cells (another sampling of the shape).
//! \param subsamples sample points per cell and axis (1..8), see above.
PolyMesh voxel_cage(const TriMesh& mesh, int resolution, VoxelCageInfo* info = nullptr,
                    double shift = 0.0, int subsamples = 1);

}  // namespace qs
