#include "core/extract/tracing.h"

#include <cmath>
#include <future>
#include <limits>
#include <utility>
#include <vector>

namespace qs {

namespace {

using HH = OpenMesh::HalfedgeHandle;
using V2 = std::array<double, 2>;

double cross(const V2& a, const V2& b) {
  return a[0] * b[1] - a[1] * b[0];
}
double dot(const V2& a, const V2& b) {
  return a[0] * b[0] + a[1] * b[1];
}
V2 sub(const V2& a, const V2& b) {
  return {a[0] - b[0], a[1] - b[1]};
}
V2 lerp(const V2& a, const V2& b, double t) {
  return {a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])};
}
double norm(const V2& a) {
  return std::hypot(a[0], a[1]);
}

class Tracer {
 public:
  Tracer(const TriMesh& mesh, const GeometryCache& g, const std::vector<int>& p,
         const std::vector<V2>& uv, const std::vector<int>& node_at_vertex, const TraceOptions& opt)
      : mesh_(mesh), g_(g), p_(p), uv_(uv), node_at_(node_at_vertex), opt_(opt) {}

  TracedArc trace(int start_vertex, int chart_face, int symbol, int end_node, int start_node) {
    const V2 dir = rotate(symbol, V2{1.0, 0.0});
    const std::vector<Start> starts = start_sectors(start_vertex, chart_face, dir);
    if (starts.empty()) {
      TracedArc out;
      out.iso_u = symbol % 2 == 1;
      return fail(out, "no start sector at vertex " + std::to_string(start_vertex) +
                           fold_note(start_vertex));
    }
    // The nearest occurrence first; the other one when only it reaches the end node.
    TracedArc first = trace_from(start_vertex, starts[0], symbol, end_node, start_node);
    if (first.ok || starts.size() < 2) return first;
    TracedArc second = trace_from(start_vertex, starts[1], symbol, end_node, start_node);
    return second.ok ? second : first;
  }

 private:
  struct Start {
    int face = -1;
    V2 dir{0, 0};
  };

  TracedArc trace_from(int start_vertex, const Start& start, int symbol, int end_node,
                       int start_node) {
    TracedArc out;
    out.iso_u = symbol % 2 == 1;
    int face = start.face;
    V2 dir = start.dir;
    add_vertex_sample(out, face, start_vertex);
    V2 point = at(face, start_vertex);
    int at_vertex = start_vertex;
    HH entry;  // halfedge of `face` we entered through (invalid at a vertex)
    const long cap = static_cast<long>(opt_.max_steps_factor) * g_.n_faces + 16;
    for (long step = 0; step < cap; ++step) {
      const Event ev = next_event(face, point, dir, at_vertex, entry);
      if (ev.vertex < 0 && ev.edge < 0)
        return fail(out, "stuck in face " + std::to_string(face) +
                             (folded(face) ? " (folded in the parameterization)"
                                           : " (fold-over or degenerate chart)"));
      const auto& fv = g_.face_vertices[face];
      const int axis = constant_axis(dir);
      const double best = ev.progress;
      const int best_vertex = ev.vertex, best_edge = ev.edge;
      const double best_t = ev.t;
      out.param_length += best;
      if (best_vertex >= 0) {
        const int w = fv[best_vertex];
        // The line passes within eps of w. It goes on at its own constant coordinate, offset
        // from w by `beside` (perpendicular to dir, carried into the next face's chart with
        // dir): taking w's coordinate instead let the line drift by up to eps at every vertex
        // it grazed, and a line along mesh edges then passed beside its end node.
        V2 beside{0, 0};
        beside[axis] = point[axis] - uv_[3 * face + best_vertex][axis];
        add_vertex_sample(out, face, w);
        if (node_at_[w] >= 0) {
          if (node_at_[w] == end_node) {
            out.ok = true;
            return out;
          }
          return fail(out, "runs into node " + std::to_string(node_at_[w]) + " (vertex " +
                               std::to_string(w) + ")" + fold_note(start_vertex));
        }
        if (mesh_.is_boundary(mesh_.vertex_handle(w)) && end_node < 0) {
          out.ok = true;
          return out;
        }
        at_vertex = w;
        entry = HH();
        if (!find_sector(w, face, dir, beside))
          return fail(out, "no continuation at vertex " + std::to_string(w) + fold_note(w));
        point = at(face, w);
        point = {point[0] + beside[0], point[1] + beside[1]};
        continue;
      }
      // Edge crossing.
      const int k = best_edge, l = (k + 1) % 3;
      const HH h = face_halfedge(face, k);
      add_edge_sample(out, face, k, best_t);
      const HH opp = mesh_.opposite_halfedge_handle(h);
      if (mesh_.is_boundary(opp)) {
        if (end_node < 0) {
          out.ok = true;
          return out;
        }
        return fail(out, "leaves the surface at edge (" + std::to_string(fv[k]) + ", " +
                             std::to_string(fv[l]) + ")");
      }
      const int next = mesh_.face_handle(opp).idx();
      const int r = step_rotation(p_[mesh_.edge_handle(h).idx()], fv[k], fv[l]);
      dir = rotate(r, dir);
      point = lerp(at(next, fv[k]), at(next, fv[l]), best_t);
      face = next;
      entry = opp;
      at_vertex = -1;
    }
    (void)start_node;
    return fail(out, "step limit reached");
  }

