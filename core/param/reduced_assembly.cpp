#include "core/param/reduced_assembly.h"

#include <algorithm>
#include <cmath>

#include "core/base/errors.h"

namespace qs {

ReducedAssembly::ReducedAssembly(const std::vector<int>& corner_wedge, int wedges, int n,
                                 const Eigen::SparseMatrix<double>& Z) {
  if (n < 2 * wedges || Z.rows() != n || corner_wedge.size() % 3 != 0)
    throw QsError("internal error: ReducedAssembly sizes disagree");
  const int nf = static_cast<int>(corner_wedge.size()) / 3;
  for (int w : corner_wedge)
    if (w < 0 || w >= wedges) throw QsError("internal error: corner wedge out of range");

  // Wedges sharing a face (each wedge with itself), as sorted lists (CSR).
  std::vector<int> nbr_outer(wedges + 1, 0);
  for (int w : corner_wedge) nbr_outer[w + 1] += 3;
  for (int w = 0; w < wedges; ++w) nbr_outer[w + 1] += nbr_outer[w];
  std::vector<int> nbr(nbr_outer[wedges]);
  {
    std::vector<int> next(nbr_outer.begin(), nbr_outer.end() - 1);
    for (int f = 0; f < nf; ++f)
      for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 3; ++l) nbr[next[corner_wedge[3 * f + k]]++] = corner_wedge[3 * f + l];
    int out = 0;
    for (int w = 0; w < wedges; ++w) {
      const auto b = nbr.begin() + nbr_outer[w], e = nbr.begin() + nbr_outer[w + 1];
      std::sort(b, e);
      const int len = static_cast<int>(std::unique(b, e) - b);
      std::copy(b, b + len, nbr.begin() + out);
      nbr_outer[w] = out;
      out += len;
    }
    nbr_outer[wedges] = out;
    nbr.resize(out);
  }
  // H: column 2w + c holds the rows 2w' + c, w' ∈ nbr(w), c = 0 (u) or 1 (v).
  H_.resize(n, n);
  H_.resizeNonZeros(static_cast<Eigen::Index>(2 * nbr.size()));
  {
    int* outer = H_.outerIndexPtr();
    int* inner = H_.innerIndexPtr();
    int pos = 0;
    for (int col = 0; col < n; ++col) {
      outer[col] = pos;
      if (col < 2 * wedges)
        for (int q = nbr_outer[col / 2]; q < nbr_outer[col / 2 + 1]; ++q)
          inner[pos++] = 2 * nbr[q] + col % 2;
    }
    outer[n] = pos;
    std::fill(H_.valuePtr(), H_.valuePtr() + H_.nonZeros(), 0.0);
  }
  face_slot_.resize(18 * static_cast<size_t>(nf));
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < 3; ++l) {
        const int wk = corner_wedge[3 * f + k], wl = corner_wedge[3 * f + l];
        const int p = static_cast<int>(
            std::lower_bound(nbr.begin() + nbr_outer[wl], nbr.begin() + nbr_outer[wl + 1], wk) -
            (nbr.begin() + nbr_outer[wl]));
        face_slot_[18 * f + 3 * k + l] = H_.outerIndexPtr()[2 * wl] + p;
        face_slot_[18 * f + 9 + 3 * k + l] = H_.outerIndexPtr()[2 * wl + 1] + p;
      }

  // Z by columns and rows; dense columns D.
  const int m = static_cast<int>(Z.cols());
  Z_ = Z;
  Z_.makeCompressed();
  {
    const Eigen::SparseMatrix<double, Eigen::RowMajor> Zr = Z_;
    zr_outer_.assign(Zr.outerIndexPtr(), Zr.outerIndexPtr() + n + 1);
    zr_col_.assign(Zr.innerIndexPtr(), Zr.innerIndexPtr() + Zr.nonZeros());
    zr_val_.assign(Zr.valuePtr(), Zr.valuePtr() + Zr.nonZeros());
  }
  const double dense_threshold = std::max(32.0, std::sqrt(static_cast<double>(m)));
  dense_pos_.assign(m, -1);
  std::vector<int> dense_cols;
  for (int b = 0; b < m; ++b)
    if (Z_.outerIndexPtr()[b + 1] - Z_.outerIndexPtr()[b] > dense_threshold) {
      dense_pos_[b] = static_cast<int>(dense_cols.size());
      dense_cols.push_back(b);
    }
  d_ = static_cast<int>(dense_cols.size());
  s_outer_.assign(n + 1, 0);
  t_outer_.assign(n + 1, 0);
  s_col_.clear(), s_val_.clear(), t_dense_.clear(), t_val_.clear(), t_rows_.clear();
  for (int i = 0; i < n; ++i) {
    for (int q = zr_outer_[i]; q < zr_outer_[i + 1]; ++q) {
      const int p = dense_pos_[zr_col_[q]];
      if (p < 0) {
        s_col_.push_back(zr_col_[q]);
        s_val_.push_back(zr_val_[q]);
      } else {
        t_dense_.push_back(p);
        t_val_.push_back(zr_val_[q]);
      }
    }
    s_outer_[i + 1] = static_cast<int>(s_col_.size());
    t_outer_[i + 1] = static_cast<int>(t_dense_.size());
    if (t_outer_[i + 1] > t_outer_[i]) t_rows_.push_back(i);
  }
  const int* h_outer = H_.outerIndexPtr();
  const int* h_inner = H_.innerIndexPtr();
  // Rows of W = H·T and of C = Zᵀ·W that can be non-zero.
  w_index_.assign(n, -1);
  w_rows_.clear();
  for (int j : t_rows_)
    for (int k = h_outer[j]; k < h_outer[j + 1]; ++k)
      if (w_index_[h_inner[k]] < 0) {
        w_index_[h_inner[k]] = static_cast<int>(w_rows_.size());
        w_rows_.push_back(h_inner[k]);
      }
  c_index_.assign(m, -1);
  std::vector<int> c_list;
  for (int i : w_rows_)
    for (int q = zr_outer_[i]; q < zr_outer_[i + 1]; ++q)
      if (c_index_[zr_col_[q]] < 0) {
        c_index_[zr_col_[q]] = static_cast<int>(c_list.size());
        c_list.push_back(zr_col_[q]);
      }
  c_rows_ = static_cast<int>(c_list.size());
  std::sort(c_list.begin(), c_list.end());
  w_.assign(static_cast<size_t>(w_rows_.size()) * d_, 0.0);
  c_.assign(static_cast<size_t>(c_rows_) * d_, 0.0);

  // Lower triangle of A (row ≥ column) with the source of every entry.
  lower_outer_.assign(m + 1, 0);
  lower_rows_.clear();
  lower_src_.clear();
  std::vector<int> mark(m, -1);
  std::vector<std::pair<int, int>> column, merged;  // (row, source)
  flops_ = 0;
  for (int b = 0; b < m; ++b) {
    column.clear();
    const int pb = dense_pos_[b];
    if (pb < 0) {
      for (int zq = Z_.outerIndexPtr()[b]; zq < Z_.outerIndexPtr()[b + 1]; ++zq) {
        const int j = Z_.innerIndexPtr()[zq];
        for (int k = h_outer[j]; k < h_outer[j + 1]; ++k) {
          const int i = h_inner[k];
          for (int q = s_outer_[i]; q < s_outer_[i + 1]; ++q) {
            const int a = s_col_[q];
            if (a < b) continue;
            ++flops_;
            if (mark[a] != b) {
              mark[a] = b;
              column.push_back({a, -1});
            }
          }
        }
      }
      std::sort(column.begin(), column.end());
      if (c_index_[b] >= 0) {  // A(d, b) = A(b, d) = C(b, d) for dense columns d > b (sorted)
        merged.clear();
        size_t q = 0;
        for (int p = 0; p < d_; ++p) {
          if (dense_cols[p] <= b) continue;
          while (q < column.size() && column[q].first < dense_cols[p])
            merged.push_back(column[q++]);
          merged.push_back({dense_cols[p], c_index_[b] * d_ + p});
        }
        merged.insert(merged.end(), column.begin() + static_cast<long>(q), column.end());
        column.swap(merged);
      }
    } else {
      for (int a : c_list)  // sorted
        if (a >= b) column.push_back({a, c_index_[a] * d_ + pb});
    }
    for (const auto& [a, src] : column) {
      lower_rows_.push_back(a);
      lower_src_.push_back(src);
    }
    lower_outer_[b + 1] = static_cast<int>(lower_rows_.size());
  }
  for (int j : t_rows_)
    flops_ += static_cast<long>(h_outer[j + 1] - h_outer[j]) * (t_outer_[j + 1] - t_outer_[j]);
  for (int i : w_rows_) flops_ += static_cast<long>(zr_outer_[i + 1] - zr_outer_[i]) * d_;

  // Full symmetric pattern: column b = upper part (rows a < b, from the lower row b) then the
  // lower part.
  std::vector<int> upper_count(m, 0);
  long strictly_lower = 0;
  for (int b = 0; b < m; ++b)
    for (int q = lower_outer_[b]; q < lower_outer_[b + 1]; ++q)
      if (lower_rows_[q] > b) ++upper_count[lower_rows_[q]], ++strictly_lower;
  A_.resize(m, m);
  A_.resizeNonZeros(static_cast<Eigen::Index>(lower_rows_.size() + strictly_lower));
  int* outer = A_.outerIndexPtr();
  int* inner = A_.innerIndexPtr();
  outer[0] = 0;
  for (int b = 0; b < m; ++b)
    outer[b + 1] = outer[b] + upper_count[b] + (lower_outer_[b + 1] - lower_outer_[b]);
  lower_slot_.resize(lower_rows_.size());
  mirror_.clear();
  mirror_.reserve(strictly_lower);
  std::vector<int> next_upper(outer, outer + m);
  for (int b = 0; b < m; ++b) {
    const int lower_start = outer[b] + upper_count[b];
    for (int q = lower_outer_[b]; q < lower_outer_[b + 1]; ++q) {
      const int a = lower_rows_[q];
      const int s = lower_start + (q - lower_outer_[b]);
      inner[s] = a;
      lower_slot_[q] = s;
      if (a > b) {  // the mirror (b, a) in column a; columns b come in increasing order
        const int u = next_upper[a]++;
        inner[u] = b;
        mirror_.push_back({u, s});
      }
    }
  }
  std::fill(A_.valuePtr(), A_.valuePtr() + A_.nonZeros(), 0.0);
  work_.assign(m, 0.0);
}

