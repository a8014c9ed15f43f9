#include "render/camera.h"

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

namespace qs::render {

void Camera::set_viewport(int width, int height) {
  width_ = std::max(1, width);
  height_ = std::max(1, height);
}

void Camera::set_scene(const glm::vec3& center, float radius) {
  scene_center_ = center;
  scene_radius_ = radius > 0.0f && std::isfinite(radius) ? radius : 1.0f;
}

namespace {

constexpr float kPi = 3.14159265358979f;
constexpr float kHalfPi = 0.5f * kPi;
constexpr float kTurntableRadPerPixel = kPi / 500.0f;

// The angle in (-pi, pi] equal to \p a modulo 2 pi.
float wrap_angle(float a) {
  return std::remainder(a, 2.0f * kPi);
}

}  // namespace

glm::quat Camera::turntable_rotation(float yaw, float pitch) {
  return glm::angleAxis(pitch, glm::vec3(1.0f, 0.0f, 0.0f)) *
         glm::angleAxis(yaw, glm::vec3(0.0f, 1.0f, 0.0f));
}

void Camera::angles_from_rotation(const glm::quat& rotation, float& yaw, float& pitch) const {
  const glm::mat3 to_world = glm::mat3_cast(glm::conjugate(rotation));
  const glm::vec3 e = to_world * glm::vec3(0.0f, 0.0f, 1.0f);  // towards the eye
  pitch = std::asin(std::clamp(e.y, -1.0f, 1.0f));
  if (std::abs(e.y) > 0.999f) {  // straight from above or below: the screen's up gives the yaw
    const glm::vec3 u = to_world * glm::vec3(0.0f, 1.0f, 0.0f);
    yaw = e.y > 0.0f ? std::atan2(u.x, -u.z) : std::atan2(-u.x, u.z);
  } else {
    yaw = std::atan2(-e.x, e.z);
  }
}

void Camera::set_goal_angles(float yaw, float pitch) {
  goal_yaw_ = yaw;
  goal_pitch_ = std::clamp(pitch, -kHalfPi, kHalfPi);
  goal_rotation_ = turntable_rotation(goal_yaw_, goal_pitch_);
}

void Camera::set_orbit_mode(OrbitMode mode) {
  mode_ = mode;
  animating_ = false;
  if (mode_ == OrbitMode::Turntable) {
    angles_from_rotation(rotation_, yaw_, pitch_);
    rotation_ = turntable_rotation(yaw_, pitch_);
  }
  goal_rotation_ = rotation_;
  goal_yaw_ = yaw_;
  goal_pitch_ = pitch_;
  goal_target_ = target_;
  goal_distance_ = distance_;
}

void Camera::reset(bool immediate) {
  // A three-quarter view from slightly above reads better than a flat front view.
  set_goal_angles(glm::radians(-30.0f), glm::radians(20.0f));
  goal_target_ = scene_center_;
  goal_distance_ = scene_radius_ / std::sin(0.5f * fov_y_rad_) * 1.05f;
  animating_ = true;
  if (immediate) update(1e6f);
}

void Camera::frame_all(bool immediate) {
  goal_rotation_ = animating_ ? goal_rotation_ : rotation_;
  if (!animating_) goal_yaw_ = yaw_, goal_pitch_ = pitch_;
  goal_target_ = scene_center_;
  goal_distance_ = scene_radius_ / std::sin(0.5f * fov_y_rad_) * 1.05f;
  animating_ = true;
  if (immediate) update(1e6f);
}

void Camera::set_axis_view(AxisView view, bool immediate) {
  float yaw = 0.0f, pitch = 0.0f;
  switch (view) {
    case AxisView::Front:
      break;
    case AxisView::Back:
      yaw = kPi;
      break;
    case AxisView::Right:
      yaw = -kHalfPi;
      break;
    case AxisView::Left:
      yaw = kHalfPi;
      break;
    case AxisView::Top:
      pitch = kHalfPi;
      break;
    case AxisView::Bottom:
      pitch = -kHalfPi;
      break;
  }
  if (!animating_) {
    goal_target_ = target_;
    goal_distance_ = distance_;
  }
  set_goal_angles(yaw, pitch);
  animating_ = true;
  if (immediate) update(1e6f);
}

void Camera::orbit_step(float yaw_deg, float pitch_deg) {
  if (!animating_) {
    goal_target_ = target_;
    goal_distance_ = distance_;
    goal_yaw_ = yaw_;
    goal_pitch_ = pitch_;
    goal_rotation_ = rotation_;
  }
  if (mode_ == OrbitMode::Turntable) {
    set_goal_angles(goal_yaw_ + glm::radians(yaw_deg), goal_pitch_ + glm::radians(pitch_deg));
  } else {
    goal_rotation_ = glm::normalize(
        glm::angleAxis(glm::radians(pitch_deg), glm::vec3(1.0f, 0.0f, 0.0f)) * goal_rotation_ *
        glm::angleAxis(glm::radians(yaw_deg), glm::vec3(0.0f, 1.0f, 0.0f)));
  }
  animating_ = true;
}

void Camera::focus(const glm::vec3& center, float radius, const glm::vec3& normal) {
  goal_rotation_ = rotation_;
  goal_yaw_ = yaw_;
  goal_pitch_ = pitch_;
  if (glm::length(normal) > 1e-6f && mode_ == OrbitMode::Turntable) {
    // Look against the normal: the eye on its side, as a turntable can (no roll).
    const glm::vec3 e = glm::normalize(normal);
    const float pitch = std::asin(std::clamp(e.y, -1.0f, 1.0f));
    const float yaw = std::abs(e.y) > 0.999f ? yaw_ : std::atan2(-e.x, e.z);
    set_goal_angles(yaw, pitch);
  } else if (glm::length(normal) > 1e-6f) {
    // Rotate the normal (in view space) onto the view axis +z (towards the eye).
    const glm::vec3 n = glm::normalize(glm::mat3_cast(rotation_) * normal);
    const glm::vec3 z(0.0f, 0.0f, 1.0f);
    const glm::vec3 axis = glm::cross(n, z);
    const float len = glm::length(axis);
    const float angle = std::atan2(len, glm::dot(n, z));
    if (len > 1e-6f)
      goal_rotation_ = glm::normalize(glm::angleAxis(angle, axis / len) * rotation_);
    else if (angle > 1.0f)  // looking exactly from behind: turn around the vertical
      goal_rotation_ =
          glm::normalize(glm::angleAxis(angle, glm::vec3(0.0f, 1.0f, 0.0f)) * rotation_);
  }
  goal_target_ = center;
  // Never zoom in so far that a single vertex fills the screen.
  const float r = std::max(radius, 0.12f * scene_radius_);
  goal_distance_ = r / std::sin(0.5f * fov_y_rad_) * 2.0f;
  animating_ = true;
}

bool Camera::update(float dt) {
  if (!animating_) return false;
  // Exponential approach: frame-rate independent and never overshoots.
  const float a = 1.0f - std::exp(-dt * 12.0f);
  target_ = glm::mix(target_, goal_target_, a);
  distance_ = glm::mix(distance_, goal_distance_, a);
  bool rotated = false;
  if (mode_ == OrbitMode::Turntable) {
    yaw_ += a * wrap_angle(goal_yaw_ - yaw_);
    pitch_ += a * (goal_pitch_ - pitch_);
    rotation_ = turntable_rotation(yaw_, pitch_);
    rotated =
        std::abs(wrap_angle(goal_yaw_ - yaw_)) < 1e-5f && std::abs(goal_pitch_ - pitch_) < 1e-5f;
  } else {
    rotation_ = glm::normalize(glm::slerp(rotation_, goal_rotation_, a));
    rotated = std::abs(glm::dot(rotation_, goal_rotation_)) > 1.0f - 1e-7f;
  }
  if (glm::length(target_ - goal_target_) < 1e-4f * scene_radius_ &&
      std::abs(distance_ - goal_distance_) < 1e-4f * scene_radius_ && rotated) {
    target_ = goal_target_;
    distance_ = goal_distance_;
    if (mode_ == OrbitMode::Turntable) {
      yaw_ = wrap_angle(goal_yaw_);
      pitch_ = goal_pitch_;
      rotation_ = turntable_rotation(yaw_, pitch_);
    } else {
      rotation_ = goal_rotation_;
    }
    animating_ = false;
  }
  return true;
}

glm::vec3 Camera::sphere_point(const glm::vec2& screen) const {
  // Bell's virtual trackball: a sphere in the middle glued to a hyperbolic sheet, so that
  // drags outside the sphere still rotate smoothly (mostly around the view axis).
  const float s = 2.0f / float(std::min(width_, height_));
  const glm::vec2 p((screen.x - 0.5f * width_) * s, (0.5f * height_ - screen.y) * s);
  const float r2 = glm::dot(p, p);
  const float z = r2 <= 0.5f ? std::sqrt(1.0f - r2) : 0.5f / std::sqrt(r2);
  return glm::normalize(glm::vec3(p, z));
}

void Camera::begin_orbit(const glm::vec2& screen) {
  animating_ = false;
  orbit_last_ = sphere_point(screen);
  orbit_last_screen_ = screen;
}

void Camera::orbit_to(const glm::vec2& screen) {
  if (mode_ == OrbitMode::Turntable) {
    // Horizontal drags turn the scene about the up axis with the cursor, vertical ones tilt it.
    const glm::vec2 d = screen - orbit_last_screen_;
    orbit_last_screen_ = screen;
    yaw_ = wrap_angle(yaw_ + d.x * kTurntableRadPerPixel);
    pitch_ = std::clamp(pitch_ + d.y * kTurntableRadPerPixel, -kHalfPi, kHalfPi);
    rotation_ = turntable_rotation(yaw_, pitch_);
    return;
  }
  orbit_last_screen_ = screen;
  const glm::vec3 p = sphere_point(screen);
  const glm::vec3 axis = glm::cross(orbit_last_, p);
  const float len = glm::length(axis);
  if (len > 1e-7f) {
    // The rotation is expressed in view space, hence applied on the left.
    const float angle = std::atan2(len, glm::dot(orbit_last_, p)) * 1.5f;
    rotation_ = glm::normalize(glm::angleAxis(angle, axis / len) * rotation_);
  }
  orbit_last_ = p;
}

void Camera::pan(const glm::vec2& delta) {
  animating_ = false;
  // World size of one pixel at the target's depth.
  const float pixel = 2.0f * distance_ * std::tan(0.5f * fov_y_rad_) / float(height_);
  const glm::mat3 to_world = glm::mat3_cast(glm::conjugate(rotation_));
  target_ -= to_world * glm::vec3(delta.x * pixel, -delta.y * pixel, 0.0f);
}

void Camera::zoom(float steps) {
  animating_ = false;
  distance_ *= std::pow(0.88f, steps);
  distance_ = std::clamp(distance_, 1e-3f * scene_radius_, 50.0f * scene_radius_);
}

glm::mat4 Camera::view() const {
  return glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 0.0f, -distance_)) *
         glm::mat4_cast(rotation_) * glm::translate(glm::mat4(1.0f), -target_);
}