  // What the line meets next in a face, ahead along its direction.
  struct Event {
    int vertex = -1;      //!< corner (0..2) of a vertex the line passes within the snap distance
    int edge = -1;        //!< else the edge fv[edge] → fv[edge + 1] it crosses
    double t = 0;         //!< the crossing's parameter along that edge
    double progress = 0;  //!< parametric distance from the line's point, along its direction
  };

  static int constant_axis(const V2& dir) { return std::abs(dir[0]) > 0.5 ? 1 : 0; }

  // The face's halfedge fv[k] → fv[k + 1] (the face's own loop: no vertex circulation as in
  // find_halfedge).
  HH face_halfedge(int f, int k) const {
    const int from = g_.face_vertices[f][k];
    HH h = mesh_.halfedge_handle(mesh_.face_handle(f));
    while (mesh_.from_vertex_handle(h).idx() != from) h = mesh_.next_halfedge_handle(h);
    return h;
  }

  // The first vertex hit or edge crossing ahead of `point` along `dir` (an axis direction) in
  // face f's chart, other than vertex `at_vertex` and the halfedge `entry` the line came in
  // through; none (vertex and edge −1) when the line does not go on through f. A vertex within
  // the snap distance of the line (TraceOptions::vertex_snap, relative to the face's parametric
  // size) is hit, and the line crosses no edge at it.
  Event next_event(int f, const V2& point, const V2& dir, int at_vertex, HH entry) const {
    const auto& fv = g_.face_vertices[f];
    const int axis = constant_axis(dir);
    const double c = point[axis];
    double diam = 0;
    for (int k = 0; k < 3; ++k)
      diam = std::max(diam, norm(sub(uv_[3 * f + k], uv_[3 * f + (k + 1) % 3])));
    const double eps = opt_.vertex_snap * std::max(diam, 1e-300);
    double lam[3];
    bool snapped[3];
    for (int k = 0; k < 3; ++k) {
      lam[k] = uv_[3 * f + k][axis] - c;
      snapped[k] = std::abs(lam[k]) <= eps;
    }
    // Any progress counts, not only more than the snap distance: a line through a corner of
    // the face beside a vertex it does not graze advances by less than that there.
    Event ev;
    for (int k = 0; k < 3; ++k) {
      if (fv[k] == at_vertex || !snapped[k]) continue;
      const double prog = dot(sub(uv_[3 * f + k], point), dir);
      if (prog > ev.progress) ev = {k, -1, 0, prog};
    }
    for (int k = 0; k < 3; ++k) {
      const int l = (k + 1) % 3;
      if (snapped[k] || snapped[l]) continue;
      if ((lam[k] > 0) == (lam[l] > 0)) continue;
      if (entry.is_valid() && face_halfedge(f, k) == entry) continue;
      const double t = lam[k] / (lam[k] - lam[l]);
      const double prog = dot(sub(lerp(uv_[3 * f + k], uv_[3 * f + l], t), point), dir);
      if (prog > ev.progress) ev = {-1, k, t, prog};
    }
    return ev;
  }

  // Whether the line leaving vertex w at offset `beside` (perpendicular to dir; zero at a node)
  // in direction dir goes on through face f (f's chart).
  bool goes_through(int f, int w, const V2& dir, const V2& beside) const {
    const V2 W = at(f, w);
    const Event ev = next_event(f, {W[0] + beside[0], W[1] + beside[1]}, dir, w, HH());
    return ev.vertex >= 0 || ev.edge >= 0;
  }

