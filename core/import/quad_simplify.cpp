#include "core/import/quad_simplify.h"

#include <algorithm>
#include <array>
#include <iterator>
#include <limits>
#include <numeric>
#include <vector>

namespace qs {

namespace {

using VH = OpenMesh::VertexHandle;

// A closed quad mesh as a face list with vertex-face incidences, edited by diagonal collapses
// and edge rotations, with an undo journal (cancel_irregular_vertices).
class QuadEditor {
 public:
  // \p normals (per vertex, unit; may be empty): the surface normal at each vertex; when given,
  // every face an operation makes or changes must turn the normals' way at each corner, with
  // sin(corner angle) > min_sine.
  QuadEditor(const PolyMesh& quads, std::vector<Vec3> normals, double min_sine)
      : normal_(std::move(normals)), min_sine_(min_sine) {
    pos_.reserve(quads.n_vertices());
    for (const auto v : quads.vertices()) pos_.push_back(quads.point(v));
    vfaces_.resize(quads.n_vertices());
    for (const auto f : quads.faces()) {
      std::array<int, 4> q{};
      int k = 0;
      for (const auto v : quads.fv_range(f)) q[k++] = v.idx();
      face_.push_back(q);
      alive_.push_back(1);
      for (int v : q) vfaces_[v].push_back(f.idx());
    }
  }

  // An operation and how much it lowers Σ (valence − 4)².
  struct Op {
    int gain = std::numeric_limits<int>::min();
    bool collapse = false;
    int f = -1, g = -1;             // collapse: face f; rotation: the two faces
    int a = -1, c = -1;             // collapse: merged corners (c into a)
    std::array<int, 4> q1{}, q2{};  // rotation: the new faces
    bool valid() const { return f >= 0; }
  };

  int valence(int v) const { return static_cast<int>(vfaces_[v].size()); }
  static int cost(int valence) { return (valence - 4) * (valence - 4); }
  bool face_alive(int f) const { return alive_[f] != 0; }
  const std::array<int, 4>& face(int f) const { return face_[f]; }
  const std::vector<int>& faces_of(int v) const { return vfaces_[v]; }
  size_t num_faces() const { return face_.size(); }
  size_t num_vertices() const { return vfaces_.size(); }

  bool adjacent(int u, int v) const {
    for (int f : vfaces_[u]) {
      const auto& q = face_[f];
      const int k = index_in(q, u);
      if (q[(k + 1) % 4] == v || q[(k + 3) % 4] == v) return true;
    }
    return false;
  }

