#include "render/gl_util.h"

#include <glm/gtc/type_ptr.hpp>
#include <utility>

#include "render/shader_library.h"

namespace qs::render {

namespace {

GLuint compile(GLenum type, const std::string& source, const std::string& name, std::string* log) {
  GLuint shader = glCreateShader(type);
  const char* text = source.c_str();
  glShaderSource(shader, 1, &text, nullptr);
  glCompileShader(shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char buffer[4096];
    glGetShaderInfoLog(shader, sizeof(buffer), nullptr, buffer);
    if (log) *log += name + ": " + buffer;
    glDeleteShader(shader);
    return 0;
  }
  return shader;
}

}  // namespace

GlProgram::~GlProgram() {
  if (id_) glDeleteProgram(id_);
}

GlProgram::GlProgram(GlProgram&& other) noexcept : id_(std::exchange(other.id_, 0)) {}

GlProgram& GlProgram::operator=(GlProgram&& other) noexcept {
  if (this != &other) {
    if (id_) glDeleteProgram(id_);
    id_ = std::exchange(other.id_, 0);
  }
  return *this;
}

bool GlProgram::build(const std::string& vertex_name, const std::string& fragment_name,
                      std::string* log) {
  std::string vs_source, fs_source;
  try {
    vs_source = shader_source(vertex_name);
    fs_source = shader_source(fragment_name);
  } catch (const std::exception& e) {
    if (log) *log += e.what();
    return false;
  }
  const GLuint vs = compile(GL_VERTEX_SHADER, vs_source, vertex_name, log);
  const GLuint fs = compile(GL_FRAGMENT_SHADER, fs_source, fragment_name, log);
  if (!vs || !fs) {
    if (vs) glDeleteShader(vs);
    if (fs) glDeleteShader(fs);
    return false;
  }
  const GLuint program = glCreateProgram();
  glAttachShader(program, vs);
  glAttachShader(program, fs);
  glLinkProgram(program);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = GL_FALSE;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    char buffer[4096];
    glGetProgramInfoLog(program, sizeof(buffer), nullptr, buffer);
    if (log) *log += vertex_name + "+" + fragment_name + ": " + buffer;
    glDeleteProgram(program);
    return false;
  }
  if (id_) glDeleteProgram(id_);
  id_ = program;
  return true;
}

void GlProgram::use() const {
  glUseProgram(id_);
}
GLint GlProgram::uniform(const char* name) const {
  return glGetUniformLocation(id_, name);
}
void GlProgram::set(const char* name, int value) const {
  glUniform1i(uniform(name), value);
}
void GlProgram::set(const char* name, float value) const {
  glUniform1f(uniform(name), value);
}
void GlProgram::set(const char* name, const glm::vec2& v) const {
  glUniform2fv(uniform(name), 1, glm::value_ptr(v));
}
void GlProgram::set(const char* name, const glm::vec3& v) const {
  glUniform3fv(uniform(name), 1, glm::value_ptr(v));
}
void GlProgram::set(const char* name, const glm::vec4& v) const {
  glUniform4fv(uniform(name), 1, glm::value_ptr(v));
}
void GlProgram::set(const char* name, const glm::mat4& m) const {
  glUniformMatrix4fv(uniform(name), 1, GL_FALSE, glm::value_ptr(m));
}
void GlProgram::set(const char* name, const glm::mat3& m) const {
  glUniformMatrix3fv(uniform(name), 1, GL_FALSE, glm::value_ptr(m));
}

GlBuffer::~GlBuffer() {
  if (id_) glDeleteBuffers(1, &id_);
}

void GlBuffer::upload(const void* data, std::size_t bytes, GLenum usage) {
  if (!id_) glGenBuffers(1, &id_);
  glBindBuffer(GL_ARRAY_BUFFER, id_);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(bytes), data, usage);
}

GlVertexArray::~GlVertexArray() {
  if (id_) glDeleteVertexArrays(1, &id_);
}

void GlVertexArray::bind() {
  if (!id_) glGenVertexArrays(1, &id_);
  glBindVertexArray(id_);
}

void GlVertexArray::attribute(GLuint location, const GlBuffer& buffer, int components,
                              int stride_floats, int offset_floats, GLuint divisor) {
  bind();
  glBindBuffer(GL_ARRAY_BUFFER, buffer.id());
  glEnableVertexAttribArray(location);
  glVertexAttribPointer(location, components, GL_FLOAT, GL_FALSE,
                        stride_floats * static_cast<GLsizei>(sizeof(float)),
                        reinterpret_cast<const void*>(offset_floats * sizeof(float)));
  glVertexAttribDivisor(location, divisor);
}

}  // namespace qs::render
