#include "render/background.h"

#include <stdexcept>

namespace qs::render {

void Background::init() {
  std::string log;
  if (!program_.build("background.vert", "background.frag", &log))
    throw std::runtime_error("background shader: " + log);
}

void Background::draw() {
  // A single full-screen triangle generated from gl_VertexID: no buffers needed, but core
  // profile still requires a bound VAO.
  glDisable(GL_DEPTH_TEST);
  glDepthMask(GL_FALSE);
  program_.use();
  program_.set("u_top", top);
  program_.set("u_bottom", bottom);
  vao_.bind();
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glDepthMask(GL_TRUE);
  glEnable(GL_DEPTH_TEST);
}

}  // namespace qs::render