  // A line along an edge of f's corner wedge at w lies in the wedges on both sides of that
  // edge up to the tolerance; only on one of them does it go on (the side it passes w on, or
  // the side of the edge's far vertex it passes). When it does not go on through f (chart
  // `dir`, `beside`), this takes the neighbouring face across that edge if it holds the
  // direction and the line goes on there (and carries dir and beside into its chart).
  void settle_on_edge(int w, int& f, V2& dir, V2& beside) const {
    if (goes_through(f, w, dir, beside)) return;
    const int k = corner_of(g_, f, w);
    const V2 W = uv_[3 * f + k];
    const V2 a = sub(uv_[3 * f + (k + 1) % 3], W), b = sub(uv_[3 * f + (k + 2) % 3], W);
    const double tol = 1e-9;
    HH cur = outgoing_in_face(w, f);
    V2 d = dir;
    if (std::abs(cross(a, dir)) <= tol * norm(a) && dot(a, dir) > 0)
      cur = step_cw(cur, w, d);  // across the first edge
    else if (std::abs(cross(b, dir)) <= tol * norm(b) && dot(b, dir) > 0)
      cur = step_ccw(cur, w, d);  // across the second edge
    else
      return;
    if (!cur.is_valid()) return;
    const int f2 = mesh_.face_handle(cur).idx();
    const V2 b2 = rotate(quarter_turns(dir, d), beside);
    if (!in_wedge(f2, w, d) || !goes_through(f2, w, d, b2)) return;
    f = f2;
    dir = d;
    beside = b2;
  }

  V2 at(int f, int v) const { return uv_[3 * f + corner_of(g_, f, v)]; }

  // The quarter turns r with rotate(r, from) == to (axis directions).
  static int quarter_turns(const V2& from, const V2& to) {
    for (int r = 1; r < 4; ++r)
      if (rotate(r, from) == to) return r;
    return 0;
  }

  bool folded(int f) const {
    const V2 a = sub(uv_[3 * f + 1], uv_[3 * f]), b = sub(uv_[3 * f + 2], uv_[3 * f]);
    return !(cross(a, b) > 0);
  }

  // " (face F at vertex w is folded …)" when a face around vertex w is folded: the arc's
  // sector has no consistent chart there, so no tracer can leave the node correctly. Every
  // failure seen on real inputs (spot, fandisk with --no-node-opt) had such a fold.
  std::string fold_note(int w) const {
    for (auto f : mesh_.vf_range(mesh_.vertex_handle(w)))
      if (folded(f.idx()))
        return " (face " + std::to_string(f.idx()) + " at vertex " + std::to_string(w) +
               " is folded in the parameterization)";
    return "";
  }

  TracedArc& fail(TracedArc& out, std::string why) {
    out.ok = false;
    out.failure = std::move(why);
    return out;
  }

  // Is `dir` inside the corner wedge of face f at vertex w (in f's chart)?
  bool in_wedge(int f, int w, const V2& dir) const {
    const int k = corner_of(g_, f, w);
    const V2 W = uv_[3 * f + k];
    V2 a = sub(uv_[3 * f + (k + 1) % 3], W), b = sub(uv_[3 * f + (k + 2) % 3], W);
    const double la = norm(a), lb = norm(b);
    if (la == 0 || lb == 0) return false;
    a = {a[0] / la, a[1] / la};
    b = {b[0] / lb, b[1] / lb};
    if (cross(a, b) <= 0) return false;  // folded corner
    const double tol = 1e-9;
    return cross(a, dir) >= -tol && cross(dir, b) >= -tol;
  }

  // Angle at w from the direction of w's edge `first` (w → next corner of f) to `d`, ccw, in
  // f's chart, and the angle of the whole corner wedge (negative when folded).
  double angle_from_first_edge(int f, int w, const V2& d) const {
    const int k = corner_of(g_, f, w);
    const V2 a = sub(uv_[3 * f + (k + 1) % 3], uv_[3 * f + k]);
    return std::atan2(cross(a, d), dot(a, d));
  }
  double wedge_angle(int f, int w) const {
    const int k = corner_of(g_, f, w);
    const V2 a = sub(uv_[3 * f + (k + 1) % 3], uv_[3 * f + k]);
    const V2 b = sub(uv_[3 * f + (k + 2) % 3], uv_[3 * f + k]);
    return std::atan2(cross(a, b), dot(a, b));
  }

