#version 330 core
// Triangles are drawn unindexed (3 vertices per face, corner order), so every corner can
// carry its own uv and the barycentric coordinate for the wireframe follows from the id.
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;   // smooth (area-weighted) vertex normal
layout(location = 2) in vec2 a_uv;       // per-corner parameterization
layout(location = 3) in float a_flag;    // 1 on faces that fold over in the parameterization

uniform mat4 u_view;
uniform mat4 u_proj;

out vec3 v_position_view;
out vec3 v_normal_view;
out vec3 v_bary;
out vec2 v_uv;
flat out float v_flag;

void main() {
  vec4 p = u_view * vec4(a_position, 1.0);
  v_position_view = p.xyz;
  v_normal_view = mat3(u_view) * a_normal;  // the view matrix has no scaling
  int corner = gl_VertexID % 3;
  v_bary = vec3(corner == 0, corner == 1, corner == 2);
  v_uv = a_uv;
  v_flag = a_flag;
  gl_Position = u_proj * p;
}
