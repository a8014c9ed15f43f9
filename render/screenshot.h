// Saving the current framebuffer as PNG (automation and tests).
#pragma once

#include <string>

namespace qs::render {

//! Reads the back buffer (\p width x \p height framebuffer pixels) and writes an RGB PNG.
//! Returns false with a message in \p error on failure.
bool save_framebuffer_png(const std::string& path, int width, int height, std::string* error);

}  // namespace qs::render
