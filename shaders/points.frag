#version 330 core
in vec4 v_color;
flat in float v_ring;
out vec4 frag_color;
void main() {
  vec2 p = gl_PointCoord * 2.0 - 1.0;
  p.y = -p.y;
  float r2 = dot(p, p);
  if (r2 > 1.0) discard;
  vec3 color = v_color.rgb;
  // Hint marker: a flat hollow ring (not a node).
  if (v_ring > 2.5) {
    if (r2 < 0.42) discard;
    frag_color = vec4(color, v_color.a * clamp((1.0 - sqrt(r2)) * 8.0, 0.0, 1.0));
    return;
  }
  // Pinned: dark outer ring with a gold band; selected: bright yellow ring.
  if (v_ring > 1.5 && r2 > 0.55) {
    color = vec3(1.0, 0.86, 0.15);
  } else if (v_ring > 0.5 && r2 > 0.62) {
    color = r2 > 0.85 ? vec3(0.08) : vec3(0.98, 0.78, 0.2);
  } else {
    vec3 n = vec3(p, sqrt(1.0 - r2));
    vec3 l = normalize(vec3(-0.4, 0.5, 0.8));
    float diffuse = max(dot(n, l), 0.0);
    float specular = pow(max(dot(n, normalize(l + vec3(0, 0, 1))), 0.0), 32.0);
    color = color * (0.35 + 0.65 * diffuse) + vec3(0.35 * specular);
  }
  // Soft edge against the background.
  float alpha = v_color.a * clamp((1.0 - sqrt(r2)) * 8.0, 0.0, 1.0);
  frag_color = vec4(color, alpha);
}
