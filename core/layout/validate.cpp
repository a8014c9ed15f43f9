#include "core/layout/validate.h"

#include <algorithm>
#include <map>
#include <numeric>
#include <set>
#include <sstream>

#include "core/base/errors.h"
#include "core/mesh/mesh_checks.h"

namespace qs {

bool ValidationResult::valid() const {
  return errors() == 0;
}

namespace {

int count_issues(const std::vector<LayoutIssue>& issues, IssueSeverity severity) {
  int count = 0;
  for (const auto& i : issues)
    if (i.severity == severity) count += i.omitted > 0 ? i.omitted : 1;
  return count;
}

}  // namespace

int ValidationResult::errors() const {
  return count_issues(issues, IssueSeverity::Error);
}

int ValidationResult::warnings() const {
  return count_issues(issues, IssueSeverity::Warning);
}

std::string format_issue(const LayoutIssue& issue) {
  std::ostringstream ss;
  ss << (issue.severity == IssueSeverity::Error ? "error" : "warning") << " [" << issue.code << "] "
     << issue.message;
  return ss.str();
}

void require_valid_layout(const TriMesh& mesh, const Layout& layout, const std::string& what) {
  const ValidationResult result = validate_layout(mesh, layout);
  if (result.valid()) return;
  std::string msg =
      what + " is not a valid layout (" + std::to_string(result.errors()) + " error(s)):";
  int shown = 0;
  for (const auto& issue : result.issues) {
    if (issue.severity != IssueSeverity::Error) continue;
    if (++shown > 12) {
      msg += "\n  ...";
      break;
    }
    msg += "\n  " + format_issue(issue);
  }
  throw InvalidInputError(msg);
}

namespace {

std::string join(const std::vector<int>& ids, size_t max_count = 12) {
  std::ostringstream ss;
  for (size_t i = 0; i < ids.size() && i < max_count; ++i) ss << (i ? ", " : "") << ids[i];
  if (ids.size() > max_count) ss << ", … (" << ids.size() << " in all)";
  return ss.str();
}

class Validator {
 public:
  Validator(const TriMesh& mesh, const Layout& layout) : mesh_(mesh), layout_(layout) {}

  ValidationResult run() {
    const bool ids_ok = check_ids();
    const bool paths_ok = ids_ok && check_paths();
    check_features();
    if (paths_ok && check_disjoint()) check_topology();
    for (const auto& [key, count] : omitted_) {
      LayoutIssue summary;
      summary.severity = key.first;
      summary.code = key.second;
      summary.message = "… and " + std::to_string(count) + " more of the same kind";
      summary.omitted = count;
      result_.issues.push_back(std::move(summary));
    }
    return std::move(result_);
  }

 private:
  // Each returns the listed issue, or nullptr when it is only counted (see omitted_).
  LayoutIssue* error(std::string code, std::string message, std::vector<int> nodes = {},
                     std::vector<int> arcs = {}, std::vector<int> vertices = {}) {
    return add(IssueSeverity::Error, std::move(code), std::move(message), std::move(nodes),
               std::move(arcs), std::move(vertices));
  }
  LayoutIssue* warning(std::string code, std::string message, std::vector<int> nodes = {},
                       std::vector<int> arcs = {}, std::vector<int> vertices = {}) {
    return add(IssueSeverity::Warning, std::move(code), std::move(message), std::move(nodes),
               std::move(arcs), std::move(vertices));
  }
  LayoutIssue* add(IssueSeverity s, std::string code, std::string message, std::vector<int> nodes,
                   std::vector<int> arcs, std::vector<int> vertices) {
    if (listed_[{s, code}]++ >= kMaxListedIssuesPerCode) {
      ++omitted_[{s, std::move(code)}];
      return nullptr;
    }
    LayoutIssue issue;
    issue.severity = s;
    issue.code = std::move(code);
    issue.message = std::move(message);
    issue.node_ids = std::move(nodes);
    issue.arc_ids = std::move(arcs);
    issue.vertices = std::move(vertices);
    result_.issues.push_back(std::move(issue));
    return &result_.issues.back();
  }

