// The editor's state without a window or GL (testable on its own): the open document with its
// undo history, recent files, the pipeline job and the result it shows, the selection, the
// status line and the error list, the autosave offer and the exports. The tools (tools.h), the
// camera and the panels act on it; nothing here draws.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "app/gui/autosave.h"
#include "app/gui/document.h"
#include "app/gui/field_hints.h"
#include "app/gui/job_control.h"
#include "app/gui/pipeline_job.h"
#include "app/gui/recent_files.h"
#include "app/gui/symmetry_state.h"

namespace qs::app {

struct EditorConfig {
  //! The bundled assets (the example opened without --mesh): never the default save target.
  std::string assets_dir;
  int worker_nice = 10;  //!< nice value of the solver threads (0: unchanged)
  //! The worker's step function; empty: the editor's pipeline job (pipeline_step).
  StepFunction step;
  //! Read and write the recent-files list (RecentFiles::default_path()).
  bool remember_recent = true;
};

struct Selection {
  int node = -1;
  int arc = -1;
};

struct ExportState {
  std::string dir;  //!< the export folder field
  std::string message;
  bool failed = false;
};

class Editor {
 public:
  explicit Editor(EditorConfig config);
  Editor(const Editor&) = delete;
  Editor& operator=(const Editor&) = delete;

  Document doc;
  RecentFiles recent;
  JobControl job;
  Selection selection;
  int highlighted_issue = -1;  //!< index into doc.validation.issues, -1: none
  //! An autosave left by an earlier session (any mesh), until restored, discarded or
  //! superseded by an edit (which first sets it aside: autosave.previous.layout.json).
  std::optional<AutosaveOffer> autosave_offer;
  std::string autosave_error;  //!< the last autosave write failed with this
  ExportState exports;
  //! The Save field: default_save_path() whenever another document is opened.
  std::string save_path;
  //! Bumped whenever the selection or a highlight changes (redraws the scene).
  std::uint64_t interaction_version = 0;
  //! Mirrored sketching (the Sketch panel's Symmetry section).
  SymmetryState symmetry;
  //! The natural cross field of the bare mesh (the View panel's "Field hints").
  FieldHints field_hints;
  //! "Live solve while dragging" (Pipeline panel): while a node is dragged and no run is in
  //! progress, every drag position is solved on the worker and shown (JobControl::live_request).
  bool live_solve = true;

  // Start-up and files. Failures are reported (errors()) and leave the document as it was.
  //! Opens \p mesh_path and \p layout_path, or the bundled example when \p mesh_path is empty,
  //! and offers an existing autosave whatever is opened. False when a file could not be opened.
  bool start(const std::string& mesh_path, const std::string& layout_path);
  bool open_mesh(const std::string& path);
  bool open_layout(const std::string& path);
  //! A mesh (.obj .off .ply .stl) or a layout (.json), by extension.
  bool open_file(const std::string& path);
  //! Saves the layout to \p path (empty: save_path) and remembers it for the next default.
  bool save(const std::string& path = {});
  //! Ctrl+S: saves to the layout's own file; false (nothing saved) when it has none or it is a
  //! bundled asset: the caller asks for a file name.
  bool quick_save();
  //! Where Save proposes to write: the layout's own file unless it is bundled, else next to
  //! the last saved layout, else in ~/Documents (or ~), named after the mesh.
  std::string default_save_path() const;
  //! True for files inside the bundled assets folder.
  bool is_bundled(const std::string& path) const;
  //! Restores the offered autosave (opening its mesh when another one is open).
  bool restore_autosave();
  //! Declines the offered autosave; it is kept as autosave.previous.layout.json.
  void discard_autosave();

  //! Once per frame: the worker's latest snapshot, the validation of the edited layout, the
  //! mirror plane and the field hints.
  void poll();

  // The pipeline.
  //! Why Run / Step cannot start now ("" when they can).
  std::string run_blocker();
  //! Run and Step start a run that keeps the layout mirror symmetric while mirrored sketching
  //! is on (WorkerOptions::symmetry and symmetry_plane).
  void run();
  void step();
  void pause();
  void stop();
  void keep_result();
  void discard_result();
  //! The job result shown instead of the edited layout (live, stopped or kept), or null.
  const Snapshot* result() const { return job.shown(doc); }
  ResultKind result_kind() const { return job.shown_kind(doc); }
  //! One line for the status bar: state, step, E and fold-overs of the shown result, or why
  //! the last run failed; "" when there is nothing to say.
  std::string job_summary() const;
  //! Writes the shown result's exports into exports.dir.
  void export_files(const ExportSelection& what);

