// Reading input files named by the user (meshes, layouts), refusing what is not a file.
#pragma once

#include <cstdint>
#include <limits>
#include <string>

namespace qs {

//! Reads the whole of \p path. Only regular files (or symbolic links to one) are read: a
//! directory, FIFO, socket or device is refused before any read, so that a FIFO cannot block
//! and /dev/zero cannot be read forever. The file is opened without blocking and checked on
//! the opened descriptor, so it cannot be swapped for something else in between.
//! \param max_bytes  largest accepted size in bytes; a larger file (or one that grows past
//!                   it while being read) is refused without reading the rest.
//! \throw InvalidInputError "<path>: cannot open file" when it does not exist,
//!        "<path>: cannot open file (<reason>)" when it cannot be opened or read,
//!        "<path>: cannot open file: it is a directory, not a regular file" (likewise a FIFO,
//!        a socket, a device), "<path>: file too large: N bytes (the limit is M bytes)".
std::string read_input_file(const std::string& path,
                            std::uintmax_t max_bytes = std::numeric_limits<std::uintmax_t>::max());

}  // namespace qs
