// Atomic file writes: the target either keeps its old content or gets the complete new one.
// Output folders can be checked up front (require_writable_folder) so that a command refuses
// an unwritable destination before it computes anything.
#pragma once

#include <functional>
#include <iosfwd>
#include <string>

namespace qs {

//! Writes \p content to \p path through a temporary file in the same folder, flushed to disk
//! and renamed over \p path. On failure the temporary file is removed and \p path keeps its
//! old content.
//! \throw QsError "cannot write '<path>': <reason>" naming \p path (never the temporary file)
//!        and the operating system's reason (strerror), e.g. "No space left on device".
void write_file_atomic(const std::string& path, const std::string& content);

//! Same, with a writer callback that streams into the temporary file. An exception of the
//! writer propagates unchanged (after the clean-up).
void write_file_atomic(const std::string& path, const std::function<void(std::ostream&)>& writer);

//! Creates the folder \p dir (with its parents; "" is the current folder) and checks that a
//! file can be created in it, by creating and removing a probe file.
//! \throw InvalidInputError "cannot write into the folder '<dir>': <reason>" (the system's
//!        reason, e.g. "Permission denied", or "it is not a folder").
void require_writable_folder(const std::string& dir);

//! For an output file: \p path is not a folder, and its folder passes require_writable_folder.
//! \throw InvalidInputError naming \p path or its folder.
void require_writable_file(const std::string& path);

//! For a thread that is about to end the process (std::_Exit) while another thread may be
//! writing: removes the temporary files of the writes in progress, and from then on every
//! write_file_atomic call in any thread waits forever instead of creating or renaming a file.
//! Targets keep their old or complete new content and no temporary file is left behind.
//! \return the number of temporary files removed.
int stop_atomic_writes_for_exit();

//! Reads a whole file. \throw InvalidInputError naming the path when it cannot be read.
std::string read_file(const std::string& path);

}  // namespace qs
