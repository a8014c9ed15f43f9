#include "app/gui/editor.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "core/layout/layout_io.h"

namespace qs::app {

namespace fs = std::filesystem;

namespace {

std::string absolute_normal(const std::string& path) {
  std::error_code ec;
  const fs::path p = fs::weakly_canonical(fs::absolute(path, ec), ec);
  return ec ? path : p.string();
}

std::string file_name(const std::string& path) {
  return fs::path(path).filename().string();
}

// The user's documents folder (~/Documents when it exists), else the home folder, else the
// working directory.
fs::path documents_dir() {
  std::error_code ec;
  if (const char* home = std::getenv("HOME"); home && *home) {
    const fs::path docs = fs::path(home) / "Documents";
    if (fs::is_directory(docs, ec)) return docs;
    return home;
  }
  return fs::current_path(ec);
}

// The first error of \p validation ("" without errors).
std::string first_error(const ValidationResult& validation) {
  for (const auto& issue : validation.issues)
    if (issue.severity == IssueSeverity::Error) return issue.message;
  return {};
}

}  // namespace

std::string lower_extension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

bool is_mesh_file(const std::string& path) {
  const std::string ext = lower_extension(path);
  return ext == ".obj" || ext == ".off" || ext == ".ply" || ext == ".stl";
}

Editor::Editor(EditorConfig config)
    : job(config.step ? config.step : editor_step_function(config.worker_nice)),
      config_(std::move(config)) {
  doc.editor.on_change = [this](const Layout& layout) { on_layout_edited(layout); };
  // A node dragged with symmetry on takes its mirror node along.
  doc.editor.drag_follow = [this](const Layout& before, Layout& moved, int node) {
    const Mirror* m = mirror();
    return m && doc.mesh ? follow_mirror(*doc.mesh, *m, before, moved, node) : std::string();
  };
  if (config_.remember_recent) recent.load();
}

void Editor::set_status(const std::string& message) {
  status_ = message;
  if (!pending_note_.empty()) {
    status_ += (status_.empty() ? "" : "; ") + pending_note_;
    pending_note_.clear();
  }
}

void Editor::report_error(const std::string& message) {
  errors_.push_back(message);
  std::fprintf(stderr, "quadsketch: %s\n", message.c_str());
}

bool Editor::start(const std::string& mesh_path, const std::string& layout_path) {
  std::string mesh = mesh_path;
  std::string layout = layout_path;
  bool ok = true;
  if (mesh.empty()) {
    // The bundled example: the scene when nothing is given.
    const fs::path example = fs::path(config_.assets_dir) / "example";
    mesh = (example / "ellipsoid.obj").string();
    if (layout.empty()) layout = (example / "ellipsoid.layout.json").string();
    std::error_code ec;
    if (!fs::exists(mesh, ec)) {
      report_error("The bundled example is missing (" + mesh +
                   "). Open a mesh with Ctrl+O or drop one onto the window.");
      mesh.clear();
      layout.clear();
      ok = false;
    }
  }
  if (!mesh.empty()) {
    if (std::string error = doc.open_mesh(mesh); !error.empty()) {
      report_error(error);
      ok = false;
      set_status("No mesh is open: open one with Ctrl+O or drop one onto the window");
    } else {
      recent.add_mesh(mesh);
      if (!layout.empty()) {
        if (std::string error = doc.open_layout(layout); !error.empty()) {
          report_error(error);
          ok = false;
        } else {
          recent.add_layout(layout);
        }
      }
    }
  } else if (!layout.empty()) {
    report_error("Cannot open layout " + layout + " without a mesh");
    ok = false;
  }
  if (config_.remember_recent) recent.save();
  autosave_offer = find_autosave();
  after_document_changed();
  return ok;
}

bool Editor::open_mesh(const std::string& path) {
  if (std::string error = doc.open_mesh(path); !error.empty()) {
    report_error(error);
    return false;
  }
  recent.add_mesh(path);
  if (config_.remember_recent) recent.save();
  after_document_changed();
  set_status("Opened " + path);
  return true;
}

bool Editor::open_layout(const std::string& path) {
  if (std::string error = doc.open_layout(path); !error.empty()) {
    report_error(error);
    return false;
  }
  recent.add_layout(path);
  if (config_.remember_recent) recent.save();
  after_document_changed();
  set_status("Opened " + path);
  return true;
}

bool Editor::open_file(const std::string& path) {
  if (is_mesh_file(path)) return open_mesh(path);
  if (lower_extension(path) == ".json") return open_layout(path);
  report_error("Cannot open " + path +
               ": expected a mesh (.obj .off .ply .stl) or a layout (.json)");
  return false;
}

void Editor::after_document_changed() {
  selection = {};
  highlighted_issue = -1;
  last_drag_.reset();
  ++interaction_version;
  save_path = default_save_path();
  job.load(doc);
}

bool Editor::is_bundled(const std::string& path) const {
  if (path.empty() || config_.assets_dir.empty()) return false;
  const fs::path file = absolute_normal(path);
  const fs::path assets = absolute_normal(config_.assets_dir);
  auto f = file.begin();
  for (auto a = assets.begin(); a != assets.end(); ++a, ++f) {
    if (a->empty()) continue;  // a trailing separator
    if (f == file.end() || *f != *a) return false;
  }
  return true;
}

std::string Editor::default_save_path() const {
  if (!doc.layout_path.empty() && !is_bundled(doc.layout_path)) return doc.layout_path;
  const std::string stem =
      doc.mesh_path.empty() ? std::string("layout") : fs::path(doc.mesh_path).stem().string();
  const std::string name = stem + ".layout.json";
  const std::string& last = recent.last_save();
  if (!last.empty() && !is_bundled(last)) {
    std::error_code ec;
    const fs::path dir = fs::path(last).parent_path();
    if (fs::is_directory(dir, ec)) return (dir / name).string();
  }
  return (documents_dir() / name).string();
}

bool Editor::save(const std::string& path) {
  const std::string target = path.empty() ? save_path : path;
  if (target.empty()) {
    set_status("Choose a file name for the layout (Ctrl+Shift+S)");
    return false;
  }
  if (std::string error = doc.save_layout_to(target); !error.empty()) {
    report_error(error);
    return false;
  }
  recent.add_layout(doc.layout_path);
  recent.set_last_save(doc.layout_path);
  if (config_.remember_recent) recent.save();
  save_path = doc.layout_path;
  // The file now holds every edit; an autosave still on offer belongs to another session.
  if (!autosave_offer) remove_autosave();
  set_status("Saved " + doc.layout_path);
  return true;
}

bool Editor::quick_save() {
  if (!doc.mesh) {
    set_status("Nothing to save: no mesh is open");
    return true;
  }
  if (doc.layout_path.empty() || is_bundled(doc.layout_path)) return false;
  save(doc.layout_path);
  return true;
}

bool Editor::restore_autosave() {
  if (!autosave_offer) return false;
  const AutosaveOffer offer = *autosave_offer;
  autosave_offer.reset();
  if (!offer.mesh_path.empty() &&
      (!doc.mesh || absolute_normal(doc.mesh_path) != offer.mesh_path)) {
    if (std::string error = doc.open_mesh(offer.mesh_path); !error.empty()) {
      report_error("Cannot restore the autosave: " + error);
      autosave_offer = offer;  // still there, still on offer
      return false;
    }
    recent.add_mesh(offer.mesh_path);
  }
  if (!doc.mesh) {
    report_error("Cannot restore the autosave: it names no mesh");
    return false;
  }
  try {
    Layout layout = load_layout(offer.path.string(), *doc.mesh);
    doc.editor.reset(doc.mesh.get(), std::move(layout));
    doc.layout_path = offer.layout_path;
    doc.dirty = true;
    doc.validated_layout_version = ~0ull;
    after_document_changed();
    set_status("Restored the autosave of " + file_name(offer.mesh_path) +
               " (not saved yet: Ctrl+S)");
    return true;
  } catch (const std::exception& e) {
    report_error(std::string("Cannot restore the autosave: ") + e.what());
    return false;
  }
}

void Editor::discard_autosave() {
  if (!autosave_offer) return;
  autosave_offer.reset();
  const std::string aside = set_autosave_aside();
  set_status(aside.empty() ? std::string("Autosave discarded") : "Autosave set aside as " + aside);
}

void Editor::on_layout_edited(const Layout& layout) {
  doc.dirty = true;
  ++interaction_version;
  // The first edit supersedes an autosave still on offer: keep it aside instead of
  // overwriting it.
  if (autosave_offer) {
    autosave_offer.reset();
    const std::string aside = set_autosave_aside();
    if (!aside.empty()) pending_note_ = "the earlier autosave was kept as " + aside;
  }
  // Autosave after every committed edit; failures are shown but never stop editing.
  try {
    write_autosave(layout, doc.mesh.get(), doc.mesh_path, doc.layout_path);
    autosave_error.clear();
  } catch (const std::exception& e) {
    autosave_error = e.what();
  }
  // Another edit than the live drag's: its undo no longer brings back the result shown before.
  if (!undoing_ && !releasing_) last_drag_.reset();
  if (releasing_) return;  // end_drag() sends the released layout's live solve
  if (job.layout_edited(layout)) {
    const std::string note = "the run's result was discarded (not kept)";
    pending_note_ = pending_note_.empty() ? note : pending_note_ + "; " + note;
  }
}

void Editor::poll() {
  if (job.poll(doc)) {
    // The end of a run replaces the "Running" message.
    const Snapshot& s = *job.latest();
    if (job.take_live_released()) {
      if (s.mesh == doc.mesh)
        set_status(s.status == WorkerStatus::Finished
                       ? "Solved the moved layout: " + s.message
                       : "The moved layout cannot be solved: " + s.message);
    } else if (!job.latest_is_live() && s.status != last_status_ && s.mesh == doc.mesh) {
      if (s.status == WorkerStatus::Finished)
        set_status("Run finished at step " + std::to_string(s.iteration) +
                   ": Keep result adopts it, Discard drops it");
      else if (s.status == WorkerStatus::Failed)
        set_status("Run failed: " + s.message);
    }
    last_status_ = s.status;
  }
  if (!doc.editor.dragging()) doc.refresh_validation();
  symmetry.poll(doc);
  field_hints.poll(doc, config_.worker_nice);
  // The selection may name what an undo or a new layout removed.
  const Layout& layout = doc.editor.layout();
  if (selection.node >= 0 && layout.node_index(selection.node) < 0) selection.node = -1;
  if (selection.arc >= 0 && layout.arc_index(selection.arc) < 0) selection.arc = -1;
}

std::string Editor::run_blocker() {
  if (!doc.mesh) return "no mesh is open (Ctrl+O opens one)";
  if (!doc.editor.dragging()) doc.refresh_validation();  // while dragging: the last one
  const Layout& layout = doc.editor.layout();
  if (layout.nodes.empty()) return "the layout is empty: place nodes (tool 2) and draw arcs (3)";
  if (layout.arcs.empty()) return "the layout has no arcs: draw arcs between the nodes (tool 3)";
  const int errors = doc.validation.errors();
  if (errors > 0) {
    return std::to_string(errors) + " validation error" + (errors == 1 ? "" : "s") +
           " to fix first: " + first_error(doc.validation);
  }
  return {};
}

void Editor::symmetry_to_job() {
  WorkerOptions& o = job.options;
  o.symmetry.reset();
  o.symmetry_plane.reset();
  if (!symmetry.enabled()) return;
  o.symmetry = symmetry.axis();
  if (const Mirror* m = symmetry.mirror()) o.symmetry_plane = m->plane;
}

void Editor::run() {
  if (job.running()) return;
  if (!job.paused()) {
    if (const std::string why = run_blocker(); !why.empty()) {
      set_status("Cannot run: " + why);
      return;
    }
  }
  symmetry_to_job();
  job.run(doc);
  set_status(job.paused() ? "Running on" : "Running");
}

void Editor::step() {
  if (job.running()) return;
  if (!job.paused()) {
    if (const std::string why = run_blocker(); !why.empty()) {
      set_status("Cannot step: " + why);
      return;
    }
  }
  symmetry_to_job();
  job.step(doc);
  set_status("One step");
}

void Editor::pause() {
  job.pause();
  set_status("Paused: Run goes on, Keep result adopts the state reached");
}

void Editor::stop() {
  job.stop(doc);
  set_status("Stopped: Keep result adopts the state reached, Discard drops it");
}

void Editor::keep_result() {
  if (job.keep(doc))
    set_status("Optimized layout kept (Ctrl+Z undoes it)");
  else
    set_status("Nothing to keep");
}

void Editor::discard_result() {
  job.discard(doc);
  set_status("Result discarded");
}

std::string Editor::job_summary() const {
  const Snapshot* s = result();
  std::ostringstream out;
  if (!s) {
    const SnapshotPtr& latest = job.latest();
    if (latest && latest->status == WorkerStatus::Failed && latest->mesh == doc.mesh)
      return "Run failed: " + latest->message;
    return {};
  }
  switch (result_kind()) {
    case ResultKind::Stopped:
      out << "stopped";
      break;
    case ResultKind::Kept:
      out << "kept result";
      break;
    default:
      out << to_string(s->status);
  }
  out << "  step " << s->iteration;
  if (std::isfinite(s->energy)) {
    char e[32];
    std::snprintf(e, sizeof(e), "%.6g", s->energy);
    out << "  E = " << e;
  }
  if (s->metrics.valid) out << "  fold-overs " << s->metrics.foldovers;
  if (s->quads) out << "  " << s->quads->quads.size() << " quads";
  return out.str();
}

void Editor::export_files(const ExportSelection& what) {
  const Snapshot* s = result();
  if (!s || !s->exports) {
    exports.message = "Nothing to export: run the pipeline first";
    exports.failed = true;
    return;
  }
  try {
    const auto written = write_job_exports(*s->exports, exports.dir, what);
    std::string list;
    for (const auto& f : written) list += (list.empty() ? "" : ", ") + f;
    exports.message = "Wrote " + list + " to " + exports.dir;
    exports.failed = false;
    set_status(exports.message);
  } catch (const std::exception& e) {
    exports.message = std::string("Export failed: ") + e.what();
    exports.failed = true;
  }
}

void Editor::apply(const EditResult& result, const std::string& done_message) {
  set_status(result.ok ? done_message : "Not done: " + result.error);
  ++interaction_version;
}

void Editor::insert_edge_loop(int arc_id) {
  bool mirror_loop = false;
  const EditResult r = sketch_insert_edge_loop(doc.editor, mirror(), arc_id, &mirror_loop);
  apply(r, "Edge loop inserted through the chord crossing arc " + std::to_string(arc_id) +
               (mirror_loop ? " (and its mirror)" : ""));
  if (r) selection = {r.id, -1};
}

void Editor::remove_edge_loop(int arc_id) {
  bool mirror_loop = false;
  const EditResult r = sketch_remove_edge_loop(doc.editor, mirror(), arc_id, &mirror_loop);
  apply(r, "Edge loop through arc " + std::to_string(arc_id) + " removed" +
               (mirror_loop ? " (and its mirror)" : ""));
  if (r) selection = {};
}

void Editor::select(int node, int arc) {
  selection = {node, arc};
  ++interaction_version;
  set_status(node >= 0  ? "Node " + std::to_string(node) + " selected"
             : arc >= 0 ? "Arc " + std::to_string(arc) + " selected"
                        : "");
}

bool Editor::begin_drag(int node_id) {
  if (!doc.editor.begin_drag(node_id)) return false;
  live_drag_ = live_solve && doc.mesh && !job.running() && !job.paused();
  if (live_drag_) {
    pre_drag_ = {};
    pre_drag_.before_position = doc.editor.undo_position();
    pre_drag_.before = job.shown_snapshot(doc);
    pre_drag_.before_kind = job.shown_kind(doc);
  }
  return true;
}

EditResult Editor::drag_to(int vertex) {
  const auto event = JobControl::Clock::now();
  const std::uint64_t version = doc.editor.version();
  EditResult r = doc.editor.drag_to(vertex);
  if (!r || !live_drag_ || doc.editor.version() == version) return r;
  // Validated here (quick next to a solve); an invalid position is shown, not solved.
  doc.refresh_validation();
  if (doc.validation.errors() > 0) {
    job.live_invalid();
    set_status("Invalid here: " + first_error(doc.validation));
  } else {
    if (status_.rfind("Invalid here: ", 0) == 0) set_status("");
    job.live_request(doc.editor.layout(), event);
  }
  return r;
}

void Editor::end_drag() {
  if (!doc.editor.dragging()) return;
  const bool live = live_drag_ && job.live();
  live_drag_ = false;
  if (!live) {
    doc.editor.end_drag();
    return;
  }
  const std::uint64_t version = doc.editor.version();
  releasing_ = true;
  doc.editor.end_drag();  // the undo step (on_layout_edited leaves the worker to us)
  releasing_ = false;
  doc.refresh_validation();
  if (doc.validation.errors() > 0)
    job.layout_edited(doc.editor.layout());  // shown like any invalid layout
  else
    job.live_release(doc.editor.layout(), JobControl::Clock::now());
  if (doc.editor.version() != version) last_drag_ = pre_drag_;
}

void Editor::cancel_drag() {
  if (!doc.editor.dragging()) return;
  const bool live = live_drag_ && job.live();
  live_drag_ = false;
  doc.editor.cancel_drag();
  if (live) {
    job.layout_edited(doc.editor.layout());
    job.restore(pre_drag_.before, pre_drag_.before_kind, doc);
  }
}

bool Editor::node_pinned(int id) const {
  if (job.live_pins()) return job.node_pinned(id);
  const Snapshot* s = result();
  const Layout& layout = s && s->layout ? *s->layout : doc.editor.layout();
  const int k = layout.node_index(id);
  return k >= 0 && layout.nodes[k].pinned;
}

bool Editor::arc_pinned(int id) const {
  if (job.live_pins()) return job.arc_pinned(id);
  const Snapshot* s = result();
  const Layout& layout = s && s->layout ? *s->layout : doc.editor.layout();
  const int k = layout.arc_index(id);
  return k >= 0 && layout.arcs[k].pinned;
}

void Editor::toggle_node_pin(int id) {
  if (job.live_pins()) {
    const bool pinned = job.toggle_node_pin(id);
    if (const Mirror* m = mirror(); m && doc.mesh) {
      const Snapshot* s = result();
      const Layout& shown = s && s->layout ? *s->layout : doc.editor.layout();
      const int mid = mirror_node_id(*doc.mesh, shown, *m, id);
      if (mid >= 0 && mid != id && job.node_pinned(mid) != pinned) job.toggle_node_pin(mid);
    }
    ++interaction_version;
    set_status(std::string(pinned ? "Pinned" : "Unpinned") + " node " + std::to_string(id) +
               " in the run (from its next step)");
    return;
  }
  apply(sketch_toggle_node_pin(doc.editor, mirror(), id),
        "Pin toggled on node " + std::to_string(id));
}

void Editor::toggle_arc_pin(int id) {
  if (job.live_pins()) {
    const bool pinned = job.toggle_arc_pin(id);
    if (const Mirror* m = mirror(); m && doc.mesh) {
      const Snapshot* s = result();
      const Layout& shown = s && s->layout ? *s->layout : doc.editor.layout();
      const int mid = mirror_arc_id(*doc.mesh, shown, *m, id);
      if (mid >= 0 && mid != id && job.arc_pinned(mid) != pinned) job.toggle_arc_pin(mid);
    }
    ++interaction_version;
    set_status(std::string(pinned ? "Pinned" : "Unpinned") + " arc " + std::to_string(id) +
               " in the run (from its next step: its route and end nodes stay)");
    return;
  }
  apply(sketch_toggle_arc_pin(doc.editor, mirror(), id),
        "Pin toggled on arc " + std::to_string(id));
}

void Editor::toggle_pin_selection() {
  if (selection.node >= 0)
    toggle_node_pin(selection.node);
  else if (selection.arc >= 0)
    toggle_arc_pin(selection.arc);
  else
    set_status("Select a node or an arc to pin (P)");
}

void Editor::delete_selection() {
  if (selection.node >= 0) {
    const int id = selection.node;
    apply(sketch_delete_node(doc.editor, mirror(), id), "Node " + std::to_string(id) + " deleted");
    selection.node = -1;
  } else if (selection.arc >= 0) {
    const int id = selection.arc;
    apply(sketch_delete_arc(doc.editor, mirror(), id), "Arc " + std::to_string(id) + " deleted");
    selection.arc = -1;
  }
}

void Editor::undo() {
  const std::string label = doc.editor.undo_label();
  // Undoing the last live drag: the result shown before it comes back (and the release's solve
  // is kept for redo, once it arrived).
  const bool drag_step =
      last_drag_ && doc.editor.undo_position() == last_drag_->before_position + 1;
  const SnapshotPtr after = drag_step && !job.live() ? job.shown_snapshot(doc) : nullptr;
  undoing_ = true;
  const bool done = doc.editor.undo();
  undoing_ = false;
  if (!done) return;
  if (drag_step) {
    last_drag_->after = after;
    job.restore(last_drag_->before, last_drag_->before_kind, doc);
  }
  set_status("Undid " + label);
}

void Editor::redo() {
  const std::string label = doc.editor.redo_label();
  const bool drag_step = last_drag_ && doc.editor.undo_position() == last_drag_->before_position;
  undoing_ = true;
  const bool done = doc.editor.redo();
  undoing_ = false;
  if (!done) return;
  if (drag_step && last_drag_->after) job.restore(last_drag_->after, ResultKind::Live, doc);
  set_status("Redid " + label);
}

std::vector<int> Editor::highlight_issue(int index) {
  std::vector<int> vertices;
  if (index < 0 || index >= int(doc.validation.issues.size())) return vertices;
  highlighted_issue = index;
  const auto& issue = doc.validation.issues[index];
  vertices = issue.vertices;
  const Layout& layout = doc.editor.layout();
  for (int id : issue.node_ids)
    if (int k = layout.node_index(id); k >= 0) vertices.push_back(layout.nodes[k].vertex);
  for (int id : issue.arc_ids)
    if (int k = layout.arc_index(id); k >= 0)
      vertices.insert(vertices.end(), layout.arcs[k].path.begin(), layout.arcs[k].path.end());
  selection.node = issue.node_ids.size() == 1 ? issue.node_ids[0] : -1;
  selection.arc = issue.arc_ids.size() == 1 && selection.node < 0 ? issue.arc_ids[0] : -1;
  ++interaction_version;
  return vertices;
}

float Editor::mesh_diagonal() {
  if (mesh_diagonal_version_ != doc.mesh_version) {
    mesh_diagonal_version_ = doc.mesh_version;
    mesh_diagonal_ = 1.0f;
    if (doc.mesh && doc.mesh->n_vertices() > 0) {
      Vec3 c;
      double r = 1.0;
      doc.bounds(c, r);
      mesh_diagonal_ = std::max(float(2.0 * r), 1e-6f);
    }
  }
  return mesh_diagonal_;
}

}  // namespace qs::app