  int nv() const { return static_cast<int>(mesh_.n_vertices()); }

  // Ids unique and non-negative, node vertices in range and distinct, arc ends known.
  bool check_ids() {
    bool ok = true;
    if (layout_.mesh_vertices >= 0 && (layout_.mesh_vertices != nv() ||
                                       layout_.mesh_faces != static_cast<int>(mesh_.n_faces()))) {
      error("mesh_mismatch", "layout was made for a mesh with " +
                                 std::to_string(layout_.mesh_vertices) + " vertices and " +
                                 std::to_string(layout_.mesh_faces) + " faces, but the mesh has " +
                                 std::to_string(nv()) + " and " + std::to_string(mesh_.n_faces()));
      ok = false;
    }
    if (layout_.nodes.empty()) {
      error("empty_layout", "the layout has no nodes");
      return false;
    }
    std::map<int, int> node_ids, arc_ids;
    std::map<int, int> vertex_node;
    for (const auto& n : layout_.nodes) {
      if (n.id < 0) error("bad_id", "node id " + std::to_string(n.id) + " is negative"), ok = false;
      if (node_ids[n.id]++ == 1)
        error("duplicate_id", "node id " + std::to_string(n.id) + " is used more than once",
              {n.id}),
            ok = false;
      if (n.vertex < 0 || n.vertex >= nv()) {
        error("bad_vertex",
              "node " + std::to_string(n.id) + ": vertex " + std::to_string(n.vertex) +
                  " is out of range (mesh has " + std::to_string(nv()) + " vertices)",
              {n.id});
        ok = false;
        continue;
      }
      auto [it, inserted] = vertex_node.emplace(n.vertex, n.id);
      if (!inserted) {
        error("nodes_share_vertex",
              "nodes " + std::to_string(it->second) + " and " + std::to_string(n.id) +
                  " are on the same vertex " + std::to_string(n.vertex),
              {it->second, n.id}, {}, {n.vertex});
        ok = false;
      }
    }
    for (const auto& a : layout_.arcs) {
      if (a.id < 0) error("bad_id", "arc id " + std::to_string(a.id) + " is negative"), ok = false;
      if (arc_ids[a.id]++ == 1)
        error("duplicate_id", "arc id " + std::to_string(a.id) + " is used more than once", {},
              {a.id}),
            ok = false;
      if (layout_.node_index(a.from) < 0) {
        error("unknown_node",
              "arc " + std::to_string(a.id) + ": 'from' refers to unknown node " +
                  std::to_string(a.from),
              {}, {a.id});
        ok = false;
      }
      if (!a.dangling() && layout_.node_index(a.to) < 0) {
        error(
            "unknown_node",
            "arc " + std::to_string(a.id) + ": 'to' refers to unknown node " + std::to_string(a.to),
            {}, {a.id});
        ok = false;
      }
    }
    return ok;
  }

