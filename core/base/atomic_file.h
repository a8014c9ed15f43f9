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

//! Reads a whole file. \throw InvalidInputError naming the path when it cannot be read.
std::string read_file(const std::string& path);

}  // namespace qs
