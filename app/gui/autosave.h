// Crash safety: after every edit the layout is written atomically to an autosave file, with
// an "autosave" block naming the mesh it belongs to (one file, one atomic write), so that it can be
// offered back at start.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "core/layout/layout.h"
#include "core/mesh/mesh.h"

namespace qs::app {

//! $QS_AUTOSAVE_DIR if set (tests), else $XDG_CACHE_HOME/quadsketch, else ~/.cache/quadsketch.
std::filesystem::path autosave_dir();
//! autosave_dir()/autosave.layout.json
std::filesystem::path autosave_path();

//! Writes the layout with its "autosave" block (mesh, layout file, time) in one atomic write. \p
//! mesh_path and \p layout_path are the files being edited. \throw QsError when the folder is not
//! writable.
void write_autosave(const Layout& layout, const TriMesh* mesh, const std::string& mesh_path,
                    const std::string& layout_path);

struct AutosaveOffer {
  std::filesystem::path path;  //!< the autosave layout
  std::string mesh_path;       //!< the mesh it belongs to (absolute)
  std::string layout_path;     //!< the file it was editing ("" for a new layout)
  std::string saved_at;        //!< local time, for the prompt
};

//! The autosave, when one exists and is worth offering: readable, with its "autosave" block,
//! and not older than the layout file it was editing (a save after it supersedes it).
//! Whatever file is open: a crash leaves edits to any mesh. Never throws.
std::optional<AutosaveOffer> find_autosave();
//! The same, only when it belongs to the mesh file \p mesh_path.
std::optional<AutosaveOffer> find_autosave(const std::string& mesh_path);

//! Deletes the autosave (its edits were saved). Never throws.
void remove_autosave();
//! Renames the autosave to autosave_dir()/autosave.previous.layout.json (so that a new
//! session's autosave does not overwrite edits that were never restored). Returns the new
//! path, "" when there was nothing to move or it failed. Never throws.
std::string set_autosave_aside();

}  // namespace qs::app