  // Every path is a chain of mesh edges joining its nodes.
  bool check_paths() {
    bool ok = true;
    for (const auto& a : layout_.arcs) {
      const std::string name = "arc " + std::to_string(a.id);
      const auto& p = a.path;
      if (p.size() < 2) {
        error("bad_path",
              name + ": path has " + std::to_string(p.size()) +
                  " vertices; an arc needs at least one mesh edge",
              {}, {a.id});
        ok = false;
        continue;
      }
      bool in_range = true;
      for (int v : p) {
        if (v < 0 || v >= nv()) {
          error("bad_path",
                name + ": path vertex " + std::to_string(v) + " is out of range (mesh has " +
                    std::to_string(nv()) + " vertices)",
                {}, {a.id});
          in_range = false;
          break;
        }
      }
      if (!in_range) {
        ok = false;
        continue;
      }
      const int from_v = layout_.nodes[layout_.node_index(a.from)].vertex;
      if (p.front() != from_v) {
        error("path_not_at_node",
              name + ": path starts at vertex " + std::to_string(p.front()) + " but node " +
                  std::to_string(a.from) + " is at vertex " + std::to_string(from_v),
              {a.from}, {a.id}, {p.front(), from_v});
        ok = false;
      }
      if (a.dangling()) {
        if (!mesh_.is_boundary(mesh_.vertex_handle(p.back()))) {
          error("dangling_not_on_boundary",
                name + " is dangling but ends at vertex " + std::to_string(p.back()) +
                    ", which is not on the mesh boundary",
                {}, {a.id}, {p.back()});
          ok = false;
        }
      } else {
        const int to_v = layout_.nodes[layout_.node_index(a.to)].vertex;
        if (p.back() != to_v) {
          error("path_not_at_node",
                name + ": path ends at vertex " + std::to_string(p.back()) + " but node " +
                    std::to_string(a.to) + " is at vertex " + std::to_string(to_v),
                {a.to}, {a.id}, {p.back(), to_v});
          ok = false;
        }
      }
      for (size_t k = 0; k + 1 < p.size(); ++k) {
        const auto h =
            mesh_.find_halfedge(mesh_.vertex_handle(p[k]), mesh_.vertex_handle(p[k + 1]));
        if (!h.is_valid()) {
          error("path_not_edge_chain",
                name + ": path vertices " + std::to_string(p[k]) + " and " +
                    std::to_string(p[k + 1]) + " are not joined by a mesh edge",
                {}, {a.id}, {p[k], p[k + 1]});
          ok = false;
          break;
        }
      }
      // No vertex twice (a loop arc may close on its start vertex).
      std::set<int> seen;
      const size_t last =
          (p.size() > 2 && p.front() == p.back() && a.from == a.to) ? p.size() - 1 : p.size();
      for (size_t k = 0; k < last; ++k) {
        if (!seen.insert(p[k]).second) {
          error("path_self_intersection",
                name + " visits vertex " + std::to_string(p[k]) + " twice", {}, {a.id}, {p[k]});
          ok = false;
          break;
        }
      }
    }
    return ok;
  }

  void check_features() {
    for (size_t i = 0; i < layout_.feature_edges.size(); ++i) {
      const auto [a, b] = layout_.feature_edges[i];
      const std::string where = "features.edges[" + std::to_string(i) + "]";
      if (a < 0 || b < 0 || a >= nv() || b >= nv()) {
        error("bad_feature", where + ": vertex out of range (" + std::to_string(a) + ", " +
                                 std::to_string(b) + ")");
      } else if (!mesh_.find_halfedge(mesh_.vertex_handle(a), mesh_.vertex_handle(b)).is_valid()) {
        error("bad_feature",
              where + ": (" + std::to_string(a) + ", " + std::to_string(b) + ") is not a mesh edge",
              {}, {}, {a, b});
      }
    }
  }

