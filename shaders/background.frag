#version 330 core
in float v_height;
uniform vec3 u_top;
uniform vec3 u_bottom;
out vec4 frag_color;
void main() {
  // Slight ease so that the middle of the screen stays mid-grey.
  float t = smoothstep(0.0, 1.0, v_height);
  frag_color = vec4(mix(u_bottom, u_top, t), 1.0);
}