void ReducedAssembly::clear() {
  std::fill(H_.valuePtr(), H_.valuePtr() + H_.nonZeros(), 0.0);
}

void ReducedAssembly::reduce() {
  const int m = static_cast<int>(A_.cols()), d = d_;
  const double* h_val = H_.valuePtr();
  const int* h_outer = H_.outerIndexPtr();
  const int* h_inner = H_.innerIndexPtr();
  // W = H·T, then C = Zᵀ·W (rows of d values).
  if (d > 0) {
    std::fill(w_.begin(), w_.end(), 0.0);
    for (int j : t_rows_)
      for (int k = h_outer[j]; k < h_outer[j + 1]; ++k) {
        double* w = &w_[static_cast<size_t>(w_index_[h_inner[k]]) * d];
        const double h = h_val[k];
        for (int q = t_outer_[j]; q < t_outer_[j + 1]; ++q) w[t_dense_[q]] += h * t_val_[q];
      }
    std::fill(c_.begin(), c_.end(), 0.0);
    for (int i : w_rows_) {
      const double* w = &w_[static_cast<size_t>(w_index_[i]) * d];
      for (int q = zr_outer_[i]; q < zr_outer_[i + 1]; ++q) {
        double* c = &c_[static_cast<size_t>(c_index_[zr_col_[q]]) * d];
        const double z = zr_val_[q];
        for (int p = 0; p < d; ++p) c[p] += z * w[p];
      }
    }
  }
  // SᵀHS column by column, then every lower entry from its source.
  double* a_val = A_.valuePtr();
  double* work = work_.data();
  const int* z_outer = Z_.outerIndexPtr();
  const int* z_inner = Z_.innerIndexPtr();
  const double* z_val = Z_.valuePtr();
  for (int b = 0; b < m; ++b) {
    if (dense_pos_[b] < 0)
      for (int zq = z_outer[b]; zq < z_outer[b + 1]; ++zq) {
        const int j = z_inner[zq];
        const double zjb = z_val[zq];
        for (int k = h_outer[j]; k < h_outer[j + 1]; ++k) {
          const int i = h_inner[k];
          const double hz = h_val[k] * zjb;
          for (int q = s_outer_[i]; q < s_outer_[i + 1]; ++q)
            if (s_col_[q] >= b) work[s_col_[q]] += s_val_[q] * hz;
        }
      }
    for (int q = lower_outer_[b]; q < lower_outer_[b + 1]; ++q) {
      if (lower_src_[q] >= 0) {
        a_val[lower_slot_[q]] = c_[lower_src_[q]];
      } else {
        a_val[lower_slot_[q]] = work[lower_rows_[q]];
        work[lower_rows_[q]] = 0.0;
      }
    }
  }
  for (const auto& [u, l] : mirror_) a_val[u] = a_val[l];
}

}  // namespace qs
