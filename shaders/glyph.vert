#version 330 core
// Cross-field glyphs: one instance per sampled face, 12 vertices = two screen-space bars
// crossing at the face centre, along the field direction d and its 90° rotation n x d.
// A bar whose colour has zero alpha is skipped (constraint markers draw one bar only).
layout(location = 0) in vec3 a_center;
layout(location = 1) in vec3 a_dir;     // first direction times the arm length (world units)
layout(location = 2) in vec3 a_normal;  // unit face normal
layout(location = 3) in vec4 a_color0;  // bar along d
layout(location = 4) in vec4 a_color1;  // bar along n x d
layout(location = 5) in float a_width;  // window pixels

uniform mat4 u_view;
uniform mat4 u_proj;
uniform vec2 u_viewport;  // framebuffer pixels
uniform float u_pixel_ratio;
uniform float u_pull;     // world units towards the camera (the surface is not z-fighting)

out vec4 v_color;
out vec2 v_local;        // x: along the bar in [-1, 1]; y: across, pixels
flat out float v_half_width;
flat out float v_facing;

const vec2 kCorners[6] = vec2[6](vec2(-1, -1), vec2(1, -1), vec2(1, 1),
                                 vec2(-1, -1), vec2(1, 1), vec2(-1, 1));

vec4 to_clip(vec3 p) {
  vec4 q = u_view * vec4(p, 1.0);
  q.xyz += normalize(-q.xyz) * u_pull;
  return u_proj * q;
}

void main() {
  int bar = gl_VertexID / 6;
  vec2 corner = kCorners[gl_VertexID % 6];
  vec3 arm = bar == 0 ? a_dir : cross(a_normal, a_dir);
  vec4 color = bar == 0 ? a_color0 : a_color1;
  // Faces seen from behind fade out (they are usually hidden by the surface anyway).
  vec3 center_view = (u_view * vec4(a_center, 1.0)).xyz;
  vec3 normal_view = mat3(u_view) * a_normal;
  v_facing = dot(normal_view, -normalize(center_view)) >= 0.0 ? 1.0 : 0.35;
  if (color.a <= 0.0) {
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0);  // outside the clip volume: nothing drawn
    v_color = vec4(0.0);
    v_local = vec2(0.0);
    v_half_width = 0.0;
    return;
  }
  vec4 c0 = to_clip(a_center - arm);
  vec4 c1 = to_clip(a_center + arm);
  vec2 s0 = c0.xy / c0.w * 0.5 * u_viewport;
  vec2 s1 = c1.xy / c1.w * 0.5 * u_viewport;
  vec2 d = s1 - s0;
  float len = length(d);
  d = len > 1e-4 ? d / len : vec2(1.0, 0.0);
  vec2 n = vec2(-d.y, d.x);
  float half_width = 0.5 * a_width * u_pixel_ratio;
  float w = half_width + 1.0;  // anti-aliasing margin
  vec4 c = corner.x < 0.0 ? c0 : c1;
  c.xy += (n * corner.y * w) / (0.5 * u_viewport) * c.w;
  gl_Position = c;
  v_color = color;
  v_local = vec2(corner.x, corner.y * w);
  v_half_width = half_width;
}
