// Neutral vertical grey gradient behind the scene.
#pragma once

#include <glm/glm.hpp>

#include "render/gl_util.h"

namespace qs::render {

class Background {
 public:
  //! \throw std::runtime_error if the shaders do not compile.
  void init();
  void draw();
  glm::vec3 top{0.46f, 0.48f, 0.51f};
  glm::vec3 bottom{0.20f, 0.21f, 0.23f};

 private:
  GlProgram program_;
  GlVertexArray vao_;
};

}  // namespace qs::render