glm::mat4 Camera::projection() const {
  // Clip planes hug the scene sphere for depth precision, but stay valid when the camera
  // is inside it.
  const float to_center = glm::length(eye() - scene_center_);
  const float far_plane = to_center + 1.5f * scene_radius_;
  const float near_plane = std::max(to_center - 1.5f * scene_radius_, 1e-3f * far_plane);
  const glm::mat4 shift = glm::translate(
      glm::mat4(1.0f), glm::vec3(2.0f * view_offset_px_ / float(width_), 0.0f, 0.0f));
  const float aspect = float(width_) / float(height_);
  if (orthographic_) {
    // The view shows at the target's distance what the perspective view shows there.
    const float h = distance_ * std::tan(0.5f * fov_y_rad_);
    return shift *
           glm::ortho(-h * aspect, h * aspect, -h, h, to_center - 1.5f * scene_radius_, far_plane);
  }
  return shift * glm::perspective(fov_y_rad_, aspect, near_plane, far_plane);
}

glm::vec3 Camera::view_direction() const {
  return glm::normalize(glm::mat3_cast(glm::conjugate(rotation_)) * glm::vec3(0.0f, 0.0f, -1.0f));
}

glm::vec3 Camera::up_direction() const {
  return glm::normalize(glm::mat3_cast(glm::conjugate(rotation_)) * glm::vec3(0.0f, 1.0f, 0.0f));
}