  // Edits and selection.
  //! The mirror of the sketch edits (sketch_edits.h): null unless symmetry is on and its plane
  //! is ready.
  const Mirror* mirror() const { return symmetry.mirror(); }
  //! Reports an edit's outcome on the status line.
  void apply(const EditResult& result, const std::string& done_message);
  //! Inserts / removes the edge loop through arc \p arc_id (mirrored with symmetry on), with
  //! the outcome on the status line.
  void insert_edge_loop(int arc_id);
  void remove_edge_loop(int arc_id);
  void select(int node, int arc);
  // Dragging a node (the select tool): LayoutEditor's drag with the live solves. With
  // live_solve on and no run in progress (running or paused), every position is validated
  // and, when valid, solved on the worker; an invalid one shows its issues instead. The
  // release solves the final layout (what is shown after it is that solve), and undoing the
  // move restores the layout and the result shown before the drag (redo: the one after it).
  //! Starts dragging node \p node_id; false when it cannot (LayoutEditor::begin_drag).
  bool begin_drag(int node_id);
  //! Moves the dragged node to \p vertex (LayoutEditor::drag_to) and asks for its solve.
  EditResult drag_to(int vertex);
  //! Releases the node: one undoable edit when it moved.
  void end_drag();
  //! Esc: the node goes back, and so does the result shown.
  void cancel_drag();
  //! Pins / unpins: in the running (or paused) job when there is one, else in the layout; with
  //! symmetry on, the mirror node or arc too.
  void toggle_node_pin(int id);
  void toggle_arc_pin(int id);
  void toggle_pin_selection();
  void delete_selection();
  void undo();
  void redo();
  //! Highlights validation issue \p index and selects what it names; returns the mesh
  //! vertices to bring into view.
  std::vector<int> highlight_issue(int index);
  //! Pinned state as drawn: the job's during a run (pins not yet applied included), the shown
  //! result's, else the edited layout's.
  bool node_pinned(int id) const;
  bool arc_pinned(int id) const;

  // Messages.
  const std::string& status() const { return status_; }
  void set_status(const std::string& message);
  const std::vector<std::string>& errors() const { return errors_; }
  //! Shows \p message in the error panel (and prints it to stderr).
  void report_error(const std::string& message);
  void clear_errors() { errors_.clear(); }

  //! Bounding-box diagonal of the mesh (1 without one), cached per mesh.
  float mesh_diagonal();

 private:
  void on_layout_edited(const Layout& layout);
  //! What was shown before and after a live drag, for its undo and redo.
  struct DragDisplay {
    std::size_t before_position = 0;  //!< LayoutEditor::undo_position() before the move
    SnapshotPtr before;
    ResultKind before_kind = ResultKind::None;
    SnapshotPtr after;  //!< the release's solve (taken when the move is undone)
  };
  //! The mirrored sketching's axis and plane (when computed) into the job's options.
  void symmetry_to_job();
  //! After the whole layout was replaced (open, restore): selection reset, worker reloaded.
  void after_document_changed();

  EditorConfig config_;
  std::string status_;
  std::string pending_note_;  //!< appended to the next status message
  std::vector<std::string> errors_;
  WorkerStatus last_status_ = WorkerStatus::Idle;  //!< of the latest snapshot polled
  float mesh_diagonal_ = 1.0f;
  std::uint64_t mesh_diagonal_version_ = ~0ull;
  bool live_drag_ = false;                //!< the current drag solves live
  bool releasing_ = false;                //!< inside end_drag() of a live drag
  bool undoing_ = false;                  //!< inside undo() / redo()
  DragDisplay pre_drag_;                  //!< of the current drag
  std::optional<DragDisplay> last_drag_;  //!< of the last live drag, until another edit
};

//! Lower-case extension of \p path with its dot (".obj").
std::string lower_extension(const std::string& path);
//! True for the mesh formats the editor opens (.obj .off .ply .stl).
bool is_mesh_file(const std::string& path);

}  // namespace qs::app