  // The start of an arc at its node vertex w: `face` is the chart face left of the arc's first
  // edge (w → next corner), `dir` its direction there. Around a cone vertex the same direction
  // occurs more than once (a valence-5 node's 450° hold it at two positions 90° apart): the
  // first occurrence each way around w (ccw from the first edge, `face` included, and cw
  // across it, through the transitions), the one nearer the first edge in parametric angle
  // first. Only one of them is the iso-line that reaches the arc's end
  // node; trace() tries the second when the first does not. (Alternating single steps both
  // ways took the occurrence fewer wedges away: on the 70K bunny after node optimization
  // three arcs of a valence-5 node started one sector off and ran into their neighbours'
  // nodes, although the parameterization had no fold-over.)
  // An arc along a mesh edge starts on the side of it where its line goes on
  // (settle_on_edge).
  std::vector<Start> start_sectors(int w, int face, const V2& dir) const {
    auto [ccw, ccw_angle] = first_occurrence(w, face, dir, true);
    auto [cw, cw_angle] = first_occurrence(w, face, dir, false);
    for (Start* s : {&ccw, &cw}) {
      V2 beside{0, 0};
      if (s->face >= 0) settle_on_edge(w, s->face, s->dir, beside);
    }
    std::vector<Start> out;
    if (ccw.face >= 0) out.push_back(ccw);
    // (Both ways can end in one face with two different directions: keep both.)
    if (cw.face >= 0 && (cw.face != ccw.face || norm(sub(cw.dir, ccw.dir)) > 1e-9))
      out.push_back(cw);
    if (out.size() == 2 && cw_angle < ccw_angle) std::swap(out[0], out[1]);
    return out;
  }

  // The first face around w whose wedge holds `dir` (carried through the transitions): ccw from
  // the first edge with `face` included, or cw across the first edge; with the parametric angle
  // swept from the first edge to that occurrence (infinity and face −1 when there is none).
  std::pair<Start, double> first_occurrence(int w, int face, const V2& dir, bool ccw) const {
    if (ccw && in_wedge(face, w, dir)) return {{face, dir}, angle_from_first_edge(face, w, dir)};
    HH cur = outgoing_in_face(w, face);
    V2 d = dir;
    double swept = ccw ? wedge_angle(face, w) : 0;
    const int degree = vertex_degree(w);
    for (int s = 0; s < degree && (cur = ccw ? step_ccw(cur, w, d) : step_cw(cur, w, d)).is_valid();
         ++s) {
      const int f = mesh_.face_handle(cur).idx();
      if (in_wedge(f, w, d)) {
        const double a = angle_from_first_edge(f, w, d);
        return {{f, d}, swept + (ccw ? a : wedge_angle(f, w) - a)};
      }
      swept += wedge_angle(f, w);
    }
    return {{-1, dir}, std::numeric_limits<double>::infinity()};
  }

  // The outgoing halfedge of vertex w in face f, and w's number of outgoing halfedges.
  HH outgoing_in_face(int w, int f) const {
    const auto vw = mesh_.vertex_handle(w);
    for (auto h : mesh_.fh_range(mesh_.face_handle(f)))
      if (mesh_.from_vertex_handle(h) == vw) return h;
    return HH();
  }
  int vertex_degree(int w) const {
    int degree = 0;
    for (auto h : mesh_.voh_range(mesh_.vertex_handle(w))) (void)h, ++degree;
    return degree;
  }
  // One face around w from the face of w's outgoing halfedge `cur`: cw crosses cur's edge,
  // ccw crosses the edge of prev(cur) (the wedge's second side). Returns the next face's
  // outgoing halfedge of w (invalid at the boundary) and carries `d` into its chart.
  HH step_cw(HH cur, int w, V2& d) const {
    const HH opp = mesh_.opposite_halfedge_handle(cur);
    if (mesh_.is_boundary(opp)) return HH();
    d = rotate(
        step_rotation(p_[mesh_.edge_handle(cur).idx()], w, mesh_.to_vertex_handle(cur).idx()), d);
    return mesh_.next_halfedge_handle(opp);
  }
  HH step_ccw(HH cur, int w, V2& d) const {
    const HH in = mesh_.prev_halfedge_handle(cur);
    const HH out = mesh_.opposite_halfedge_handle(in);
    if (mesh_.is_boundary(out)) return HH();
    d = rotate(
        step_rotation(p_[mesh_.edge_handle(in).idx()], mesh_.from_vertex_handle(in).idx(), w), d);
    return out;
  }

