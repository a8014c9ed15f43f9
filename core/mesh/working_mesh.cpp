// WorkingMesh: construction, queries, splits and point insertion. Flips, moves, removal,
// compaction and measures are in working_mesh_edits.cpp.
#include "core/mesh/working_mesh.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/base/errors.h"

namespace qs {

namespace {

using VH = OpenMesh::VertexHandle;
using FH = OpenMesh::FaceHandle;
using EH = OpenMesh::EdgeHandle;

std::string bary_text(const std::array<double, 3>& b) {
  return "(" + std::to_string(b[0]) + ", " + std::to_string(b[1]) + ", " + std::to_string(b[2]) +
         ")";
}

}  // namespace

// One hypothetical split: the new vertex (origin, position), the triangles it would create
// (corner -1 = the new vertex) with their hosts, and the faces it would replace.
struct WorkingMesh::Candidate {
  enum class Kind { kEdge, kFace } kind = Kind::kFace;
  int element = -1;  // edge or face index
  SurfacePoint origin;
  bool exact = false;
  std::vector<std::array<int, 3>> triangles;
  std::vector<int> hosts;
  std::vector<int> replaced;
  // Filled by evaluate().
  bool valid = false;
  double min_angle = 0;  // degrees, smallest angle of the new triangles
  double old_angle = 0;  // degrees, smallest angle of the replaced faces
};

void validate_working_mesh_options(const WorkingMeshOptions& options) {
  if (!std::isfinite(options.snap) || options.snap < 0 || options.snap > 0.5) {
    throw InvalidInputError("working mesh: snap must be in [0, 0.5], got " +
                            std::to_string(options.snap));
  }
  if (!std::isfinite(options.min_angle_deg) || options.min_angle_deg < 0 ||
      options.min_angle_deg >= 60) {
    throw InvalidInputError("working mesh: min_angle_deg must be in [0, 60), got " +
                            std::to_string(options.min_angle_deg));
  }
}

WorkingMesh::WorkingMesh(std::shared_ptr<const TriMesh> input, WorkingMeshOptions options)
    : input_(std::move(input)), options_(options) {
  if (!input_) throw InvalidInputError("working mesh: no input mesh");
  validate_working_mesh_options(options_);
  const TriMesh& in = *input_;
  if (in.n_faces() == 0) throw InvalidInputError("working mesh: the input mesh has no faces");
  for (auto v : in.vertices()) {
    if (in.has_vertex_status() && in.status(v).deleted()) {
      throw InvalidInputError("working mesh: input vertex " + std::to_string(v.idx()) +
                              " is marked deleted (compact the input first)");
    }
  }
  for (auto f : in.all_faces()) {
    if (in.has_face_status() && in.status(f).deleted()) {
      throw InvalidInputError("working mesh: input face " + std::to_string(f.idx()) +
                              " is marked deleted (compact the input first)");
    }
  }
  n_input_ = static_cast<int>(in.n_vertices());
  const int nf = static_cast<int>(in.n_faces());
  input_corners_.resize(nf);
  for (auto f : in.faces()) {
    int k = 0;
    for (auto v : in.fv_range(f)) input_corners_[f.idx()][k++] = v.idx();
  }
  origin_.resize(n_input_);
  Vec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
  for (auto v : in.vertices()) {
    int face = -1;
    for (auto f : in.vf_range(v)) {
      face = f.idx();
      break;
    }
    if (face < 0) {
      throw InvalidInputError("working mesh: input vertex " + std::to_string(v.idx()) +
                              " belongs to no face");
    }
    SurfacePoint o;
    o.face = face;
    for (int k = 0; k < 3; ++k) o.bary[k] = input_corners_[face][k] == v.idx() ? 1.0 : 0.0;
    origin_[v.idx()] = o;
    lo.minimize(in.point(v));
    hi.maximize(in.point(v));
  }
  bbox_diagonal_ = (hi - lo).norm();
  mesh_ = in;
  host_.resize(nf);
  slot_.resize(nf);
  hosted_.assign(nf, {});
  for (int f = 0; f < nf; ++f) {
    host_[f] = f;
    slot_[f] = 0;
    hosted_[f].push_back(f);
  }
  live_faces_ = nf;
}

// ---- helpers ----

double WorkingMesh::det3(const Bary& a, const Bary& b, const Bary& c) {
  const double x = b[1] * c[2] - b[2] * c[1];
  const double y = b[2] * c[0] - b[0] * c[2];
  const double z = b[0] * c[1] - b[1] * c[0];
  return a[0] * x + a[1] * y + a[2] * z;
}

double WorkingMesh::triangle_min_angle_deg(const Vec3& a, const Vec3& b, const Vec3& c) {
  auto angle = [](const Vec3& u, const Vec3& v) {
    return std::atan2(OpenMesh::cross(u, v).norm(), OpenMesh::dot(u, v));
  };
  const double m = std::min({angle(b - a, c - a), angle(c - b, a - b), angle(a - c, b - c)});
  return m * 180.0 / M_PI;
}

int WorkingMesh::zero_count(const Bary& b) {
  return (b[0] == 0) + (b[1] == 0) + (b[2] == 0);
}

void WorkingMesh::check_vertex(int v, const char* what) const {
  if (v < 0 || v >= static_cast<int>(mesh_.n_vertices()) || mesh_.status(VH(v)).deleted()) {
    throw InvalidInputError(std::string(what) + ": no working-mesh vertex " + std::to_string(v));
  }
}

void WorkingMesh::check_face(int f, const char* what) const {
  if (f < 0 || f >= static_cast<int>(mesh_.n_faces()) || mesh_.status(FH(f)).deleted()) {
    throw InvalidInputError(std::string(what) + ": no working-mesh face " + std::to_string(f));
  }
}

void WorkingMesh::check_edge(int e, const char* what) const {
  if (e < 0 || e >= static_cast<int>(mesh_.n_edges()) || mesh_.status(EH(e)).deleted()) {
    throw InvalidInputError(std::string(what) + ": no working-mesh edge " + std::to_string(e));
  }
}

SurfacePoint WorkingMesh::checked_point(const SurfacePoint& p, const char* what) const {
  if (p.face < 0 || p.face >= static_cast<int>(input_->n_faces())) {
    throw InvalidInputError(std::string(what) + ": input face " + std::to_string(p.face) +
                            " out of range (the input has " + std::to_string(input_->n_faces()) +
                            " faces)");
  }
  // The tolerances of the layout files' points (routing's snap_to_vertex).
  bool ok = true;
  for (double b : p.bary) ok = ok && std::isfinite(b) && b >= -1e-9;
  SurfacePoint out = p;
  double sum = 0;
  for (double& b : out.bary) sum += (b = std::max(b, 0.0));
  if (!ok || !(std::abs(sum - 1) <= 1e-6)) {
    throw InvalidInputError(std::string(what) + ": barycentrics " + bary_text(p.bary) +
                            " are outside input face " + std::to_string(p.face));
  }
  // An affine combination up to rounding, so that the point lies on the face's plane; zeros
  // stay zeros. Weights that already sum to 1 up to rounding are kept bit for bit.
  if (std::abs(sum - 1) > 1e-12) {
    for (double& b : out.bary) b /= sum;
  }
  return out;
}

std::array<int, 3> WorkingMesh::corners(int f) const {
  std::array<int, 3> c{};
  int k = 0;
  for (auto v : mesh_.fv_range(FH(f))) c[k++] = v.idx();
  return c;
}

// ---- queries ----

const SurfacePoint& WorkingMesh::origin(int v) const {
  check_vertex(v, "origin");
  return origin_[v];
}

int WorkingMesh::host(int f) const {
  check_face(f, "host");
  return host_[f];
}

const std::vector<int>& WorkingMesh::hosted_faces(int input_face) const {
  if (input_face < 0 || input_face >= static_cast<int>(hosted_.size())) {
    throw InvalidInputError("hosted_faces: input face " + std::to_string(input_face) +
                            " out of range");
  }
  return hosted_[input_face];
}

Vec3 WorkingMesh::position(const SurfacePoint& p) const {
  if (p.face < 0 || p.face >= static_cast<int>(input_->n_faces())) {
    throw InvalidInputError("position: input face " + std::to_string(p.face) + " out of range");
  }
  // Zero weights are skipped and the rest summed in corner order: a point of an input edge
  // gets the same bits from both adjacent faces (two terms commute), an input corner its
  // input position exactly.
  Vec3 sum(0, 0, 0);
  bool first = true;
  for (int k = 0; k < 3; ++k) {
    if (p.bary[k] == 0) continue;
    const Vec3 term = p.bary[k] * input_->point(VH(input_corners_[p.face][k]));
    sum = first ? term : sum + term;
    first = false;
  }
  return sum;
}

std::optional<std::array<double, 3>> WorkingMesh::point_in_input_face(const SurfacePoint& p,
                                                                      int input_face) const {
  if (input_face < 0 || input_face >= static_cast<int>(input_->n_faces()) || p.face < 0 ||
      p.face >= static_cast<int>(input_->n_faces())) {
    throw InvalidInputError("point_in_input_face: input face " +
                            std::to_string(p.face < 0 ? p.face : input_face) + " out of range");
  }
  if (p.face == input_face) return p.bary;
  const auto& src = input_corners_[p.face];
  const auto& dst = input_corners_[input_face];
  Bary out{0.0, 0.0, 0.0};
  for (int k = 0; k < 3; ++k) {
    if (p.bary[k] == 0) continue;
    const auto it = std::find(dst.begin(), dst.end(), src[k]);
    if (it == dst.end()) return std::nullopt;
    out[it - dst.begin()] = p.bary[k];
  }
  return out;
}

SurfacePoint WorkingMesh::input_point(int face, const std::array<double, 3>& bary) const {
  check_face(face, "input_point");
  const int h = host_[face];
  const auto c = corners(face);
  Bary w{std::clamp(bary[0], 0.0, 1.0), std::clamp(bary[1], 0.0, 1.0),
         std::clamp(bary[2], 0.0, 1.0)};
  const double sum = w[0] + w[1] + w[2];
  SurfacePoint out;
  out.face = h;
  out.bary = {0, 0, 0};
  for (int k = 0; k < 3; ++k) {
    const Bary b = host_bary(c[k], h);
    for (int j = 0; j < 3; ++j) out.bary[j] += (sum > 0 ? w[k] / sum : 1.0 / 3) * b[j];
  }
  return out;
}

std::optional<std::array<double, 3>> WorkingMesh::bary_in_input_face(int v, int input_face) const {
  check_vertex(v, "bary_in_input_face");
  return point_in_input_face(origin_[v], input_face);
}

WorkingMesh::Bary WorkingMesh::host_bary(int v, int host) const {
  const auto b = point_in_input_face(origin_[v], host);
  if (!b) {
    throw QsError("working mesh: internal error, vertex " + std::to_string(v) +
                  " is not on input face " + std::to_string(host));
  }
  return *b;
}

WorkingMesh::Carrier WorkingMesh::carrier(int v) const {
  check_vertex(v, "carrier");
  if (v < n_input_) return Carrier::kInputVertex;
  return zero_count(origin_[v].bary) >= 1 ? Carrier::kInputEdge : Carrier::kInputFace;
}

std::optional<std::array<int, 2>> WorkingMesh::input_edge_of(int v) const {
  if (carrier(v) != Carrier::kInputEdge) return std::nullopt;
  const SurfacePoint& o = origin_[v];
  std::array<int, 2> e{};
  int k = 0;
  for (int j = 0; j < 3; ++j) {
    if (o.bary[j] != 0) e[k++] = input_corners_[o.face][j];
  }
  if (e[0] > e[1]) std::swap(e[0], e[1]);
  return e;
}

WorkingMesh::Location WorkingMesh::locate(const SurfacePoint& p) const {
  return locate_in(checked_point(p, "locate"));
}

WorkingMesh::Location WorkingMesh::locate_in(const SurfacePoint& p) const {
  Location loc;
  const int zeros = zero_count(p.bary);
  if (zeros >= 2) {
    // An input vertex: W vertex index = input vertex index.
    int k = 0;
    while (p.bary[k] == 0) ++k;
    const int v = input_corners_[p.face][k];
    for (auto f : mesh_.vf_range(VH(v))) {
      loc.face = f.idx();
      const auto c = corners(loc.face);
      for (int j = 0; j < 3; ++j) loc.bary[j] = c[j] == v ? 1.0 : 0.0;
      return loc;
    }
  }
  const int zero = zeros == 1 ? (p.bary[0] == 0 ? 0 : p.bary[1] == 0 ? 1 : 2) : -1;
  double best = -std::numeric_limits<double>::infinity();
  for (int g : hosted_[p.face]) {
    const auto c = corners(g);
    const Bary a = host_bary(c[0], p.face), b = host_bary(c[1], p.face),
               d = host_bary(c[2], p.face);
    // A point of an input edge is located in a face with an edge along it, where the weight
    // of the opposite corner is then exactly 0.
    if (zero >= 0 && (a[zero] == 0) + (b[zero] == 0) + (d[zero] == 0) != 2) continue;
    const double det = det3(a, b, d);
    const Bary l{det3(p.bary, b, d) / det, det3(a, p.bary, d) / det, det3(a, b, p.bary) / det};
    const double m = std::min({l[0], l[1], l[2]});
    if (m > best) {
      best = m;
      loc.face = g;
      loc.bary = l;
      if (m >= 0) break;
    }
  }
  if (loc.face < 0 || best < -1e-9) {
    throw QsError("working mesh: internal error, no face of input face " + std::to_string(p.face) +
                  " contains " + bary_text(p.bary));
  }
  for (double& l : loc.bary) l = std::max(l, 0.0);
  return loc;
}

double WorkingMesh::face_min_angle_deg(int f) const {
  check_face(f, "face_min_angle_deg");
  const auto c = corners(f);
  return triangle_min_angle_deg(mesh_.point(VH(c[0])), mesh_.point(VH(c[1])),
                                mesh_.point(VH(c[2])));
}

// ---- hosted-face bookkeeping ----

void WorkingMesh::add_hosted(int f, int host) {
  if (static_cast<int>(host_.size()) <= f) {
    host_.resize(f + 1, -1);
    slot_.resize(f + 1, -1);
  }
  host_[f] = host;
  slot_[f] = static_cast<int>(hosted_[host].size());
  hosted_[host].push_back(f);
}

void WorkingMesh::remove_hosted(int f) {
  auto& list = hosted_[host_[f]];
  const int s = slot_[f];
  list[s] = list.back();
  slot_[list[s]] = s;
  list.pop_back();
  slot_[f] = -1;
}

void WorkingMesh::adopt_new_faces(int first_new_face, int v) {
  // Each face split off around v has exactly one older neighbour across an edge at v: the face
  // it was split from, whose host it shares.
  for (int g = first_new_face; g < static_cast<int>(mesh_.n_faces()); ++g) {
    int parent = -1;
    for (auto h : mesh_.fh_range(FH(g))) {
      if (mesh_.from_vertex_handle(h).idx() != v && mesh_.to_vertex_handle(h).idx() != v) continue;
      const FH o = mesh_.opposite_face_handle(h);
      if (o.is_valid() && o.idx() < first_new_face) parent = o.idx();
    }
    if (parent < 0) {
      throw QsError("working mesh: internal error, split face " + std::to_string(g) +
                    " has no parent");
    }
    add_hosted(g, host_[parent]);
    ++live_faces_;
  }
}

// ---- splits ----

int WorkingMesh::add_vertex(const SurfacePoint& o) {
  const int v = mesh_.add_vertex(position(o)).idx();
  if (static_cast<int>(origin_.size()) <= v) origin_.resize(v + 1);
  origin_[v] = o;
  return v;
}

SurfacePoint WorkingMesh::edge_point(int edge, double t) const {
  const auto h0 = mesh_.halfedge_handle(EH(edge), 0);
  FH f = mesh_.face_handle(h0);
  if (!f.is_valid()) f = mesh_.face_handle(mesh_.halfedge_handle(EH(edge), 1));
  SurfacePoint o;
  o.face = host_[f.idx()];
  const Bary a = host_bary(mesh_.from_vertex_handle(h0).idx(), o.face);
  const Bary b = host_bary(mesh_.to_vertex_handle(h0).idx(), o.face);
  // Exact zeros shared by a and b (an input edge) stay exactly 0.
  for (int k = 0; k < 3; ++k) o.bary[k] = (1 - t) * a[k] + t * b[k];
  return o;
}

SurfacePoint WorkingMesh::face_point(int face, const Bary& bary) const {
  SurfacePoint o;
  o.face = host_[face];
  o.bary = {0.0, 0.0, 0.0};
  const auto c = corners(face);
  for (int j = 0; j < 3; ++j) {
    const Bary b = host_bary(c[j], o.face);
    for (int k = 0; k < 3; ++k) o.bary[k] += bary[j] * b[k];
  }
  return o;
}

WorkingMesh::Candidate WorkingMesh::edge_split_candidate(int edge, const SurfacePoint& o) const {
  Candidate c;
  c.kind = Candidate::Kind::kEdge;
  c.element = edge;
  c.origin = o;
  for (int side = 0; side < 2; ++side) {
    const auto h = mesh_.halfedge_handle(EH(edge), side);
    const FH f = mesh_.face_handle(h);
    if (!f.is_valid()) continue;
    const int a = mesh_.from_vertex_handle(h).idx(), b = mesh_.to_vertex_handle(h).idx();
    const int d = mesh_.to_vertex_handle(mesh_.next_halfedge_handle(h)).idx();
    c.triangles.push_back({a, -1, d});
    c.triangles.push_back({-1, b, d});
    c.hosts.push_back(host_[f.idx()]);
    c.hosts.push_back(host_[f.idx()]);
    c.replaced.push_back(f.idx());
  }
  return c;
}

WorkingMesh::Candidate WorkingMesh::face_split_candidate(int face, const SurfacePoint& o) const {
  Candidate c;
  c.kind = Candidate::Kind::kFace;
  c.element = face;
  c.origin = o;
  const auto v = corners(face);
  for (int k = 0; k < 3; ++k) {
    c.triangles.push_back({v[k], v[(k + 1) % 3], -1});
    c.hosts.push_back(host_[face]);
  }
  c.replaced.push_back(face);
  return c;
}

bool WorkingMesh::evaluate(Candidate& c) const {
  c.valid = true;
  c.min_angle = 180;
  const Vec3 q = position(c.origin);
  for (size_t i = 0; i < c.triangles.size(); ++i) {
    const int h = c.hosts[i];
    std::array<Bary, 3> b;
    std::array<Vec3, 3> x;
    for (int k = 0; k < 3; ++k) {
      const int v = c.triangles[i][k];
      if (v < 0) {
        const auto qb = point_in_input_face(c.origin, h);
        if (!qb) {
          c.valid = false;
          return false;
        }
        b[k] = *qb;
        x[k] = q;
      } else {
        b[k] = host_bary(v, h);
        x[k] = mesh_.point(VH(v));
      }
    }
    if (!(det3(b[0], b[1], b[2]) > kMinDet)) c.valid = false;
    c.min_angle = std::min(c.min_angle, triangle_min_angle_deg(x[0], x[1], x[2]));
  }
  c.old_angle = 180;
  for (int f : c.replaced) c.old_angle = std::min(c.old_angle, face_min_angle_deg(f));
  return c.valid;
}

int WorkingMesh::split_edge_at(int edge, const SurfacePoint& o) {
  const int first_new_face = static_cast<int>(mesh_.n_faces());
  const int v = add_vertex(o);
  mesh_.split(EH(edge), VH(v));
  adopt_new_faces(first_new_face, v);
  return v;
}

int WorkingMesh::split_face_at(int face, const SurfacePoint& o) {
  const int first_new_face = static_cast<int>(mesh_.n_faces());
  const int v = add_vertex(o);
  mesh_.split(FH(face), VH(v));
  adopt_new_faces(first_new_face, v);
  return v;
}

int WorkingMesh::split_edge(int edge, double t) {
  check_edge(edge, "split_edge");
  if (!(t > 0 && t < 1)) {
    throw InvalidInputError("split_edge: parameter t = " + std::to_string(t) +
                            " of working-mesh edge " + std::to_string(edge) + " is not in (0, 1)");
  }
  Candidate c = edge_split_candidate(edge, edge_point(edge, t));
  if (!evaluate(c)) {
    throw InvalidInputError("split_edge: t = " + std::to_string(t) +
                            " is too close to an end of working-mesh edge " + std::to_string(edge) +
                            " (a split triangle would be degenerate)");
  }
  return split_edge_at(edge, c.origin);
}

int WorkingMesh::split_face(int face, const std::array<double, 3>& bary) {
  check_face(face, "split_face");
  const double sum = bary[0] + bary[1] + bary[2];
  if (!(bary[0] > 0 && bary[1] > 0 && bary[2] > 0) || !std::isfinite(sum) ||
      !(std::abs(sum - 1) <= 1e-6)) {
    throw InvalidInputError("split_face: barycentrics " + bary_text(bary) +
                            " are not strictly inside working-mesh face " + std::to_string(face));
  }
  const double scale = std::abs(sum - 1) > 1e-12 ? 1 / sum : 1.0;
  const Bary normalized{bary[0] * scale, bary[1] * scale, bary[2] * scale};
  Candidate c = face_split_candidate(face, face_point(face, normalized));
  if (!evaluate(c)) {
    throw InvalidInputError("split_face: barycentrics " + bary_text(bary) +
                            " are too close to an edge of working-mesh face " +
                            std::to_string(face) + " (a split triangle would be degenerate)");
  }
  return split_face_at(face, c.origin);
}

// ---- insertion ----

WorkingMesh::Inserted WorkingMesh::insert_point(const SurfacePoint& p_in,
                                                const std::function<bool(int)>& may_reuse,
                                                const std::function<bool(int)>& may_split) {
  const SurfacePoint p = checked_point(p_in, "insert_point");
  const Location loc = locate_in(p);
  const int f = loc.face;
  const auto c = corners(f);
  const Vec3 x = position(p);
  std::array<Vec3, 3> cx;
  for (int k = 0; k < 3; ++k) cx[k] = mesh_.point(VH(c[k]));
  const double eps = options_.snap *
                     ((cx[0] - cx[1]).norm() + (cx[1] - cx[2]).norm() + (cx[2] - cx[0]).norm()) / 3;
  auto reusable = [&](int v) { return !may_reuse || may_reuse(v); };
  auto same_point = [&](int v) {
    const auto b = point_in_input_face(origin_[v], p.face);
    return b && *b == p.bary;
  };

  // 1. A vertex at p (two exact zero weights), or the nearest reusable one within eps.
  for (int k = 0; k < 3; ++k) {
    if (loc.bary[(k + 1) % 3] == 0 && loc.bary[(k + 2) % 3] == 0) {
      if (!reusable(c[k])) {
        throw InvalidInputError("insert_point: the point " + bary_text(p.bary) + " of input face " +
                                std::to_string(p.face) + " is working-mesh vertex " +
                                std::to_string(c[k]) + ", which may not be reused");
      }
      return {c[k], same_point(c[k]), false};
    }
  }
  int best_vertex = -1;
  double best_distance = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    auto consider = [&](int v) {
      const double d = (mesh_.point(VH(v)) - x).norm();
      if (d <= eps && d < best_distance && reusable(v)) {
        best_distance = d;
        best_vertex = v;
      }
    };
    consider(c[k]);
    for (auto w : mesh_.vv_range(VH(c[k]))) consider(w.idx());
  }
  if (best_vertex >= 0) return {best_vertex, same_point(best_vertex), false};