  // Arcs share no edge and no interior vertex, and do not pass through nodes.
  bool check_disjoint() {
    bool ok = true;
    std::vector<int> vertex_node(mesh_.n_vertices(), -1);
    for (const auto& n : layout_.nodes) vertex_node[n.vertex] = n.id;
    std::vector<int> edge_owner(mesh_.n_edges(), -1);
    std::vector<int> vertex_owner(mesh_.n_vertices(), -1);  // interior vertices & dangling ends
    std::set<std::pair<int, int>> reported;
    auto report_pair = [&](int a, int b, const std::string& code, const std::string& msg, int v) {
      const auto key = std::minmax(a, b);
      if (reported.insert({key.first, key.second}).second) error(code, msg, {}, {a, b}, {v});
      ok = false;
    };
    for (const auto& a : layout_.arcs) {
      const auto& p = a.path;
      for (size_t k = 0; k + 1 < p.size(); ++k) {
        const auto e = mesh_.edge_handle(
            mesh_.find_halfedge(mesh_.vertex_handle(p[k]), mesh_.vertex_handle(p[k + 1])));
        int& owner = edge_owner[e.idx()];
        if (owner >= 0 && owner != a.id) {
          report_pair(owner, a.id, "arc_overlap",
                      "arcs " + std::to_string(owner) + " and " + std::to_string(a.id) +
                          " share mesh edge (" + std::to_string(p[k]) + ", " +
                          std::to_string(p[k + 1]) + ")",
                      p[k]);
        } else if (owner == a.id) {
          error("path_self_intersection",
                "arc " + std::to_string(a.id) + " uses mesh edge (" + std::to_string(p[k]) + ", " +
                    std::to_string(p[k + 1]) + ") twice",
                {}, {a.id}, {p[k], p[k + 1]});
          ok = false;
        }
        owner = a.id;
      }
      const size_t interior_end = a.dangling() ? p.size() : p.size() - 1;
      for (size_t k = 1; k < interior_end; ++k) {
        const int v = p[k];
        if (vertex_node[v] >= 0) {
          const bool own_end = a.dangling() ? false : (k == p.size() - 1);
          if (!own_end) {
            error("arc_through_node",
                  "arc " + std::to_string(a.id) + " passes through node " +
                      std::to_string(vertex_node[v]) + " (vertex " + std::to_string(v) + ")",
                  {vertex_node[v]}, {a.id}, {v});
            ok = false;
          }
          continue;
        }
        int& owner = vertex_owner[v];
        if (owner >= 0 && owner != a.id) {
          report_pair(owner, a.id, "arc_crossing",
                      "arcs " + std::to_string(owner) + " and " + std::to_string(a.id) +
                          " cross or touch at vertex " + std::to_string(v),
                      v);
        }
        owner = a.id;
      }
    }
    return ok;
  }