  // Finds the face around w (starting at `face`, sweeping both ways with transitions) whose
  // corner wedge contains dir, on the side of the edge the line passes when dir runs along
  // one (settle_on_edge); updates face, dir and the line's offset `beside` from w to that
  // face's chart.
  bool find_sector(int w, int& face, V2& dir, V2& beside) const {
    const V2 dir0 = dir;
    if (!find_wedge(w, face, dir)) return false;
    beside = rotate(quarter_turns(dir0, dir), beside);
    settle_on_edge(w, face, dir, beside);
    return true;
  }
  bool find_wedge(int w, int& face, V2& dir) const {
    if (in_wedge(face, w, dir)) return true;
    const HH o0 = outgoing_in_face(w, face);
    const int degree = vertex_degree(w);
    HH cw = o0, ccw = o0;
    V2 dcw = dir, dccw = dir;
    for (int s = 0; s < degree && (cw.is_valid() || ccw.is_valid()); ++s) {
      if (cw.is_valid() && (cw = step_cw(cw, w, dcw)).is_valid()) {
        const int f = mesh_.face_handle(cw).idx();
        if (in_wedge(f, w, dcw)) {
          face = f, dir = dcw;
          return true;
        }
      }
      if (ccw.is_valid() && (ccw = step_ccw(ccw, w, dccw)).is_valid()) {
        const int f = mesh_.face_handle(ccw).idx();
        if (in_wedge(f, w, dccw)) {
          face = f, dir = dccw;
          return true;
        }
      }
    }
    return false;
  }

  void add_vertex_sample(TracedArc& out, int f, int v) {
    SurfacePoint sp;
    sp.face = f;
    sp.bary = {0, 0, 0};
    sp.bary[corner_of(g_, f, v)] = 1;
    out.samples.push_back(sp);
    const auto& x = mesh_.point(mesh_.vertex_handle(v));
    out.polyline.push_back({x[0], x[1], x[2]});
    out.uv.push_back(at(f, v));
  }

  void add_edge_sample(TracedArc& out, int f, int k, double t) {
    const int l = (k + 1) % 3;
    SurfacePoint sp;
    sp.face = f;
    sp.bary = {0, 0, 0};
    sp.bary[k] = 1 - t;
    sp.bary[l] = t;
    out.samples.push_back(sp);
    const auto& fv = g_.face_vertices[f];
    const Vec3 x = (1 - t) * mesh_.point(mesh_.vertex_handle(fv[k])) +
                   t * mesh_.point(mesh_.vertex_handle(fv[l]));
    out.polyline.push_back({x[0], x[1], x[2]});
    out.uv.push_back(lerp(uv_[3 * f + k], uv_[3 * f + l], t));
  }

  const TriMesh& mesh_;
  const GeometryCache& g_;
  const std::vector<int>& p_;
  const std::vector<V2>& uv_;
  const std::vector<int>& node_at_;
  TraceOptions opt_;
};

}  // namespace

