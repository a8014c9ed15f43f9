#version 330 core
in vec3 v_position_view;
in vec3 v_normal_view;
in vec3 v_bary;
in vec2 v_uv;
flat in float v_flag;

uniform vec3 u_front_color;
uniform vec3 u_back_color;
uniform bool u_flat;             // face normals from screen-space derivatives
uniform bool u_wireframe;
uniform vec3 u_wire_color;
uniform float u_wire_width;      // pixels
uniform int u_mode;              // 0 shaded, 1 uv checker + grid
uniform float u_checker_scale;   // checker cells per uv unit
uniform bool u_show_foldovers;

out vec4 frag_color;

// Distance to the nearest edge in pixels, from the barycentric coordinates' screen gradient.
float edge_distance_px() {
  vec3 d = fwidth(v_bary);
  vec3 px = v_bary / max(d, vec3(1e-6));
  return min(px.x, min(px.y, px.z));
}

// Anti-aliased iso-lines at integer values of x, width in pixels.
float grid_line(vec2 x, float width_px) {
  vec2 d = fwidth(x);
  vec2 f = abs(fract(x - 0.5) - 0.5) / max(d, vec2(1e-6));
  return 1.0 - clamp(min(f.x, f.y) - 0.5 * width_px + 0.5, 0.0, 1.0);
}

void main() {
  vec3 n = u_flat ? normalize(cross(dFdx(v_position_view), dFdy(v_position_view)))
                  : normalize(v_normal_view);
  vec3 base = u_front_color;
  // Two-sided lighting: light both sides, tint back faces so orientation stays readable.
  if (!gl_FrontFacing) {
    if (!u_flat) n = -n;
    base = u_back_color;
  }
  if (u_flat && dot(n, v_position_view) > 0.0) n = -n;

  if (u_mode == 1) {
    vec2 uv = v_uv * u_checker_scale;
    float checker = mod(floor(uv.x) + floor(uv.y), 2.0);
    base *= mix(0.78, 1.0, checker);
    float fine = grid_line(uv, 1.0);
    float coarse = grid_line(uv / 4.0, 2.0);
    base = mix(base, vec3(0.85, 0.32, 0.22), 0.55 * fine);
    base = mix(base, vec3(0.12, 0.13, 0.16), 0.8 * coarse);
  }
  if (u_show_foldovers && v_flag > 0.5) base = mix(base, vec3(0.95, 0.08, 0.08), 0.75);

  // Headlight plus a weaker fill from above-left; Blinn-Phong specular.
  vec3 v = normalize(-v_position_view);
  vec3 l1 = v;
  vec3 l2 = normalize(vec3(-0.5, 0.8, 0.4));
  float diffuse = 0.75 * max(dot(n, l1), 0.0) + 0.25 * max(dot(n, l2), 0.0);
  float specular = pow(max(dot(n, normalize(l1 + v)), 0.0), 48.0) * 0.18;
  vec3 color = base * (0.22 + 0.78 * diffuse) + vec3(specular);

  if (u_wireframe) {
    float d = edge_distance_px();
    float line = 1.0 - clamp(d - 0.5 * u_wire_width + 0.5, 0.0, 1.0);
    color = mix(color, u_wire_color, line * 0.6);
  }
  frag_color = vec4(color, 1.0);
}