  void check_topology() {
    const LayoutTopology topo = build_topology(mesh_, layout_);
    // Nodes without arcs and high valences.
    for (int n = 0; n < topo.num_nodes; ++n) {
      const int id = layout_.nodes[n].id;
      const int v = layout_.nodes[n].vertex;
      if (topo.valence[n] == 0) {
        error("isolated_node",
              "node " + std::to_string(id) + " (vertex " + std::to_string(v) + ") has no arcs",
              {id}, {}, {v});
      } else if (topo.valence[n] >= 8) {
        warning("high_valence",
                "node " + std::to_string(id) + " has valence " + std::to_string(topo.valence[n]) +
                    "; nodes of valence 8 or more may not be embeddable without "
                    "fold-overs (paper §9.2)",
                {id}, {}, {v});
      }
    }
    // Patches.
    std::vector<int> first_face(topo.patches.size(), -1);
    for (int f = static_cast<int>(topo.face_patch.size()) - 1; f >= 0; --f)
      first_face[topo.face_patch[f]] = f;
    for (size_t pid = 0; pid < topo.patches.size(); ++pid) {
      const auto& P = topo.patches[pid];
      std::vector<int> arc_ids, node_ids, vertices;
      for (int d : P.darts) arc_ids.push_back(layout_.arcs[LayoutTopology::arc_of(d)].id);
      for (int c : P.corners) {
        node_ids.push_back(layout_.nodes[c].id);
        vertices.push_back(layout_.nodes[c].vertex);
      }
      if (vertices.empty()) {
        const auto f = mesh_.face_handle(first_face[pid]);
        for (auto v : mesh_.fv_range(f)) vertices.push_back(v.idx());
      }
      const std::string where = "patch containing face " + std::to_string(first_face[pid]) +
                                (arc_ids.empty() ? std::string(" (no arcs on its border)")
                                                 : " (arcs " + join(arc_ids) + ")");
      LayoutIssue* added = nullptr;
      if (P.border_cycles != 1 || P.euler != 1) {
        added = error("patch_not_disk",
                      where + " is not a disk: " + std::to_string(P.border_cycles) +
                          " border cycle(s), Euler characteristic " + std::to_string(P.euler),
                      node_ids, arc_ids, vertices);
      } else if (!P.trimmed && P.corners.size() != 4) {
        added = error("patch_valence",
                      where + " has " + std::to_string(P.corners.size()) + " corners (nodes " +
                          join(node_ids) + "); a full patch needs 4",
                      node_ids, arc_ids, vertices);
      } else if (P.trimmed && P.corners.size() >= 4) {
        added = error("patch_valence",
                      where + " is trimmed by the boundary and has " +
                          std::to_string(P.corners.size()) + " corners (nodes " + join(node_ids) +
                          "); a trimmed patch needs fewer than 4",
                      node_ids, arc_ids, vertices);
      }
      if (added) added->patch_faces = {first_face[pid]};
    }
    // Layout connectivity (boundary loops connect what touches them).
    std::vector<int> parent(topo.num_nodes, 0);
    std::iota(parent.begin(), parent.end(), 0);
    auto find = [&](int x) {
      while (parent[x] != x) x = parent[x] = parent[parent[x]];
      return x;
    };
    auto unite = [&](int a, int b) { parent[find(a)] = find(b); };
    const auto loops = boundary_loops(mesh_);
    std::vector<int> vertex_loop(mesh_.n_vertices(), -1);
    for (size_t l = 0; l < loops.size(); ++l)
      for (int v : loops[l]) vertex_loop[v] = static_cast<int>(l);
    std::vector<int> loop_rep(loops.size(), -1);
    auto touch_loop = [&](int node, int v) {
      const int l = vertex_loop[v];
      if (l < 0) return;
      if (loop_rep[l] < 0)
        loop_rep[l] = node;
      else
        unite(node, loop_rep[l]);
    };
    for (const auto& a : layout_.arcs) {
      const int na = layout_.node_index(a.from);
      if (!a.dangling()) unite(na, layout_.node_index(a.to));
      for (int v : a.path) touch_loop(na, v);
    }
    for (int n = 0; n < topo.num_nodes; ++n) touch_loop(n, layout_.nodes[n].vertex);
    std::map<int, int> comps;
    for (int n = 0; n < topo.num_nodes; ++n) comps.emplace(find(n), layout_.nodes[n].id);
    if (comps.size() > 1) {
      std::vector<int> reps;
      for (auto& [root, id] : comps) reps.push_back(id);
      error("layout_disconnected",
            "the layout has " + std::to_string(comps.size()) +
                " separate parts on one connected surface (nodes " + join(reps) +
                " are in different parts)",
            reps);
    }
    // Euler characteristic (closed surfaces; with boundary it follows from the disk checks).
    if (loops.empty()) {
      const int chi_mesh = static_cast<int>(mesh_.n_vertices()) -
                           static_cast<int>(mesh_.n_edges()) + static_cast<int>(mesh_.n_faces());
      const int chi_layout = topo.num_nodes - topo.num_arcs + static_cast<int>(topo.patches.size());
      if (chi_mesh != chi_layout) {
        error("euler_mismatch",
              "nodes − arcs + patches = " + std::to_string(topo.num_nodes) + " − " +
                  std::to_string(topo.num_arcs) + " + " + std::to_string(topo.patches.size()) +
                  " = " + std::to_string(chi_layout) +
                  ", but the surface has Euler characteristic " + std::to_string(chi_mesh));
      }
    }
  }

  const TriMesh& mesh_;
  const Layout& layout_;
  ValidationResult result_;
  // Issues found per (severity, code), and those beyond kMaxListedIssuesPerCode (not listed).
  std::map<std::pair<IssueSeverity, std::string>, int> listed_, omitted_;
};

}  // namespace

ValidationResult validate_layout(const TriMesh& mesh, const Layout& layout) {
  return Validator(mesh, layout).run();
}

}  // namespace qs
