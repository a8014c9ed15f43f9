#version 330 core
// Nodes and highlighted vertices as screen-space sphere impostors (point sprites).
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec4 a_color;
layout(location = 2) in float a_size;   // diameter, window pixels
layout(location = 3) in float a_ring;   // 0 none, 1 pinned marker, 2 selected, 3 hollow ring

uniform mat4 u_view;
uniform mat4 u_proj;
uniform float u_pixel_ratio;
uniform float u_pull;
uniform float u_size_scale;

out vec4 v_color;
flat out float v_ring;

void main() {
  vec4 q = u_view * vec4(a_position, 1.0);
  q.xyz += normalize(-q.xyz) * u_pull;
  gl_Position = u_proj * q;
  gl_PointSize = max(1.0, a_size * u_size_scale * u_pixel_ratio);
  v_color = a_color;
  v_ring = a_ring;
}
