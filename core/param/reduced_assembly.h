// Assembly of the energy matrix H on the wedge unknowns and of the reduced matrix A = ZᵀHZ on
// fixed sparsity patterns (docs/design.md, "Energy" and "Solving"). The patterns are built once per
// constraint elimination; every later assembly (new geometry, new field) scatters per-face
// blocks into H's values and fills A's values in place, with no triplet sorting, no sparse
// temporaries and no change of A's pattern, so CHOLMOD's symbolic analysis is reused
// (SpdSolver).
//
// Z = S + T: T holds Z's few dense columns (D: the seam translations left free, e.g. the
// periods of the handles, used by every node's expression), S the rest (rows of 1–3 terms).
// Then A[¬D, ¬D] = SᵀHS (column by column, Gustavson) and A[:, D] = Zᵀ(H·T) with H·T and
// Zᵀ(H·T) as dense |D|-wide rows, which costs O(|D|·(nnz(H) + nnz(Z))) instead of the
// O(Σ|Z_i|·|Z_j|) of a sparse triple product.
#pragma once

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <vector>

namespace qs {

namespace detail {
//! A SparseMatrix that moves by swapping: Eigen 3.4.0's SparseMatrix has no move operations,
//! so moving a class that holds one copies it.
class MovableSparse : public Eigen::SparseMatrix<double> {
 public:
  using Base = Eigen::SparseMatrix<double>;
  using Base::operator=;
  MovableSparse() = default;
  MovableSparse(const MovableSparse&) = default;
  MovableSparse& operator=(const MovableSparse&) = default;
  MovableSparse(MovableSparse&& other) noexcept { swap(other); }
  MovableSparse& operator=(MovableSparse&& other) noexcept {
    swap(other);
    return *this;
  }
};
}  // namespace detail

class ReducedAssembly {
 public:
  ReducedAssembly() = default;

  //! H's pattern on the wedge unknowns and the faces' slots in it: it depends on corner_wedge
  //! only, so it can be built before (or beside) the constraint elimination that gives Z.
  struct WedgePattern {
    int wedges = 0;
    std::vector<int> outer;      //!< 2·wedges + 1 column starts
    std::vector<int> inner;      //!< row indices, sorted within each column
    std::vector<int> face_slot;  //!< 18 per face: (k, l) of u at 3k + l, of v at 9 + 3k + l
  };
  //! \p corner_wedge: wedge of each face corner (size 3·#F, corner k of face f at 3f + k).
  static WedgePattern wedge_pattern(const std::vector<int>& corner_wedge, int wedges);

  //! \p corner_wedge: wedge of each face corner (size 3·#F, corner k of face f at 3f + k);
  //! wedge w owns the unknowns 2w (u) and 2w + 1 (v). \p variables ≥ 2·wedges: the unknowns x
  //! (the ones past the wedges, e.g. seam translations, have no energy term). \p Z: the
  //! elimination x = Z·y + z0 (variables × free).
  ReducedAssembly(const std::vector<int>& corner_wedge, int wedges, int variables,
                  const Eigen::SparseMatrix<double>& Z);
  //! The same from a pattern built by wedge_pattern(). \p second_thread: A's pattern (the
  //! symbolic ZᵀHZ) is built in two halves of its columns, one on a second thread, when A has
  //! at least 16384 columns (the same pattern either way).
  ReducedAssembly(WedgePattern pattern, int variables, const Eigen::SparseMatrix<double>& Z,
                  bool second_thread = false);

  //! Zeroes H's values.
  void clear();
  //! Adds face f's blocks: \p Hu on its corners' u unknowns, \p Hv on the v unknowns (both
  //! symmetric 3×3, corner order of corner_wedge).
  void add_face(int f, const Eigen::Matrix3d& Hu, const Eigen::Matrix3d& Hv) {
    const int* s = &face_slot_[18 * f];
    double* h = H_.valuePtr();
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < 3; ++l) {
        h[s[3 * k + l]] += Hu(k, l);
        h[s[9 + 3 * k + l]] += Hv(k, l);
      }
  }
  //! Fills A = ZᵀHZ (full symmetric pattern) from H's current values.
  void reduce();

  //! variables × variables, symmetric (both triangles stored).
  const Eigen::SparseMatrix<double>& H() const { return H_; }
  //! free × free, symmetric (both triangles stored); the pattern never changes.
  const Eigen::SparseMatrix<double>& A() const { return A_; }
  //! Multiply-adds of one reduce() (Σ over H entries (i, j) of the products of the lengths of
  //! Z's rows i and j, lower triangle).
  long reduce_flops() const { return flops_; }

 private:
  detail::MovableSparse H_;
  detail::MovableSparse A_;
  std::vector<int>
      face_slot_;  // per face 18 slots into H_: (k, l) of u at 3k + l, of v at 9 + 3k + l
  // Z by columns and by rows, entries split into S (column not dense) and T (dense column).
  detail::MovableSparse Z_;
  std::vector<int> zr_outer_, zr_col_;  // Z by rows (all entries)
  std::vector<double> zr_val_;
  std::vector<int> s_outer_, s_col_;  // S by rows
  std::vector<double> s_val_;
  std::vector<int> t_outer_, t_dense_;  // T by rows: dense-column position 0..d−1
  std::vector<double> t_val_;
  std::vector<int> dense_pos_;  // per free unknown: position in D, or −1
  int d_ = 0;
  std::vector<int> w_rows_;   // rows i of W = H·T that can be non-zero
  std::vector<int> w_index_;  // per unknown x_i: row of W, or −1
  std::vector<int> t_rows_;   // unknowns j with a T entry
  std::vector<int> c_index_;  // per free unknown a: row of C = Zᵀ·W, or −1
  int c_rows_ = 0;
  std::vector<double> w_, c_;  // dense, row-major, d_ wide
  // Lower triangle of A column by column: row, slot in A_, and the source of its value
  // (−1: the SᵀHS accumulator, else an index into c_).
  std::vector<int> lower_outer_, lower_rows_, lower_slot_, lower_src_;
  std::vector<std::pair<int, int>> mirror_;  // (upper slot, its lower mirror slot) of A_
  std::vector<double> work_;                 // dense column accumulator (size free)
  long flops_ = 0;
};

}  // namespace qs
