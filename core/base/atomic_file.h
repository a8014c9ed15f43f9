// Atomic file writes: the target either keeps its old content or gets the complete new one.
#pragma once

#include <functional>
#include <iosfwd>
#include <string>

namespace qs {

//! Writes \p content to \p path through a temporary file in the same folder, flushed to disk
//! and renamed over \p path. \throw QsError when the folder is not writable.
void write_file_atomic(const std::string& path, const std::string& content);

//! Same, with a writer callback that streams into the temporary file.
void write_file_atomic(const std::string& path, const std::function<void(std::ostream&)>& writer);

//! For a thread that is about to end the process (std::_Exit) while another thread may be
//! writing: removes the temporary files of the writes in progress, and from then on every
//! write_file_atomic call in any thread waits forever instead of creating or renaming a file.
//! Targets keep their old or complete new content and no temporary file is left behind.
//! \return the number of temporary files removed.
int stop_atomic_writes_for_exit();

//! Reads a whole file. \throw InvalidInputError naming the path when it cannot be read.
std::string read_file(const std::string& path);

}  // namespace qs
