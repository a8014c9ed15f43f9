#include "core/param/constraints.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <unordered_map>

#include "core/base/errors.h"

namespace qs {

namespace {

// Expression of an eliminated variable: Σ coef·x_free + constant.
struct Expr {
  std::unordered_map<int, double> terms;
  double constant = 0;
};

}  // namespace

Reduction eliminate_constraints(const ConstraintSystem& sys, double tolerance) {
  const int n = sys.variables;
  std::vector<Expr> expr(n);
  std::vector<char> eliminated(n, 0);
  std::vector<std::vector<int>> users(n);  // free var -> eliminated vars whose expr uses it
  Reduction red;
  std::vector<std::string> incompatible;
  for (const LinearRow& row : sys.rows) {
    // Reduce the row to free variables.
    std::unordered_map<int, double> acc;
    double rhs = row.rhs;
    double scale = 0;
    for (auto [v, c] : row.terms) {
      scale = std::max(scale, std::abs(c));
      if (eliminated[v]) {
        for (auto [u, cu] : expr[v].terms) acc[u] += c * cu;
        rhs -= c * expr[v].constant;
      } else {
        acc[v] += c;
      }
    }
    const double drop = 1e-12 * std::max(1.0, scale);
    int pivot = -1;
    double best = 0;
    for (auto it = acc.begin(); it != acc.end();) {
      if (std::abs(it->second) <= drop) {
        it = acc.erase(it);
        continue;
      }
      const double a = std::abs(it->second);
      // Ties (all ±1 here) go to the lowest index: wedge values before the seam
      // translations, which would otherwise chain the rows of one cut curve together.
      if (a > best + 1e-12 || (std::abs(a - best) <= 1e-12 && (pivot < 0 || it->first < pivot)))
        best = a, pivot = it->first;
      ++it;
    }
    if (pivot < 0) {
      if (std::abs(rhs) > tolerance * std::max(1.0, scale)) {
        incompatible.push_back(sys.origins[row.origin]);
      } else {
        ++red.redundant;
        red.redundant_origins.push_back(row.origin);
      }
      continue;
    }
    // x_pivot = (rhs − Σ_{u≠pivot} c_u x_u) / c_pivot
    const double cp = acc[pivot];
    Expr e;
    e.constant = rhs / cp;
    for (auto [u, c] : acc)
      if (u != pivot) e.terms[u] = -c / cp;
    // Substitute into every expression that uses the pivot.
    for (int q : users[pivot]) {
      auto it = expr[q].terms.find(pivot);
      if (it == expr[q].terms.end()) continue;
      const double c = it->second;
      expr[q].terms.erase(it);
      expr[q].constant += c * e.constant;
      for (auto [u, cu] : e.terms) {
        double& slot = expr[q].terms[u];
        if (slot == 0.0) users[u].push_back(q);
        slot += c * cu;
      }
    }
    users[pivot].clear();
    users[pivot].shrink_to_fit();
    for (auto [u, cu] : e.terms) users[u].push_back(pivot);
    expr[pivot] = std::move(e);
    eliminated[pivot] = 1;
    ++red.eliminated;
  }
  if (!incompatible.empty()) {
    std::ostringstream ss;
    ss << "incompatible constraints (" << incompatible.size() << "): ";
    for (size_t i = 0; i < incompatible.size() && i < 8; ++i)
      ss << (i ? "; " : "") << incompatible[i];
    if (incompatible.size() > 8) ss << "; …";
    throw InvalidInputError(ss.str());
  }
  red.free_index.assign(n, -1);
  int m = 0;
  for (int v = 0; v < n; ++v)
    if (!eliminated[v]) red.free_index[v] = m++;
  std::vector<Eigen::Triplet<double>> triplets;
  red.z0 = Eigen::VectorXd::Zero(n);
  for (int v = 0; v < n; ++v) {
    if (!eliminated[v]) {
      triplets.emplace_back(v, red.free_index[v], 1.0);
      continue;
    }
    red.z0(v) = expr[v].constant;
    for (auto [u, c] : expr[v].terms)
      if (c != 0.0) triplets.emplace_back(v, red.free_index[u], c);
  }
  red.Z.resize(n, m);
  red.Z.setFromTriplets(triplets.begin(), triplets.end());
  return red;
}

}  // namespace qs
