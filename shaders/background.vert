#version 330 core
// Full-screen triangle from the vertex id (no vertex buffer).
out float v_height;
void main() {
  vec2 p = vec2((gl_VertexID == 1) ? 3.0 : -1.0, (gl_VertexID == 2) ? 3.0 : -1.0);
  v_height = 0.5 * (p.y + 1.0);
  gl_Position = vec4(p, 0.999, 1.0);
}
