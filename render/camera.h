// Orbit camera around a target: turntable (default) or virtual-trackball rotation, pan in the
// view plane, dolly zoom, axis views, perspective or orthographic projection, animated moves.
// GL-free. Screen coordinates are window (logical) pixels with y down, as GLFW gives them;
// the framebuffer may be larger on high-DPI displays.
//
// World axes: +y is up (the convention of OBJ, PLY and glTF files and of Blender's OBJ
// export). The turntable turns about the world y axis and tilts about the view's horizontal
// axis, never rolling; the front view looks along -z (from +z), the right view along -x (from
// +x), the top view along -y (from +y, with -z up on the screen).
#pragma once

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace qs::render {

struct Ray {
  glm::dvec3 origin{0.0};
  glm::dvec3 direction{0.0, 0.0, -1.0};  //!< unit length
};

//! How a left drag rotates the view.
enum class OrbitMode {
  Turntable,  //!< about the world up axis and the horizontal view axis; no roll
  Trackball,  //!< Bell's virtual trackball: free rotation, rolls with circular drags
};

//! The axis views (Blender's numpad views).
enum class AxisView { Front, Back, Right, Left, Top, Bottom };

class Camera {
 public:
  //! Window size in logical pixels.
  void set_viewport(int width, int height);
  glm::vec2 viewport() const { return {float(width_), float(height_)}; }
  //! Horizontal shift of the view centre in pixels (e.g. half the width of a side panel), so
  //! that the scene centres in the visible part of the window.
  void set_view_offset(float pixels) { view_offset_px_ = pixels; }

  //! Bounding sphere of the scene: used by reset(), frame_all() and the clipping planes.
  void set_scene(const glm::vec3& center, float radius);
  //! Home view: a three-quarter view from slightly above, the whole scene in view (animated
  //! unless \p immediate).
  void reset(bool immediate = false);
  //! The whole scene in view, keeping the viewing direction (animated unless \p immediate).
  void frame_all(bool immediate = false);
  //! Centers on a sphere and zooms so that it fills about half the view (animated). With a
  //! non-zero \p normal, also turns to look at it from that side (turntable: the yaw and
  //! tilt of that direction; trackball: the smallest rotation), so that a point on the far
  //! side of the surface comes into view from outside.
  void focus(const glm::vec3& center, float radius, const glm::vec3& normal = glm::vec3(0.0f));
  //! Looks along an axis (see the header comment), keeping target and distance (animated
  //! unless \p immediate).
  void set_axis_view(AxisView view, bool immediate = false);
  //! Turns the view by \p yaw_deg about the world up axis and tilts it by \p pitch_deg (a
  //! turntable step in both modes; numpad 4/6/8/2). Animated.
  void orbit_step(float yaw_deg, float pitch_deg);

  void set_orbit_mode(OrbitMode mode);
  OrbitMode orbit_mode() const { return mode_; }
  void set_orthographic(bool orthographic) { orthographic_ = orthographic; }
  bool orthographic() const { return orthographic_; }

  //! Orbit drag: begin at a screen point, then move to further points.
  void begin_orbit(const glm::vec2& screen);
  void orbit_to(const glm::vec2& screen);
  //! Moves the target so that the scene follows the cursor by \p delta pixels.
  void pan(const glm::vec2& delta);
  //! Dolly towards the target; positive steps zoom in (mouse wheel).
  void zoom(float steps);
  //! Advances the animation by \p dt seconds. Returns true while animating.
  bool update(float dt);
  bool animating() const { return animating_; }

  glm::mat4 view() const;
  glm::mat4 projection() const;
  glm::vec3 eye() const;
  glm::vec3 target() const { return target_; }
  //! Unit vector from the eye towards the target (world space).
  glm::vec3 view_direction() const;
  //! Unit vector pointing up on the screen (world space).
  glm::vec3 up_direction() const;
  float distance() const { return distance_; }
  float scene_radius() const { return scene_radius_; }

  //! Ray through a screen point (world space).
  Ray ray(const glm::vec2& screen) const;
  //! Screen position (x, y in pixels) and NDC depth of a world point; depth > 1 or w <= 0
  //! means behind the camera or beyond the far plane.
  glm::vec3 project(const glm::vec3& world) const;

 private:
  glm::vec3 sphere_point(const glm::vec2& screen) const;
  //! Turntable angles (radians) of the current rotation (its roll dropped).
  void angles_from_rotation(const glm::quat& rotation, float& yaw, float& pitch) const;
  static glm::quat turntable_rotation(float yaw, float pitch);
  //! Sets the animation goal to the turntable angles (or the rotation they give).
  void set_goal_angles(float yaw, float pitch);

  int width_ = 1;
  int height_ = 1;
  float view_offset_px_ = 0.0f;
  float fov_y_rad_ = glm::radians(35.0f);
  OrbitMode mode_ = OrbitMode::Turntable;
  bool orthographic_ = false;
  //! World to view rotation. In turntable mode always turntable_rotation(yaw_, pitch_).
  glm::quat rotation_{1.0f, 0.0f, 0.0f, 0.0f};
  float yaw_ = 0.0f;    //!< turntable: turn about +y (radians)
  float pitch_ = 0.0f;  //!< turntable: tilt, positive looks from above, in [-pi/2, pi/2]
  glm::vec3 target_{0.0f};
  float distance_ = 3.0f;
  glm::vec3 scene_center_{0.0f};
  float scene_radius_ = 1.0f;
  glm::vec3 orbit_last_{0.0f, 0.0f, 1.0f};
  glm::vec2 orbit_last_screen_{0.0f};
  // Animation goals.
  bool animating_ = false;
  glm::vec3 goal_target_{0.0f};
  float goal_distance_ = 3.0f;
  glm::quat goal_rotation_{1.0f, 0.0f, 0.0f, 0.0f};
  float goal_yaw_ = 0.0f;
  float goal_pitch_ = 0.0f;
};

}  // namespace qs::render
