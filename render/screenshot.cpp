#include "render/screenshot.h"

#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES
#endif
#include <GL/glcorearb.h>
#include <stb_image_write.h>  // implementation lives in Debian's libstb

#include <string>
#include <vector>

#include "core/base/atomic_file.h"

namespace qs::render {

bool save_framebuffer_png(const std::string& path, int width, int height, std::string* error) {
  if (width <= 0 || height <= 0) {
    if (error) *error = "empty framebuffer";
    return false;
  }
  std::vector<unsigned char> pixels(static_cast<std::size_t>(width) * height * 3);
  glReadBuffer(GL_BACK);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width, height, GL_RGB, GL_UNSIGNED_BYTE, pixels.data());
  // GL rows start at the bottom; PNG rows at the top. Encode in memory, then write the file
  // atomically (temp file + rename) so an interrupted run never leaves a torn PNG.
  std::string png;
  const auto append = [](void* context, void* data, int size) {
    static_cast<std::string*>(context)->append(static_cast<const char*>(data),
                                               static_cast<std::size_t>(size));
  };
  stbi_flip_vertically_on_write(1);
  const int ok = stbi_write_png_to_func(append, &png, width, height, 3, pixels.data(), width * 3);
  stbi_flip_vertically_on_write(0);
  if (!ok) {
    if (error) *error = "cannot encode the framebuffer as PNG for " + path;
    return false;
  }
  try {
    write_file_atomic(path, png);
  } catch (const std::exception& e) {
    if (error) *error = e.what();
    return false;
  }
  return true;
}

}  // namespace qs::render