Extraction extract_layout(const TriMesh& mesh, const GeometryCache& g, const Layout& layout,
                          const LayoutTopology& topo, const Labeling& labeling,
                          const std::vector<int>& p, const std::vector<V2>& uv,
                          const TraceOptions& opt) {
  Extraction ex;
  std::vector<int> node_at(g.n_vertices, -1);
  for (int n = 0; n < topo.num_nodes; ++n) node_at[layout.nodes[n].vertex] = n;
  ex.arcs.resize(topo.num_arcs);
  // Arcs [begin, end) (each traced independently: Tracer keeps no state between arcs).
  auto trace_arcs = [&](int begin, int end) {
    Tracer tracer(mesh, g, p, uv, node_at, opt);
    for (int a = begin; a < end; ++a) {
      const int h = 2 * a;
      const int start_node = topo.half_node[h];
      const int end_node = topo.half_node[h + 1];
      ex.arcs[a] = tracer.trace(layout.nodes[start_node].vertex, labeling.chart_face[h],
                                labeling.symbol[h], end_node, start_node);
    }
  };
  if (opt.second_thread_arcs > 0 && topo.num_arcs >= opt.second_thread_arcs) {
    const int half = topo.num_arcs / 2;
    // (std::async's future waits in its destructor if the first half throws)
    auto second = std::async(std::launch::async, trace_arcs, half, topo.num_arcs);
    trace_arcs(0, half);
    second.get();
  } else {
    trace_arcs(0, topo.num_arcs);
  }
  for (int a = 0; a < topo.num_arcs; ++a)
    if (!ex.arcs[a].ok)
      ex.problems.push_back("arc " + std::to_string(layout.arcs[a].id) + ": " + ex.arcs[a].failure);
  // Crossings: segments of different arcs inside one face (in that face's chart). Segment i of
  // an arc (samples i, i + 1) lies in sample i + 1's face: both samples are on the boundary of
  // a common face, the one traversed. Segments by face (CSR, counting sort), and each
  // segment's end points in the face's chart computed once per face.
  std::vector<int> seg_start(g.n_faces + 1, 0);
  for (int a = 0; a < topo.num_arcs; ++a) {
    const auto& s = ex.arcs[a].samples;
    for (size_t i = 0; i + 1 < s.size(); ++i) ++seg_start[s[i + 1].face + 1];
  }
  for (int f = 0; f < g.n_faces; ++f) seg_start[f + 1] += seg_start[f];
  std::vector<std::pair<int, int>> segments(seg_start[g.n_faces]);  // (arc, sample index)
  {
    std::vector<int> next(seg_start.begin(), seg_start.end() - 1);
    for (int a = 0; a < topo.num_arcs; ++a) {
      const auto& s = ex.arcs[a].samples;
      for (size_t i = 0; i + 1 < s.size(); ++i)
        segments[next[s[i + 1].face]++] = {a, static_cast<int>(i)};
    }
  }
  std::vector<std::array<V2, 2>> ends;  // per segment of the current face: its end points
  for (int f = 0; f < g.n_faces; ++f) {
    const int first = seg_start[f], count = seg_start[f + 1] - first;
    if (count < 2) continue;
    const std::pair<int, int>* segs = &segments[first];
    bool several_arcs = false;
    for (int i = 1; i < count; ++i) several_arcs |= segs[i].first != segs[0].first;
    if (!several_arcs) continue;
    ends.resize(count);
    for (int i = 0; i < count; ++i) {
      const auto& si = ex.arcs[segs[i].first].samples;
      ends[i] = {uv_in_face(mesh, g, uv, si[segs[i].second], f),
                 uv_in_face(mesh, g, uv, si[segs[i].second + 1], f)};
    }
    for (int i = 0; i < count; ++i)
      for (int j = i + 1; j < count; ++j) {
        if (segs[i].first == segs[j].first) continue;
        const V2 &a0 = ends[i][0], &a1 = ends[i][1], &b0 = ends[j][0], &b1 = ends[j][1];
        const double d1 = cross(sub(a1, a0), sub(b0, a0)), d2 = cross(sub(a1, a0), sub(b1, a0));
        const double d3 = cross(sub(b1, b0), sub(a0, b0)), d4 = cross(sub(b1, b0), sub(a1, b0));
        const double tol = 1e-12 * (norm(sub(a1, a0)) * norm(sub(b1, b0)) + 1e-300);
        if (((d1 > tol && d2 < -tol) || (d1 < -tol && d2 > tol)) &&
            ((d3 > tol && d4 < -tol) || (d3 < -tol && d4 > tol))) {
          ++ex.crossings;
          if (ex.crossings <= 5)
            ex.problems.push_back("arcs " + std::to_string(layout.arcs[segs[i].first].id) +
                                  " and " + std::to_string(layout.arcs[segs[j].first].id) +
                                  " cross in face " + std::to_string(f));
        }
      }
  }
  // Patch sizes: lengths of the first two sides.
  ex.patch_size.resize(topo.patches.size());
  for (size_t pi = 0; pi < topo.patches.size(); ++pi) {
    const auto& darts = topo.patches[pi].darts;
    if (darts.size() >= 2)
      ex.patch_size[pi] = {ex.arcs[darts[0] >> 1].param_length,
                           ex.arcs[darts[1] >> 1].param_length};
  }
  bool all_ok = true;
  for (const auto& t : ex.arcs) all_ok &= t.ok;
  ex.structurally_equivalent = all_ok && ex.crossings == 0;
  // Parametric cone angle at every interior node.
  std::vector<std::string> cone_problems;
  for (int n = 0; n < topo.num_nodes; ++n) {
    const int w = layout.nodes[n].vertex;
    if (g.vertex_on_boundary[w]) continue;
    double cone = 0;
    for (auto f : mesh.vf_range(mesh.vertex_handle(w))) {
      const int k = corner_of(g, f.idx(), w);
      const V2 W = uv[3 * f.idx() + k];
      const V2 a = sub(uv[3 * f.idx() + (k + 1) % 3], W), b = sub(uv[3 * f.idx() + (k + 2) % 3], W);
      cone += std::atan2(cross(a, b), dot(a, b));
    }
    const double expected = topo.valence[n] * M_PI / 2;
    if (!(std::abs(cone - expected) <= M_PI / 4)) {
      ++ex.bad_cones;
      cone_problems.push_back("node " + std::to_string(layout.nodes[n].id) + " (vertex " +
                              std::to_string(w) + "): parametric cone angle " +
                              std::to_string(std::lround(cone * 180 / M_PI)) + "° instead of " +
                              std::to_string(90 * topo.valence[n]) + "°");
    }
  }
  if (!ex.structurally_equivalent)
    for (size_t i = 0; i < cone_problems.size() && i < 20; ++i)
      ex.problems.push_back(cone_problems[i]);
  return ex;
}

