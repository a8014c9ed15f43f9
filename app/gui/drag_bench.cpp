#include "app/gui/drag_bench.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "render/renderer.h"

namespace qs::app {

namespace {

constexpr float kPi = 3.14159265f;
constexpr double kReleaseTimeoutS = 600.0;

double median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double max_of(const std::vector<double>& v) {
  return v.empty() ? std::numeric_limits<double>::quiet_NaN()
                   : *std::max_element(v.begin(), v.end());
}

double seconds(std::chrono::steady_clock::duration d) {
  return std::chrono::duration<double>(d).count();
}

glm::vec3 vertex_point(const TriMesh& mesh, int v) {
  const auto& p = mesh.point(OpenMesh::VertexHandle(v));
  return {float(p[0]), float(p[1]), float(p[2])};
}

}  // namespace

DragBench::DragBench(int positions) : positions_(std::max(2, positions)) {}

bool DragBench::plan(AppContext& ctx) {
  const Editor& editor = ctx.editor;
  if (!editor.doc.mesh) {
    error_ = "no mesh is open";
    return false;
  }
  const Layout& layout = editor.doc.editor.layout();
  const TriMesh& mesh = *editor.doc.mesh;
  const glm::vec2 centre = 0.5f * ctx.camera.viewport();
  std::vector<glm::vec2> screen(layout.nodes.size(), glm::vec2(-1e9f));
  for (std::size_t k = 0; k < layout.nodes.size(); ++k) {
    const int v = layout.nodes[k].vertex;
    if (v >= 0 && v < int(mesh.n_vertices()))
      screen[k] = glm::vec2(ctx.camera.project(vertex_point(mesh, v)));
  }
  // Visible: picked where it is drawn (not behind the surface).
  std::vector<char> visible(layout.nodes.size(), 0);
  for (std::size_t k = 0; k < layout.nodes.size(); ++k)
    visible[k] = screen[k].x > -1e8f && ctx.tools.pick_node(screen[k], 6.0f, editor, ctx.camera,
                                                            ctx.picker) == layout.nodes[k].id;
  // The free visible node nearest to the middle of the view.
  float best = std::numeric_limits<float>::max();
  std::size_t chosen = layout.nodes.size();
  for (std::size_t k = 0; k < layout.nodes.size(); ++k) {
    if (layout.nodes[k].pinned || !visible[k]) continue;
    const float d = glm::length(screen[k] - centre);
    if (d < best) {
      best = d;
      chosen = k;
    }
  }
  if (chosen == layout.nodes.size()) {
    error_ = "no free node of the layout is in view";
    return false;
  }
  node_ = layout.nodes[chosen].id;
  from_ = screen[chosen];
  // Three quarters of a circle through the node, its centre towards the middle of the view, its
  // radius a third of the nearest visible node's distance.
  const float height = ctx.camera.viewport().y;
  float nearest = height;
  for (std::size_t k = 0; k < layout.nodes.size(); ++k)
    if (k != chosen && visible[k]) nearest = std::min(nearest, glm::length(screen[k] - from_));
  radius_ = std::clamp(0.35f * nearest, 0.02f * height, 0.15f * height);
  const glm::vec2 to_centre = centre - from_;
  along_ = glm::length(to_centre) > 1.0f ? glm::normalize(to_centre) : glm::vec2(1.0f, 0.0f);
  return true;
}

bool DragBench::after_frame(AppContext& ctx) {
  ++frame_;
  Editor& editor = ctx.editor;
  const auto now = Clock::now();
  switch (phase_) {
    case Phase::Start:
      if (frame_ < 3) return false;  // the view is set up
      if (!plan(ctx)) {
        phase_ = Phase::Done;
        return true;
      }
      ctx.tools.set_tool(Tool::Select);
      editor.job.clear_live_stats();
      phase_ = Phase::Drag;
      [[fallthrough]];
    case Phase::Drag: {
      // One mouse event per frame: the press, positions 1..N along the path, the release.
      MouseInput in;
      in.left_down = true;
      const float turn = 1.5f * kPi * float(std::min(next_, positions_)) / float(positions_);
      const glm::vec2 across(-along_.y, along_.x);
      in.position = from_ + radius_ * ((1.0f - std::cos(turn)) * along_ + std::sin(turn) * across);
      if (next_ == 0) {
        in.left_clicked = true;
        first_event_ = now;
      } else if (next_ > positions_) {
        in.left_down = false;
        release_ = now;
        phase_ = Phase::Wait;
      }
      const std::uint64_t version = editor.doc.editor.version();
      const auto before = Clock::now();
      ctx.tools.mouse(in, editor, ctx.camera, ctx.picker);
      if (editor.doc.editor.version() != version)
        ui_ms_.push_back(std::chrono::duration<double, std::milli>(Clock::now() - before).count());
      if (next_ > 0 && next_ <= positions_) {
        if (editor.doc.editor.version() != version) ++moves_;
        const std::string& status = editor.status();
        if (status.rfind("Cannot move there", 0) == 0) {
          ++refused_;
          if (refusal_.empty()) refusal_ = status;
          editor.set_status("");
        }
      }
      ++next_;
      return false;
    }
    case Phase::Wait:
      if (editor.job.live()) {
        if (seconds(now - release_) <= kReleaseTimeoutS) return false;
        error_ = "the solve of the released layout did not arrive";
      } else if (const Snapshot* s = editor.result()) {
        final_ = "step " + std::to_string(s->iteration) + ", " + s->message;
      } else {
        const SnapshotPtr& latest = editor.job.latest();
        final_ = latest && latest->status == WorkerStatus::Failed
                     ? "failed: " + latest->message
                     : std::string("no result shown (") + editor.status() + ")";
      }
      if (moves_ == 0 && error_.empty()) error_ = "no mouse position moved the node";
      phase_ = Phase::Done;
      return true;
    case Phase::Done:
      return true;
  }
  return true;
}

void DragBench::frame_shown(AppContext& ctx) {
  const JobControl::LiveStats& stats = ctx.editor.job.live_stats();
  if (phase_ == Phase::Start || stats.shown <= shown_seen_) return;
  shown_seen_ = stats.shown;
  const auto now = Clock::now();
  end_ = now;
  const double ms = std::chrono::duration<double, std::milli>(now - stats.last_event).count();
  latency_ms_.push_back(ms);
  if (phase_ == Phase::Drag) ++shown_while_dragging_;
  if (phase_ == Phase::Done) release_latency_ms_ = ms;
  // The solve just shown: the live one, or after the release the worker's result.
  const SnapshotPtr& latest = ctx.editor.job.latest();
  if (latest && latest->metrics.valid && std::isfinite(latest->metrics.total_ms))
    solve_ms_.push_back(latest->metrics.total_ms);
}

std::string DragBench::report(const AppContext& ctx) const {
  if (!error_.empty()) return "bench-drag: failed: " + error_;
  const Editor& editor = ctx.editor;
  const double drag_s = seconds(release_ - first_event_);
  const double total_s = seconds(end_ - first_event_);
  const int shown = int(latency_ms_.size());
  const std::string renderer = render::current_renderer_name();
  char line[768];
  std::snprintf(
      line, sizeof(line),
      "bench-drag: node %d over %d mouse positions (%d moved it) in %.2f s; mesh %zu faces, "
      "%zu nodes, %zu arcs; %d solves asked for, %d sent, %d shown (%d while dragging): %.1f "
      "solves/s while "
      "dragging, %.1f overall; latency mouse event -> solve shown: median %.0f ms, max %.0f "
      "ms; release -> its solve shown %.0f ms; worker time per solve: median %.0f ms, max %.0f "
      "ms; UI thread per move (route, validate, ask): median %.1f ms",
      node_, positions_, moves_, drag_s,
      editor.doc.mesh ? std::size_t(editor.doc.mesh->n_faces()) : std::size_t(0),
      editor.doc.editor.layout().nodes.size(), editor.doc.editor.layout().arcs.size(),
      editor.job.live_stats().requests, editor.job.live_stats().sent, shown, shown_while_dragging_,
      drag_s > 0 ? shown_while_dragging_ / drag_s : 0.0, total_s > 0 ? shown / total_s : 0.0,
      median(latency_ms_), max_of(latency_ms_), release_latency_ms_, median(solve_ms_),
      max_of(solve_ms_), median(ui_ms_));
  std::string refused;
  if (refused_ > 0)
    refused = "; " + std::to_string(refused_) + " positions refused (" + refusal_ + ")";
  return std::string(line) + refused + "; after the release: " + final_ +
         "; renderer: " + (renderer.empty() ? "?" : renderer);
}

}  // namespace qs::app