  // 2. Edges of f within eps (nearest first), split at p's projection; exact when p is on one.
  std::vector<std::pair<double, Candidate>> edges;
  for (int k = 0; k < 3; ++k) {
    const int a = c[(k + 1) % 3], b = c[(k + 2) % 3];
    OpenMesh::SmartHalfedgeHandle h = mesh_.find_halfedge(VH(a), VH(b));
    const int edge = h.edge().idx();
    const bool forward = mesh_.halfedge_handle(EH(edge), 0) == h;
    if (may_split && !may_split(edge)) {
      if (loc.bary[k] == 0) {
        throw InvalidInputError("insert_point: the point " + bary_text(p.bary) + " of input face " +
                                std::to_string(p.face) + " lies on working-mesh edge " +
                                std::to_string(edge) + ", which may not be split");
      }
      continue;
    }
    if (loc.bary[k] == 0) {
      // p lies on this edge. Its origin is p itself unless the edge runs along an input edge
      // and p's weights do not say so (then the edge's own interpolation is used).
      const double t_ab = loc.bary[(k + 2) % 3] / (loc.bary[(k + 1) % 3] + loc.bary[(k + 2) % 3]);
      const SurfacePoint along = edge_point(edge, forward ? t_ab : 1 - t_ab);
      const bool keep_p = zero_count(along.bary) == 0 || zero_count(p.bary) == 1;
      Candidate cand = edge_split_candidate(edge, keep_p ? p : along);
      cand.exact = keep_p;
      edges.emplace_back(0.0, std::move(cand));
      continue;
    }
    const Vec3 ab = cx[(k + 2) % 3] - cx[(k + 1) % 3];
    const double len2 = ab.sqrnorm();
    const double t = len2 > 0 ? OpenMesh::dot(x - cx[(k + 1) % 3], ab) / len2 : -1;
    if (!(t > 0 && t < 1)) continue;
    const double d = (x - (cx[(k + 1) % 3] + t * ab)).norm();
    if (d > eps) continue;
    edges.emplace_back(d, edge_split_candidate(edge, edge_point(edge, forward ? t : 1 - t)));
  }
  std::stable_sort(edges.begin(), edges.end(),
                   [](const auto& l, const auto& r) { return l.first < r.first; });
  std::vector<Candidate> candidates;
  for (auto& e : edges) candidates.push_back(std::move(e.second));