glm::vec3 Camera::eye() const {
  return target_ + glm::mat3_cast(glm::conjugate(rotation_)) * glm::vec3(0.0f, 0.0f, distance_);
}

Ray Camera::ray(const glm::vec2& screen) const {
  const glm::mat4 inverse = glm::inverse(projection() * view());
  const float x = 2.0f * screen.x / float(width_) - 1.0f;
  const float y = 1.0f - 2.0f * screen.y / float(height_);
  glm::vec4 a = inverse * glm::vec4(x, y, -1.0f, 1.0f);
  glm::vec4 b = inverse * glm::vec4(x, y, 1.0f, 1.0f);
  Ray r;
  r.origin = glm::dvec3(glm::vec3(a) / a.w);
  r.direction = glm::normalize(glm::dvec3(glm::vec3(b) / b.w) - r.origin);
  return r;
}

glm::vec3 Camera::project(const glm::vec3& world) const {
  const glm::vec4 clip = projection() * view() * glm::vec4(world, 1.0f);
  if (clip.w <= 0.0f) return {-1e9f, -1e9f, 2.0f};
  const glm::vec3 ndc = glm::vec3(clip) / clip.w;
  return {(ndc.x * 0.5f + 0.5f) * float(width_), (0.5f - ndc.y * 0.5f) * float(height_), ndc.z};
}

}  // namespace qs::render
