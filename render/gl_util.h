// Small RAII wrappers for OpenGL 3.3 core objects (programs, buffers, vertex arrays).
// All calls must happen on the thread that owns the GL context (the main thread).
#pragma once

#ifndef GL_GLEXT_PROTOTYPES  // also set by CMake for qs_render users
#define GL_GLEXT_PROTOTYPES
#endif
#include <GL/glcorearb.h>

#include <glm/glm.hpp>
#include <string>

namespace qs::render {

//! A linked shader program built from two shader files (see shader_library.h).
class GlProgram {
 public:
  GlProgram() = default;
  ~GlProgram();
  GlProgram(GlProgram&& other) noexcept;
  GlProgram& operator=(GlProgram&& other) noexcept;
  GlProgram(const GlProgram&) = delete;
  GlProgram& operator=(const GlProgram&) = delete;

  //! Compiles and links; on failure keeps the previous program and returns false with the
  //! compiler log in \p log (so a typo during a Debug reload does not blank the view).
  bool build(const std::string& vertex_name, const std::string& fragment_name,
             std::string* log = nullptr);
  bool valid() const { return id_ != 0; }
  void use() const;
  GLint uniform(const char* name) const;
  void set(const char* name, int value) const;
  void set(const char* name, float value) const;
  void set(const char* name, const glm::vec2& value) const;
  void set(const char* name, const glm::vec3& value) const;
  void set(const char* name, const glm::vec4& value) const;
  void set(const char* name, const glm::mat4& value) const;
  void set(const char* name, const glm::mat3& value) const;

 private:
  GLuint id_ = 0;
};

//! A buffer object (GL_ARRAY_BUFFER by default).
class GlBuffer {
 public:
  GlBuffer() = default;
  ~GlBuffer();
  GlBuffer(const GlBuffer&) = delete;
  GlBuffer& operator=(const GlBuffer&) = delete;

  //! Creates the buffer on first use and replaces its content.
  void upload(const void* data, std::size_t bytes, GLenum usage = GL_STATIC_DRAW);
  GLuint id() const { return id_; }

 private:
  GLuint id_ = 0;
};

//! A vertex array object.
class GlVertexArray {
 public:
  GlVertexArray() = default;
  ~GlVertexArray();
  GlVertexArray(const GlVertexArray&) = delete;
  GlVertexArray& operator=(const GlVertexArray&) = delete;
  void bind();  //!< creates on first use
  //! Float attribute \p location read from \p buffer (bound as GL_ARRAY_BUFFER).
  void attribute(GLuint location, const GlBuffer& buffer, int components, int stride_floats,
                 int offset_floats, GLuint divisor = 0);

 private:
  GLuint id_ = 0;
};

}  // namespace qs::render