std::array<double, 2> uv_in_face(const TriMesh& mesh, const GeometryCache& g,
                                 const std::vector<V2>& uv, const SurfacePoint& sp, int f) {
  const auto& sv = g.face_vertices[sp.face];
  const Vec3 x = sp.bary[0] * mesh.point(mesh.vertex_handle(sv[0])) +
                 sp.bary[1] * mesh.point(mesh.vertex_handle(sv[1])) +
                 sp.bary[2] * mesh.point(mesh.vertex_handle(sv[2]));
  const auto& fv = g.face_vertices[f];
  const Vec3 p0 = mesh.point(mesh.vertex_handle(fv[0])), p1 = mesh.point(mesh.vertex_handle(fv[1])),
             p2 = mesh.point(mesh.vertex_handle(fv[2]));
  const Vec3 n = (p1 - p0) % (p2 - p0);
  const double a2 = n.sqrnorm();
  const double b1 = (((x - p0) % (p2 - p0)) | n) / a2, b2 = (((p1 - p0) % (x - p0)) | n) / a2;
  return V2{(1 - b1 - b2) * uv[3 * f][0] + b1 * uv[3 * f + 1][0] + b2 * uv[3 * f + 2][0],
            (1 - b1 - b2) * uv[3 * f][1] + b1 * uv[3 * f + 1][1] + b2 * uv[3 * f + 2][1]};
}

void annotate_layout(const TriMesh& mesh, const LayoutTopology& topo, const Extraction& ex,
                     Layout& layout) {
  for (int n = 0; n < topo.num_nodes; ++n) {
    auto& node = layout.nodes[n];
    const auto v = mesh.vertex_handle(node.vertex);
    const auto& x = mesh.point(v);
    node.position = std::array<double, 3>{x[0], x[1], x[2]};
    node.valence = topo.valence[n];
    // A face containing the vertex, with barycentric 1 at it.
    for (auto f : mesh.vf_range(v)) {
      SurfacePoint sp;
      sp.face = f.idx();
      sp.bary = {0, 0, 0};
      int k = 0;
      for (auto w : mesh.fv_range(f)) {
        if (w == v) sp.bary[k] = 1;
        ++k;
      }
      node.point = sp;
      break;
    }
  }
  for (int a = 0; a < topo.num_arcs; ++a) {
    auto& arc = layout.arcs[a];
    const auto& t = ex.arcs[a];
    arc.label = t.iso_u ? "u" : "v";
    arc.samples = t.samples;
    arc.polyline = t.polyline;
  }
  layout.patches.clear();
  for (size_t pi = 0; pi < topo.patches.size(); ++pi) {
    LayoutPatch patch;
    patch.id = static_cast<int>(pi);
    for (int c : topo.patches[pi].corners) patch.nodes.push_back(layout.nodes[c].id);
    for (int d : topo.patches[pi].darts) patch.arcs.push_back(layout.arcs[d >> 1].id);
    patch.size = ex.patch_size[pi];
    layout.patches.push_back(patch);
  }
}

}  // namespace qs
