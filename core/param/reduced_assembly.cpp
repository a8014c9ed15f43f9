#include "core/param/reduced_assembly.h"

#include <algorithm>
#include <cmath>
#include <future>

#include "core/base/errors.h"

namespace qs {

namespace {

// Sorts a list of a few dozen indices at most in place (insertion sort; std::sort beyond).
void sort_short(std::vector<int>& v) {
  if (v.size() > 32) {
    std::sort(v.begin(), v.end());
    return;
  }
  for (size_t i = 1; i < v.size(); ++i) {
    const int x = v[i];
    size_t j = i;
    for (; j > 0 && v[j - 1] > x; --j) v[j] = v[j - 1];
    v[j] = x;
  }
}

}  // namespace

ReducedAssembly::WedgePattern ReducedAssembly::wedge_pattern(const std::vector<int>& corner_wedge,
                                                             int wedges) {
  if (wedges < 0 || corner_wedge.size() % 3 != 0)
    throw QsError("internal error: ReducedAssembly sizes disagree");
  const int nf = static_cast<int>(corner_wedge.size()) / 3;
  for (int w : corner_wedge)
    if (w < 0 || w >= wedges) throw QsError("internal error: corner wedge out of range");

  // Per wedge w (sequentially, so the writes to H's pattern are sequential): the wedges
  // sharing a face with it (itself included), sorted, give H's columns 2w (rows 2w', u) and
  // 2w + 1 (rows 2w' + 1, v); the slots of w's corners' face blocks follow from the positions.
  WedgePattern pat;
  pat.wedges = wedges;
  std::vector<int> wc_start(wedges + 1, 0), wc(corner_wedge.size());
  for (int w : corner_wedge) ++wc_start[w + 1];
  for (int w = 0; w < wedges; ++w) wc_start[w + 1] += wc_start[w];
  {
    std::vector<int> next(wc_start.begin(), wc_start.end() - 1);
    for (int c = 0; c < 3 * nf; ++c) wc[next[corner_wedge[c]]++] = c;
  }
  std::vector<int>& hp = pat.outer;
  std::vector<int>& hi = pat.inner;
  hp.assign(2 * static_cast<size_t>(wedges) + 1, 0);
  hi.reserve(static_cast<size_t>(16) * wedges);
  pat.face_slot.resize(18 * static_cast<size_t>(nf));
  std::vector<int> mark(wedges, -1), pos(wedges, 0), list;
  for (int w = 0; w < wedges; ++w) {
    list.clear();
    for (int q = wc_start[w]; q < wc_start[w + 1]; ++q) {
      const int* fw = &corner_wedge[3 * (wc[q] / 3)];
      for (int k = 0; k < 3; ++k)
        if (mark[fw[k]] != w) {
          mark[fw[k]] = w;
          list.push_back(fw[k]);
        }
    }
    sort_short(list);  // a handful of wedges
    const int len = static_cast<int>(list.size());
    const int base = static_cast<int>(hi.size());
    hp[2 * w] = base;
    hp[2 * w + 1] = base + len;
    for (int i = 0; i < len; ++i) {
      pos[list[i]] = i;
      hi.push_back(2 * list[i]);
    }
    for (int i = 0; i < len; ++i) hi.push_back(2 * list[i] + 1);
    for (int q = wc_start[w]; q < wc_start[w + 1]; ++q) {
      const int f = wc[q] / 3, l = wc[q] % 3;
      int* slot = &pat.face_slot[18 * static_cast<size_t>(f)];
      for (int k = 0; k < 3; ++k) {
        const int p = pos[corner_wedge[3 * f + k]];
        slot[3 * k + l] = base + p;
        slot[9 + 3 * k + l] = base + len + p;
      }
    }
  }
  hp[2 * static_cast<size_t>(wedges)] = static_cast<int>(hi.size());
  return pat;
}

ReducedAssembly::ReducedAssembly(const std::vector<int>& corner_wedge, int wedges, int n,
                                 const Eigen::SparseMatrix<double>& Z)
    : ReducedAssembly(wedge_pattern(corner_wedge, wedges), n, Z) {}

ReducedAssembly::ReducedAssembly(WedgePattern pattern, int n, const Eigen::SparseMatrix<double>& Z,
                                 bool second_thread) {
  const int wedges = pattern.wedges;
  if (n < 2 * wedges || Z.rows() != n ||
      pattern.outer.size() != 2 * static_cast<size_t>(wedges) + 1)
    throw QsError("internal error: ReducedAssembly sizes disagree");
  face_slot_ = std::move(pattern.face_slot);
  H_.resize(n, n);
  H_.resizeNonZeros(static_cast<Eigen::Index>(pattern.inner.size()));
  std::copy(pattern.outer.begin(), pattern.outer.end(), H_.outerIndexPtr());
  // The unknowns past the wedges (seam translations) have empty columns.
  std::fill(H_.outerIndexPtr() + 2 * wedges + 1, H_.outerIndexPtr() + n + 1,
            static_cast<int>(pattern.inner.size()));
  std::copy(pattern.inner.begin(), pattern.inner.end(), H_.innerIndexPtr());
  std::fill(H_.valuePtr(), H_.valuePtr() + H_.nonZeros(), 0.0);

  // Z by columns and rows; dense columns D.
  const int m = static_cast<int>(Z.cols());
  Z_ = Z;
  Z_.makeCompressed();
  {  // Z by rows (a counting-sort transpose: columns increase within every row)
    const int* zo = Z_.outerIndexPtr();
    const int* zi = Z_.innerIndexPtr();
    const double* zv = Z_.valuePtr();
    const int nz = static_cast<int>(Z_.nonZeros());
    zr_outer_.assign(n + 1, 0);
    for (int q = 0; q < nz; ++q) ++zr_outer_[zi[q] + 1];
    for (int i = 0; i < n; ++i) zr_outer_[i + 1] += zr_outer_[i];
    zr_col_.resize(nz);
    zr_val_.resize(nz);
    std::vector<int> next(zr_outer_.begin(), zr_outer_.end() - 1);
    for (int b = 0; b < m; ++b)
      for (int q = zo[b]; q < zo[b + 1]; ++q) {
        const int at = next[zi[q]]++;
        zr_col_[at] = b;
        zr_val_[at] = zv[q];
      }
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
  s_col_.reserve(zr_col_.size());
  s_val_.reserve(zr_col_.size());
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

  // Lower triangle of A (row ≥ column) with the source of every entry, for the columns
  // [b0, b1): rows and sources appended to \p out, out.end[b − b0] after column b.
  struct Columns {
    std::vector<int> rows, src, end;
    long flops = 0;
  };
  auto lower_columns = [&](int b0, int b1, Columns& out) {
    constexpr int reserve_factor = 8;  // lower entries per column, a guess (grows if needed)
    out.rows.reserve(static_cast<size_t>(reserve_factor) * (b1 - b0));
    out.src.reserve(static_cast<size_t>(reserve_factor) * (b1 - b0));
    out.end.resize(b1 - b0);
    std::vector<int> mark(m, -1), column;
    for (int b = b0; b < b1; ++b) {
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
              ++out.flops;
              if (mark[a] != b) {
                mark[a] = b;
                column.push_back(a);
              }
            }
          }
        }
        sort_short(column);  // columns hold a few dozen rows
        // A(d, b) = A(b, d) = C(b, d) for the dense columns d > b, merged in (both sorted).
        size_t q = 0;
        if (c_index_[b] >= 0)
          for (int p = 0; p < d_; ++p) {
            if (dense_cols[p] <= b) continue;
            for (; q < column.size() && column[q] < dense_cols[p]; ++q) {
              out.rows.push_back(column[q]);
              out.src.push_back(-1);
            }
            out.rows.push_back(dense_cols[p]);
            out.src.push_back(c_index_[b] * d_ + p);
          }
        for (; q < column.size(); ++q) {
          out.rows.push_back(column[q]);
          out.src.push_back(-1);
        }
      } else {
        for (int a : c_list)  // sorted
          if (a >= b) {
            out.rows.push_back(a);
            out.src.push_back(c_index_[a] * d_ + pb);
          }
      }
      out.end[b - b0] = static_cast<int>(out.rows.size());
    }
  };
  // Two halves of the columns on two threads for large matrices (the same pattern).
  constexpr int kThreadColumns = 16384;
  const int split = second_thread && m >= kThreadColumns ? m / 2 : m;
  Columns first, second;
  if (split < m) {
    auto other = std::async(std::launch::async, [&]() { lower_columns(split, m, second); });
    lower_columns(0, split, first);
    other.get();
  } else {
    lower_columns(0, m, first);
  }
  lower_outer_.assign(m + 1, 0);
  for (int b = 0; b < split; ++b) lower_outer_[b + 1] = first.end[b];
  for (int b = split; b < m; ++b)
    lower_outer_[b + 1] = static_cast<int>(first.rows.size()) + second.end[b - split];
  lower_rows_ = std::move(first.rows);
  lower_src_ = std::move(first.src);
  lower_rows_.insert(lower_rows_.end(), second.rows.begin(), second.rows.end());
  lower_src_.insert(lower_src_.end(), second.src.begin(), second.src.end());
  flops_ = first.flops + second.flops;
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
