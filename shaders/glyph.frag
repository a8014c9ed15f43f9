#version 330 core
in vec4 v_color;
in vec2 v_local;
flat in float v_half_width;
flat in float v_facing;
out vec4 frag_color;
void main() {
  float coverage = clamp(v_half_width + 0.5 - abs(v_local.y), 0.0, 1.0);
  // Bars taper towards their tips so that the crosses read as directions, not as a mesh.
  float along = abs(v_local.x);
  float taper = 1.0 - smoothstep(0.55, 1.0, along);
  float alpha = v_color.a * coverage * mix(0.35, 1.0, taper) * v_facing;
  if (alpha <= 0.01) discard;
  frag_color = vec4(v_color.rgb, alpha);
}
