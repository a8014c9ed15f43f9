// GLSL sources (shaders/*.vert|*.frag): embedded at build time, reloadable from disk in Debug.
#pragma once

#include <string>

namespace qs::render {

//! Source of an embedded shader by file name ("mesh.vert"), or nullptr. Generated at build
//! time by cmake/EmbedShaders.cmake.
const char* embedded_shader(const char* name);

//! Source of a shader by file name. In Debug builds the file in QS_SHADER_SOURCE_DIR is
//! preferred when it exists, so edits show up after "Reload shaders" without rebuilding.
//! \throw std::runtime_error when the shader is unknown.
std::string shader_source(const std::string& name);

//! True when shader_source() reads from disk (Debug builds with the source tree present).
bool shaders_from_disk();

}  // namespace qs::render
