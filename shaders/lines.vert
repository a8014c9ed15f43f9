#version 330 core
// Thick polylines without geometry shaders: one instance per segment, six vertices forming
// a screen-space quad around it (extended by half the width at both ends so that joints
// of consecutive segments are filled).
layout(location = 0) in vec3 a_p0;
layout(location = 1) in vec3 a_p1;
layout(location = 2) in vec4 a_color;
layout(location = 3) in float a_width;  // window pixels

uniform mat4 u_view;
uniform mat4 u_proj;
uniform vec2 u_viewport;    // framebuffer pixels
uniform float u_pixel_ratio;
uniform float u_pull;       // world units towards the camera (avoids z-fighting)
uniform float u_width_scale;

out vec4 v_color;
out float v_across;     // signed distance from the center line, pixels
out float v_half_width; // pixels

const vec2 kCorners[6] = vec2[6](vec2(0, -1), vec2(1, -1), vec2(1, 1),
                                 vec2(0, -1), vec2(1, 1), vec2(0, 1));

vec4 to_clip(vec3 p) {
  vec4 q = u_view * vec4(p, 1.0);
  q.xyz += normalize(-q.xyz) * u_pull;
  return u_proj * q;
}

void main() {
  vec2 corner = kCorners[gl_VertexID];
  vec4 c0 = to_clip(a_p0);
  vec4 c1 = to_clip(a_p1);
  vec2 s0 = c0.xy / c0.w * 0.5 * u_viewport;
  vec2 s1 = c1.xy / c1.w * 0.5 * u_viewport;
  vec2 d = s1 - s0;
  float len = length(d);
  d = len > 1e-4 ? d / len : vec2(1.0, 0.0);
  vec2 n = vec2(-d.y, d.x);
  float half_width = 0.5 * a_width * u_width_scale * u_pixel_ratio;
  float w = half_width + 1.0;  // one pixel margin for anti-aliasing
  vec4 c = corner.x < 0.5 ? c0 : c1;
  vec2 offset = n * corner.y * w + d * (corner.x < 0.5 ? -half_width : half_width);
  c.xy += offset / (0.5 * u_viewport) * c.w;
  gl_Position = c;
  v_color = a_color;
  v_across = corner.y * w;
  v_half_width = half_width;
}
