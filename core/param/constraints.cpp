#include "core/param/constraints.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/base/errors.h"

namespace qs {

namespace {

using Terms = std::vector<std::pair<int, double>>;

// Coefficients this small after a substitution are exact cancellations up to round-off (the
// rows have coefficients ±1, ±2 and products of them).
constexpr double kCancel = 1e-13;

// Dense scatter workspace for one sparse linear combination: O(terms) per use, no hashing, no
// allocation after the first rows.
class Accumulator {
 public:
  explicit Accumulator(int n) : value_(n, 0.0), used_(n, 0) {}
  void add(int v, double c) {
    if (!used_[v]) {
      used_[v] = 1;
      touched_.push_back(v);
    }
    value_[v] += c;
  }
  //! Moves the entries with |c| > drop into \p out (sorted by variable) and clears.
  void take(double drop, Terms& out) {
    out.clear();
    std::sort(touched_.begin(), touched_.end());
    for (int v : touched_) {
      if (std::abs(value_[v]) > drop) out.push_back({v, value_[v]});
      value_[v] = 0;
      used_[v] = 0;
    }
    touched_.clear();
  }

 private:
  std::vector<double> value_;
  std::vector<char> used_;
  std::vector<int> touched_;
};

// Eliminated variables as fully reduced expressions x_v = Σ expr[v] + constant[v] over the
// variables still free (sorted by variable).
struct Store {
  explicit Store(int n) : expr(n), constant(n, 0.0), eliminated(n, 0), users(n) {}
  std::vector<Terms> expr;
  std::vector<double> constant;
  std::vector<char> eliminated;
  // Per free variable: eliminated variables whose expression may use it (entries can be
  // stale after a cancellation; the size is the Markowitz count).
  std::vector<std::vector<int>> users;
  std::vector<int> order;  // eliminated variables in elimination order

  // Adds c·x_v, with x_v replaced by its expression when eliminated.
  void add_reduced(Accumulator& acc, int v, double c, double& rhs) const {
    if (eliminated[v]) {
      for (const auto& [u, cu] : expr[v]) acc.add(u, c * cu);
      rhs -= c * constant[v];
    } else {
      acc.add(v, c);
    }
  }

  // x_pivot = (rhs − Σ_{u≠pivot} c_u x_u) / c_pivot, substituted into every user.
  void eliminate(int pivot, const Terms& row, double rhs, Terms& merged) {
    double cp = 0;
    for (const auto& [v, c] : row)
      if (v == pivot) cp = c;
    Terms e;
    e.reserve(row.size() - 1);
    for (const auto& [u, c] : row)
      if (u != pivot) e.push_back({u, -c / cp});
    const double e_const = rhs / cp;
    for (int q : users[pivot]) {
      Terms& eq = expr[q];
      const auto it = std::lower_bound(eq.begin(), eq.end(), std::make_pair(pivot, -HUGE_VAL));
      if (it == eq.end() || it->first != pivot) continue;  // stale: cancelled earlier
      const double c = it->second;
      eq.erase(it);
      constant[q] += c * e_const;
      merged.clear();
      size_t i = 0, j = 0;
      while (i < eq.size() || j < e.size()) {
        if (j == e.size() || (i < eq.size() && eq[i].first < e[j].first)) {
          merged.push_back(eq[i++]);
        } else if (i == eq.size() || e[j].first < eq[i].first) {
          merged.push_back({e[j].first, c * e[j].second});
          users[e[j].first].push_back(q);
          ++j;
        } else {
          const double s = eq[i].second + c * e[j].second;
          if (std::abs(s) > kCancel) merged.push_back({eq[i].first, s});
          ++i, ++j;
        }
      }
      eq.swap(merged);
    }
    std::vector<int>().swap(users[pivot]);
    for (const auto& [u, cu] : e) users[u].push_back(pivot);
    expr[pivot] = std::move(e);
    constant[pivot] = e_const;
    eliminated[pivot] = 1;
    order.push_back(pivot);
  }