  void neighbours(int v, std::vector<int>& out) const {
    out.clear();
    for (int f : vfaces_[v]) {
      const auto& q = face_[f];
      const int k = index_in(q, v);
      out.push_back(q[(k + 1) % 4]);
      out.push_back(q[(k + 3) % 4]);
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  }

  // Best diagonal collapse of face f.
  Op best_collapse(int f) const {
    Op best;
    const auto& q = face_[f];
    std::vector<int> na, nc, common;
    for (int k = 0; k < 2; ++k) {
      const int a = q[k], b = q[k + 1], c = q[(k + 2) % 4], d = q[(k + 3) % 4];
      const int va = valence(a), vb = valence(b), vc = valence(c), vd = valence(d);
      if (vb < 4 || vd < 4 || va + vc - 2 > kMaxValence) continue;
      neighbours(a, na);
      neighbours(c, nc);
      if (std::binary_search(na.begin(), na.end(), c)) continue;
      common.clear();
      std::set_intersection(na.begin(), na.end(), nc.begin(), nc.end(), std::back_inserter(common));
      if (common.size() != 2) continue;  // {b, d}; more would pinch the surface
      int shared = 0;
      for (int g : vfaces_[a]) shared += index_in(face_[g], c) >= 0;
      if (shared != 1) continue;
      const int gain = cost(va) + cost(vb) + cost(vc) + cost(vd) - cost(va + vc - 2) -
                       cost(vb - 1) - cost(vd - 1);
      if (gain > best.gain && !normal_.empty()) {
        // The faces around a and c with both at their midpoint.
        const Vec3 m = 0.5 * (pos_[a] + pos_[c]);
        Vec3 nm = normal_[a] + normal_[c];
        nm /= std::max(1e-12, nm.norm());
        bool ok = true;
        for (int w : {a, c}) {
          for (int g : vfaces_[w]) {
            if (g == f || !ok) continue;
            std::array<Vec3, 4> p, n;
            for (int i = 0; i < 4; ++i) {
              const int x = face_[g][i];
              p[i] = (x == a || x == c) ? m : pos_[x];
              n[i] = (x == a || x == c) ? nm : normal_[x];
            }
            ok = convex(p, n);
          }
        }
        if (!ok) continue;
      }
      if (gain > best.gain) {
        best.gain = gain;
        best.collapse = true;
        best.f = f;
        best.a = a;
        best.c = c;
      }
    }
    return best;
  }

  // Best rotation of the edge from q[k] to q[k + 1] of face f.
  Op best_rotation(int f, int k) const {
    Op best;
    const auto& q1 = face_[f];
    const int u = q1[k], v = q1[(k + 1) % 4], p = q1[(k + 2) % 4], pq = q1[(k + 3) % 4];
    if (valence(u) < 4 || valence(v) < 4) return best;
    int g = -1, k2 = -1;
    for (int h : vfaces_[v]) {
      const int i = index_in(face_[h], v);
      if (h != f && face_[h][(i + 1) % 4] == u) g = h, k2 = i;
    }
    if (g < 0) return best;
    const auto& q2 = face_[g];
    const int r = q2[(k2 + 2) % 4], s = q2[(k2 + 3) % 4];
    std::array<int, 6> six{u, v, p, pq, r, s};
    std::sort(six.begin(), six.end());
    if (std::adjacent_find(six.begin(), six.end()) != six.end()) return best;
    // The hexagon v, p, pq, u, r, s split along p–r or pq–s instead of u–v.
    const int x[2] = {p, pq}, y[2] = {r, s};
    for (int option = 0; option < 2; ++option) {
      if (valence(x[option]) + 1 > kMaxValence || valence(y[option]) + 1 > kMaxValence) continue;
      if (adjacent(x[option], y[option])) continue;
      if (!normal_.empty()) {
        const std::array<int, 4> n1 =
            option == 0 ? std::array<int, 4>{p, pq, u, r} : std::array<int, 4>{pq, u, r, s};
        const std::array<int, 4> n2 =
            option == 0 ? std::array<int, 4>{r, s, v, p} : std::array<int, 4>{s, v, p, pq};
        if (!convex_face(n1) || !convex_face(n2)) continue;
      }
      const int gain = cost(valence(u)) + cost(valence(v)) + cost(valence(x[option])) +
                       cost(valence(y[option])) - cost(valence(u) - 1) - cost(valence(v) - 1) -
                       cost(valence(x[option]) + 1) - cost(valence(y[option]) + 1);
      if (gain > best.gain) {
        best.gain = gain;
        best.collapse = false;
        best.f = f;
        best.g = g;
        if (option == 0) {
          best.q1 = {p, pq, u, r};
          best.q2 = {r, s, v, p};
        } else {
          best.q1 = {pq, u, r, s};
          best.q2 = {s, v, p, pq};
        }
      }
    }
    return best;
  }

  // Best operation on face f (its collapse or the rotation of one of its edges).
  Op best_at(int f) const {
    Op best = best_collapse(f);
    for (int k = 0; k < 4; ++k) {
      const Op r = best_rotation(f, k);
      if (r.gain > best.gain) best = r;
    }
    return best;
  }

  void apply(const Op& op) {
    if (op.collapse) {
      const std::array<int, 4> old = face_[op.f];
      set_face(op.f, old, false);
      set_position(op.a, 0.5 * (pos_[op.a] + pos_[op.c]));
      if (!normal_.empty()) {
        Vec3 nm = normal_[op.a] + normal_[op.c];
        normal_[op.a] = nm / std::max(1e-12, nm.norm());
      }
      const std::vector<int> around = vfaces_[op.c];
      for (int g : around) {
        std::array<int, 4> q = face_[g];
        for (int& v : q)
          if (v == op.c) v = op.a;
        set_face(g, q, true);
      }
    } else {
      set_face(op.f, op.q1, true);
      set_face(op.g, op.q2, true);
    }
  }

  // The journal position to undo back to.
  size_t mark() const { return journal_.size(); }
  void undo(size_t to) {
    while (journal_.size() > to) {
      const Entry e = journal_.back();
      journal_.pop_back();
      if (e.face >= 0) {
        replace(e.face, e.quad, e.alive);
      } else {
        pos_[e.vertex] = e.position;
        if (!normal_.empty()) normal_[e.vertex] = e.normal;
      }
    }
  }
  void forget() { journal_.clear(); }

  const Vec3& position(int v) const { return pos_[v]; }

 private:
  static constexpr int kMaxValence = 8;
  struct Entry {
    int face = -1;  // face entry, or -1 for a position entry
    std::array<int, 4> quad{};
    bool alive = false;
    int vertex = -1;
    Vec3 position{0, 0, 0}, normal{0, 0, 0};
  };

  // Every corner turns the way of the normal there, with sin(angle) > min_sine_.
  bool convex(const std::array<Vec3, 4>& p, const std::array<Vec3, 4>& n) const {
    for (int i = 0; i < 4; ++i) {
      const Vec3 e1 = p[(i + 1) % 4] - p[i], e2 = p[(i + 3) % 4] - p[i];
      if (OpenMesh::dot(OpenMesh::cross(e1, e2), n[i]) <= min_sine_ * e1.norm() * e2.norm())
        return false;
    }
    return true;
  }
  bool convex_face(const std::array<int, 4>& q) const {
    std::array<Vec3, 4> p, n;
    for (int i = 0; i < 4; ++i) p[i] = pos_[q[i]], n[i] = normal_[q[i]];
    return convex(p, n);
  }

  static int index_in(const std::array<int, 4>& q, int v) {
    for (int i = 0; i < 4; ++i)
      if (q[i] == v) return i;
    return -1;
  }

  void replace(int f, const std::array<int, 4>& q, bool alive) {
    if (alive_[f]) {
      for (int v : face_[f]) {
        auto& list = vfaces_[v];
        list.erase(std::find(list.begin(), list.end(), f));
      }
    }
    face_[f] = q;
    alive_[f] = alive;
    if (alive)
      for (int v : q) vfaces_[v].push_back(f);
  }
  void set_face(int f, const std::array<int, 4>& q, bool alive) {
    Entry e;
    e.face = f;
    e.quad = face_[f];
    e.alive = alive_[f] != 0;
    journal_.push_back(e);
    replace(f, q, alive);
  }
  void set_position(int v, const Vec3& p) {
    Entry e;
    e.vertex = v;
    e.position = pos_[v];
    if (!normal_.empty()) e.normal = normal_[v];
    journal_.push_back(e);
    pos_[v] = p;
  }

  std::vector<Vec3> pos_;
  std::vector<Vec3> normal_;
  double min_sine_ = 0;
  std::vector<std::array<int, 4>> face_;
  std::vector<char> alive_;
  std::vector<std::vector<int>> vfaces_;
  std::vector<Entry> journal_;
};

int count_irregular(const QuadEditor& ed) {
  int n = 0;
  for (size_t v = 0; v < ed.num_vertices(); ++v) {
    const int val = ed.valence(static_cast<int>(v));
    n += val > 0 && val != 4;
  }
  return n;
}

// Applies improving operations until there is none; returns how many.
int greedy_pass(QuadEditor& ed, int& collapses, int& rotations) {
  int applied = 0;
  for (bool changed = true; changed;) {
    changed = false;
    for (size_t f = 0; f < ed.num_faces(); ++f) {
      if (!ed.face_alive(static_cast<int>(f))) continue;
      const QuadEditor::Op op = ed.best_at(static_cast<int>(f));
      if (op.valid() && op.gain > 0) {
        ed.apply(op);
        ++(op.collapse ? collapses : rotations);
        ++applied;
        changed = true;
      }
    }
  }
  return applied;
}

// Faces within two rings of the given vertices.
std::vector<int> faces_near(const QuadEditor& ed, const std::vector<int>& vertices) {
  std::vector<int> ring, out;
  for (int v : vertices)
    for (int f : ed.faces_of(v))
      for (int w : ed.face(f)) ring.push_back(w);
  std::sort(ring.begin(), ring.end());
  ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
  for (int v : ring)
    for (int f : ed.faces_of(v)) out.push_back(f);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

// Tries neutral operations at the faces around \p vertices, each followed by the best
// operation near it when that one improves, else (depth > 1) by further neutral operations at
// the irregular vertices it touched. Keeps the first sequence that ends improving; undoes the
// rest.
bool look_ahead(QuadEditor& ed, const std::vector<int>& vertices, int depth,
                CageSimplifyStats& st) {
  std::vector<int> around;
  for (int v : vertices) around.insert(around.end(), ed.faces_of(v).begin(), ed.faces_of(v).end());
  std::sort(around.begin(), around.end());
  around.erase(std::unique(around.begin(), around.end()), around.end());
  std::vector<QuadEditor::Op> neutral;
  for (int f : around) {
    const QuadEditor::Op c = ed.best_collapse(f);
    if (c.valid() && c.gain == 0) neutral.push_back(c);
    for (int k = 0; k < 4; ++k) {
      const QuadEditor::Op r = ed.best_rotation(f, k);
      if (r.valid() && r.gain == 0) neutral.push_back(r);
    }
  }
  for (const QuadEditor::Op& op : neutral) {
    // Ops are found on the state before any of them; each is applied alone.
    const size_t m = ed.mark();
    std::vector<int> touched(ed.face(op.f).begin(), ed.face(op.f).end());
    if (!op.collapse) touched.insert(touched.end(), ed.face(op.g).begin(), ed.face(op.g).end());
    ed.apply(op);
    QuadEditor::Op best;
    for (int g : faces_near(ed, touched)) {
      if (!ed.face_alive(g)) continue;
      const QuadEditor::Op next = ed.best_at(g);
      if (next.gain > best.gain) best = next;
    }
    bool success = false;
    if (best.valid() && best.gain > 0) {
      ed.apply(best);
      ++(best.collapse ? st.collapses : st.rotations);
      success = true;
    } else if (depth > 1) {
      std::vector<int> irregular;
      for (int v : touched)
        if (ed.valence(v) != 0 && ed.valence(v) != 4) irregular.push_back(v);
      std::sort(irregular.begin(), irregular.end());
      irregular.erase(std::unique(irregular.begin(), irregular.end()), irregular.end());
      success = !irregular.empty() && look_ahead(ed, irregular, depth - 1, st);
    }
    if (success) {
      ++(op.collapse ? st.collapses : st.rotations);
      return true;
    }
    ed.undo(m);
  }
  return false;
}

}  // namespace

CageSimplifyStats cancel_irregular_vertices(PolyMesh& quads, const QuadSimplifyOptions& options,
                                            const std::vector<Vec3>* normals,
                                            std::vector<int>* kept_vertex) {
  CageSimplifyStats st;
  QuadEditor ed(quads, normals ? *normals : std::vector<Vec3>(), options.min_corner_sine);
  st.quads_before = static_cast<int>(quads.n_faces());
  st.irregular_before = count_irregular(ed);
  greedy_pass(ed, st.collapses, st.rotations);
  ed.forget();
  const int depth = std::max(1, options.depth);
  for (int round = 0; round < options.rounds; ++round) {
    int accepted = 0;
    for (size_t v0 = 0; v0 < ed.num_vertices(); ++v0) {
      const int val0 = ed.valence(static_cast<int>(v0));
      if (val0 == 0 || val0 == 4) continue;
      if (look_ahead(ed, {static_cast<int>(v0)}, depth, st)) ++accepted;
      ed.forget();
    }
    accepted += greedy_pass(ed, st.collapses, st.rotations);
    ed.forget();
    if (accepted == 0) break;
  }
  // Rebuild with the surviving vertices in their old order.
  std::vector<int> new_index(ed.num_vertices(), -1), kept;
  PolyMesh out;
  for (size_t v = 0; v < ed.num_vertices(); ++v) {
    if (ed.valence(static_cast<int>(v)) == 0) continue;
    new_index[v] = static_cast<int>(kept.size());
    kept.push_back(static_cast<int>(v));
    out.add_vertex(ed.position(static_cast<int>(v)));
  }
  for (size_t f = 0; f < ed.num_faces(); ++f) {
    if (!ed.face_alive(static_cast<int>(f))) continue;
    std::vector<VH> vs;
    for (int v : ed.face(static_cast<int>(f))) vs.emplace_back(new_index[v]);
    if (!out.add_face(vs).is_valid()) {
      // Not expected (the operations keep the mesh manifold): keep the input.
      st = CageSimplifyStats{};
      st.quads_before = st.quads_after = static_cast<int>(quads.n_faces());
      QuadEditor again(quads, {}, 0.0);
      st.irregular_before = st.irregular_after = count_irregular(again);
      if (kept_vertex) {
        kept_vertex->resize(quads.n_vertices());
        std::iota(kept_vertex->begin(), kept_vertex->end(), 0);
      }
      return st;
    }
  }
  quads = std::move(out);
  st.quads_after = static_cast<int>(quads.n_faces());
  st.irregular_after = count_irregular(ed);
  if (kept_vertex) *kept_vertex = std::move(kept);
  return st;
}

}  // namespace qs
