#version 330 core
in vec4 v_color;
in float v_across;
in float v_half_width;
out vec4 frag_color;
void main() {
  float coverage = clamp(v_half_width + 0.5 - abs(v_across), 0.0, 1.0);
  if (coverage <= 0.0) discard;
  // Darker rim makes lines readable on both light and dark surfaces.
  float rim = smoothstep(v_half_width - 1.5, v_half_width, abs(v_across));
  vec3 color = mix(v_color.rgb, v_color.rgb * 0.45, rim * step(2.5, v_half_width));
  frag_color = vec4(color, v_color.a * coverage);
}