  // 3. The exact face split.
  if (zero_count(loc.bary) == 0) {
    Candidate cand = face_split_candidate(f, p);
    cand.exact = true;
    candidates.push_back(std::move(cand));
  }

  const Candidate* chosen = nullptr;
  const Candidate* best = nullptr;
  for (Candidate& cand : candidates) {
    if (!evaluate(cand)) continue;
    if (cand.min_angle >= std::min(options_.min_angle_deg, cand.old_angle)) {
      chosen = &cand;
      break;
    }
    if (!best || cand.min_angle > best->min_angle) best = &cand;
  }
  // No candidate meets the bar (p close to a vertex that may not be reused or an edge that may
  // not be split): p is moved towards the centre of f, by at most eps, until its split does.
  // On an edge of f, p moves along that edge towards its middle instead.
  Candidate moved;
  const int zeros = zero_count(loc.bary);
  // The move is linear in s (s = 1 reaches the centre); it stops at eps from p.
  Vec3 centre(0, 0, 0);
  for (int k = 0; k < 3; ++k)
    if (loc.bary[k] != 0) centre += cx[k] / (3 - zeros);
  const double reach = (centre - x).norm();
  const double s_max = reach > 0 ? eps / reach : 0;
  for (double s : {0.25, 0.5, 0.75}) {
    if (chosen || zeros > 1 || s_max <= 0) break;
    s = std::min(s, s_max);
    Bary b;
    for (int k = 0; k < 3; ++k)
      b[k] = loc.bary[k] == 0 ? 0.0 : (1 - s) * loc.bary[k] + s / (3 - zeros);
    if (zeros == 1) {
      int k0 = 0;
      while (loc.bary[k0] != 0) ++k0;
      const int a = c[(k0 + 1) % 3], bv = c[(k0 + 2) % 3];
      const OpenMesh::SmartHalfedgeHandle h = mesh_.find_halfedge(VH(a), VH(bv));
      const int edge = h.edge().idx();
      if (may_split && !may_split(edge)) break;
      const bool forward = mesh_.halfedge_handle(EH(edge), 0) == h;
      const double t = b[(k0 + 2) % 3] / (b[(k0 + 1) % 3] + b[(k0 + 2) % 3]);
      moved = edge_split_candidate(edge, edge_point(edge, forward ? t : 1 - t));
    } else {
      moved = face_split_candidate(f, face_point(f, b));
    }
    moved.exact = false;
    if (evaluate(moved) && moved.min_angle >= std::min(options_.min_angle_deg, moved.old_angle))
      chosen = &moved;
    if (s >= s_max) break;
  }
  if (!chosen) chosen = best;
  if (!chosen) {
    throw InvalidInputError("insert_point: the point " + bary_text(p.bary) + " of input face " +
                            std::to_string(p.face) +
                            " is too close to a working-mesh vertex that may not be reused "
                            "(near face " +
                            std::to_string(f) + ")");
  }
  const int v = chosen->kind == Candidate::Kind::kEdge
                    ? split_edge_at(chosen->element, chosen->origin)
                    : split_face_at(chosen->element, chosen->origin);
  return {v, chosen->exact, true};
}

}  // namespace qs