  // Pivot of a reduced row among the variables allowed by \p allowed (threshold pivoting:
  // |c| ≥ ½·max|c| of the row; then the largest |c|, then the fewest users, then the lowest
  // index), or −1.
  template <class Allowed>
  int choose_pivot(const Terms& row, Allowed allowed) const {
    double row_max = 0;
    for (const auto& t : row) row_max = std::max(row_max, std::abs(t.second));
    int pivot = -1;
    double pivot_abs = 0;
    size_t pivot_users = 0;
    for (const auto& [v, c] : row) {
      const double a = std::abs(c);
      if (!allowed(v) || a < 0.5 * row_max) continue;
      const bool larger = a > pivot_abs * (1 + 1e-12);
      const bool tie = !larger && a >= pivot_abs * (1 - 1e-12);
      if (pivot < 0 || larger || (tie && users[v].size() < pivot_users))
        pivot = v, pivot_abs = a, pivot_users = users[v].size();
    }
    return pivot;
  }
};

}  // namespace

Reduction eliminate_constraints(const ConstraintSystem& sys, double tolerance) {
  const int n = sys.variables;
  if (!sys.eliminate_last.empty() && static_cast<int>(sys.eliminate_last.size()) != n)
    throw InvalidInputError(
        "ConstraintSystem::eliminate_last must be empty or have one entry "
        "per variable");
  auto last = [&](int v) { return !sys.eliminate_last.empty() && sys.eliminate_last[v]; };
  auto origin_name = [&](const LinearRow& row) {
    return row.origin >= 0 && row.origin < static_cast<int>(sys.origins.size())
               ? sys.origins[row.origin]
               : std::string("unnamed row");
  };
  Reduction red;
  std::vector<std::string> incompatible;
  Accumulator acc(n);
  Terms row_terms, merged;
  // A reduced row 0 = rhs: redundant or incompatible.
  auto empty_row = [&](const LinearRow& row, double rhs, double scale) {
    if (std::abs(rhs) > tolerance * std::max(1.0, scale)) {
      incompatible.push_back(origin_name(row));
    } else {
      ++red.redundant;
      red.redundant_origins.push_back(row.origin);
    }
  };

  // Pass 1: every row with a candidate pivot that is not an eliminate-last variable. Rows
  // whose reduction only has eliminate-last candidates wait for pass 2.
  Store first(n);
  std::vector<int> deferred;
  for (int r = 0; r < static_cast<int>(sys.rows.size()); ++r) {
    const LinearRow& row = sys.rows[r];
    double rhs = row.rhs, scale = 0;
    for (const auto& [v, c] : row.terms) {
      if (v < 0 || v >= n)
        throw InvalidInputError("constraint row of " + origin_name(row) + " uses variable " +
                                std::to_string(v) + " of " + std::to_string(n));
      if (!std::isfinite(c))
        throw InvalidInputError("constraint row of " + origin_name(row) +
                                " has a non-finite coefficient");
      scale = std::max(scale, std::abs(c));
      first.add_reduced(acc, v, c, rhs);
    }
    acc.take(1e-12 * std::max(1.0, scale), row_terms);
    if (row_terms.empty()) {
      empty_row(row, rhs, scale);
      continue;
    }
    const int pivot = first.choose_pivot(row_terms, [&](int v) { return !last(v); });
    if (pivot < 0) {
      deferred.push_back(r);
      continue;
    }
    first.eliminate(pivot, row_terms, rhs, merged);
  }

  // Pass 2: the deferred rows, reduced over pass 1's free variables, eliminated among
  // themselves (few rows, few variables).
  Store second(deferred.empty() ? 0 : n);  // unused (empty) without deferred rows
  for (int r : deferred) {
    const LinearRow& row = sys.rows[r];
    double rhs = row.rhs, scale = 0;
    for (const auto& [v, c] : row.terms) {
      scale = std::max(scale, std::abs(c));
      if (!first.eliminated[v]) {
        second.add_reduced(acc, v, c, rhs);
        continue;
      }
      for (const auto& [u, cu] : first.expr[v]) second.add_reduced(acc, u, c * cu, rhs);
      rhs -= c * first.constant[v];
    }
    acc.take(1e-12 * std::max(1.0, scale), row_terms);
    if (row_terms.empty()) {
      empty_row(row, rhs, scale);
      continue;
    }
    second.eliminate(second.choose_pivot(row_terms, [](int) { return true; }), row_terms, rhs,
                     merged);
  }
  if (!incompatible.empty()) {
    std::ostringstream ss;
    ss << "incompatible constraints (" << incompatible.size() << "): ";
    for (size_t i = 0; i < incompatible.size() && i < 8; ++i)
      ss << (i ? "; " : "") << incompatible[i];
    if (incompatible.size() > 8) ss << "; …";
    throw InfeasibleLayoutError(ss.str());
  }

  // Pass 3: substitute pass 2's expressions into pass 1's, once each.
  if (!second.order.empty()) {
    for (int v : first.order) {
      bool uses = false;
      for (const auto& t : first.expr[v]) uses |= second.eliminated[t.first] != 0;
      if (!uses) continue;
      double rhs = -first.constant[v];  // add_reduced subtracts constants from a "rhs"
      for (const auto& [u, c] : first.expr[v]) second.add_reduced(acc, u, c, rhs);
      acc.take(kCancel, first.expr[v]);
      first.constant[v] = -rhs;
    }
  }

  red.free_index.assign(n, -1);
  int m = 0;
  std::vector<const Terms*> expr(n, nullptr);
  std::vector<double> constant(n, 0.0);
  for (int v = 0; v < n; ++v) {
    if (first.eliminated[v]) {
      expr[v] = &first.expr[v], constant[v] = first.constant[v];
    } else if (!deferred.empty() && second.eliminated[v]) {
      expr[v] = &second.expr[v], constant[v] = second.constant[v];
    } else {
      red.free_index[v] = m++;
    }
  }
  red.eliminated = n - m;
  // Rows of Z are the expressions (sorted by variable, so by column): CSR arrays, converted
  // once to column-major.
  std::vector<int> outer(n + 1, 0), inner;
  std::vector<double> values;
  {
    size_t nz = 0;
    for (int v = 0; v < n; ++v) nz += expr[v] ? expr[v]->size() : 1;
    inner.reserve(nz);
    values.reserve(nz);
  }
  for (int v = 0; v < n; ++v) {
    if (!expr[v]) {
      inner.push_back(red.free_index[v]);
      values.push_back(1.0);
    } else {
      for (const auto& [u, c] : *expr[v]) {
        inner.push_back(red.free_index[u]);
        values.push_back(c);
      }
    }
    outer[v + 1] = static_cast<int>(inner.size());
  }
  red.Z = Eigen::Map<const Eigen::SparseMatrix<double, Eigen::RowMajor>>(
      n, m, static_cast<Eigen::Index>(inner.size()), outer.data(), inner.data(), values.data());
  red.z0 = Eigen::Map<const Eigen::VectorXd>(constant.data(), n);
  return red;
}

}  // namespace qs
