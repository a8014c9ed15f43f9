#include "app/gui/state_dump.h"

#include <cmath>

#include "app/gui/ui_text.h"
#include "core/base/atomic_file.h"

namespace qs::app {

namespace {

using nlohmann::json;

json number(double x) {
  return std::isfinite(x) ? json(x) : json(nullptr);
}

json vec(const glm::vec3& v) {
  return json::array({v.x, v.y, v.z});
}

json layout_json(const Layout& layout) {
  json nodes = json::array(), arcs = json::array();
  for (const auto& n : layout.nodes)
    nodes.push_back({{"id", n.id}, {"vertex", n.vertex}, {"pinned", n.pinned}});
  for (const auto& a : layout.arcs)
    arcs.push_back(
        {{"id", a.id}, {"from", a.from}, {"to", a.to}, {"pinned", a.pinned}, {"path", a.path}});
  return {{"nodes", nodes}, {"arcs", arcs}};
}

json snapshot_json(const Snapshot& s) {
  json out = {{"status", to_string(s.status)},
              {"iteration", s.iteration},
              {"generation", s.generation},
              {"energy", number(s.energy)},
              {"energy_init", number(s.energy_init)},
              {"message", s.message},
              {"history", s.node_history.size()},
              {"quads", s.quads ? s.quads->quads.size() : 0},
              {"exports", bool(s.exports)},
              {"has_quad_export", s.exports && s.exports->quads != nullptr},
              {"foldovers", s.metrics.valid ? json(s.metrics.foldovers) : json(nullptr)}};
  if (s.layout) out["layout"] = layout_json(*s.layout);
  return out;
}

}  // namespace

json state_json(AppContext& ctx, int frames) {
  Editor& editor = ctx.editor;
  const Document& doc = editor.doc;
  json state;
  state["frames"] = frames;
  json document = {{"mesh", doc.mesh_path},
                   {"mesh_loaded", doc.mesh != nullptr},
                   {"layout", doc.layout_path},
                   {"dirty", doc.dirty},
                   {"validation_errors", doc.validation.errors()},
                   {"can_undo", doc.editor.can_undo()}};
  document.update(layout_json(doc.editor.layout()));
  state["document"] = document;
  state["save_path"] = editor.save_path;
  state["save_path_bundled"] = editor.is_bundled(editor.save_path);
  state["status"] = editor.status();
  state["errors"] = editor.errors();
  if (editor.autosave_offer)
    state["autosave_offer"] = {{"mesh", editor.autosave_offer->mesh_path},
                               {"layout", editor.autosave_offer->layout_path},
                               {"saved_at", editor.autosave_offer->saved_at}};
  else
    state["autosave_offer"] = nullptr;
  const std::string blocker = editor.run_blocker();
  state["run_blocker"] = blocker;
  const SnapshotPtr& latest = editor.job.latest();
  if (latest) {
    json job = snapshot_json(*latest);
    job.erase("layout");
    state["job"] = job;
  } else {
    state["job"] = nullptr;
  }
  state["running"] = editor.job.running();
  state["paused"] = editor.job.paused();
  if (const Snapshot* s = editor.result()) {
    json result = snapshot_json(*s);
    result["kind"] = to_string(editor.result_kind());
    state["result"] = result;
  } else {
    state["result"] = nullptr;
  }
  state["selection"] = {{"node", editor.selection.node}, {"arc", editor.selection.arc}};
  json symmetry = {{"enabled", editor.symmetry.enabled()},
                   {"axis", to_string(editor.symmetry.axis())},
                   {"ready", editor.mirror() != nullptr},
                   {"error", editor.symmetry.error()}};
  if (const auto& fit = editor.symmetry.fit()) {
    const MirrorPlane& p = fit->plane;
    symmetry["normal"] = json::array({p.normal[0], p.normal[1], p.normal[2]});
    symmetry["offset"] = p.offset;
    symmetry["residual"] = fit->relative;
  }
  state["symmetry"] = symmetry;
  json hints = {{"enabled", editor.field_hints.enabled},
                {"computing", editor.field_hints.computing()},
                {"error", editor.field_hints.error()},
                {"scale", editor.field_hints.scale()}};
  if (const NaturalField* raw = editor.field_hints.raw_field())
    hints["all_singularities"] = raw->singularities.size();
  if (const NaturalField* f = editor.field_hints.field()) {
    json singularities = json::array();
    for (const auto& s : f->singularities)
      singularities.push_back({{"vertex", s.vertex}, {"index", s.index}});
    hints["singularities"] = singularities;
  } else {
    hints["singularities"] = nullptr;
  }
  state["field_hints"] = hints;
  state["tool"] = tool_name(ctx.tools.tool());
  const render::Camera& camera = ctx.camera;
  state["camera"] = {
      {"mode", camera.orbit_mode() == render::OrbitMode::Turntable ? "turntable" : "trackball"},
      {"orthographic", camera.orthographic()},
      {"view_direction", vec(camera.view_direction())},
      {"up", vec(camera.up_direction())},
      {"animating", camera.animating()}};
  const FileBrowser& browser = ctx.ui.browser;
  state["browser"] = {{"open", browser.is_open()},
                      {"mode", browser.mode() == BrowserMode::Save ? "save" : "open"},
                      {"folder", browser.folder()},
                      {"file_name", browser.file_name},
                      {"entries", browser.entries().size()},
                      {"filter", browser.filters()[browser.filter()].label}};
  state["status_bar"] = {{"message", ui_text(editor.status())},
                         {"job", ui_text(editor.job_summary())},
                         {"run_blocker", ui_text(blocker)}};
  state["unicode_font"] = unicode_text();
  return state;
}

bool write_state_json(AppContext& ctx, int frames, const std::string& path, std::string* error) {
  try {
    write_file_atomic(path, state_json(ctx, frames).dump(2) + "\n");
    return true;
  } catch (const std::exception& e) {
    if (error) *error = e.what();
    return false;
  }
}

}  // namespace qs::app
