// Orbit camera: virtual trackball rotation around a target, pan in the view plane, dolly zoom,
// animated focus. Screen coordinates are window (logical) pixels with y down, as GLFW gives
// them; the framebuffer may be larger on high-DPI displays.
#pragma once

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace qs::render {

struct Ray {
  glm::dvec3 origin{0.0};
  glm::dvec3 direction{0.0, 0.0, -1.0};  //!< unit length
};

class Camera {
 public:
  //! Window size in logical pixels.
  void set_viewport(int width, int height);
  glm::vec2 viewport() const { return {float(width_), float(height_)}; }
  //! Horizontal shift of the view centre in pixels (e.g. half the width of a side panel), so
  //! that the scene centres in the visible part of the window.
  void set_view_offset(float pixels) { view_offset_px_ = pixels; }

  //! Bounding sphere of the scene: used by reset() and for the clipping planes.
  void set_scene(const glm::vec3& center, float radius);
  //! Home view: looking down -z at the whole scene (animated unless \p immediate).
  void reset(bool immediate = false);
  //! Centers on a sphere and zooms so that it fills about half the view (animated). With a
  //! non-zero \p normal, also turns (by the smallest rotation) to look at it from that side,
  //! so that a point on the far side of the surface comes into view from outside.
  void focus(const glm::vec3& center, float radius, const glm::vec3& normal = glm::vec3(0.0f));

  //! Trackball drag: begin at a screen point, then move to further points.
  void begin_orbit(const glm::vec2& screen);
  void orbit_to(const glm::vec2& screen);
  //! Moves the target so that the scene follows the cursor by \p delta pixels.
  void pan(const glm::vec2& delta);
  //! Dolly towards the target; positive steps zoom in (mouse wheel).
  void zoom(float steps);
  //! Advances the focus animation by \p dt seconds. Returns true while animating.
  bool update(float dt);

  glm::mat4 view() const;
  glm::mat4 projection() const;
  glm::vec3 eye() const;
  float distance() const { return distance_; }
  float scene_radius() const { return scene_radius_; }

  //! Ray through a screen point (world space).
  Ray ray(const glm::vec2& screen) const;
  //! Screen position (x, y in pixels) and NDC depth of a world point; depth > 1 or w <= 0
  //! means behind the camera or beyond the far plane.
  glm::vec3 project(const glm::vec3& world) const;

 private:
  glm::vec3 sphere_point(const glm::vec2& screen) const;

  int width_ = 1;
  int height_ = 1;
  float view_offset_px_ = 0.0f;
  float fov_y_rad_ = glm::radians(35.0f);
  glm::quat rotation_{1.0f, 0.0f, 0.0f, 0.0f};
  glm::vec3 target_{0.0f};
  float distance_ = 3.0f;
  glm::vec3 scene_center_{0.0f};
  float scene_radius_ = 1.0f;
  glm::vec3 orbit_last_{0.0f, 0.0f, 1.0f};
  // Focus animation goals.
  bool animating_ = false;
  glm::vec3 goal_target_{0.0f};
  float goal_distance_ = 3.0f;
  glm::quat goal_rotation_{1.0f, 0.0f, 0.0f, 0.0f};
};

}  // namespace qs::render
