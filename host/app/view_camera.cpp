// The live view's camera (view.hpp: ViewCamera): orbit, pan, dolly and framing, and the
// `candela render` options that reproduce it.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "app/view.hpp"

namespace candela {
namespace {

constexpr float kPi = 3.14159265f;

std::string vec_text(glm::vec3 v) {
  char text[96];
  std::snprintf(text, sizeof text, "%.9g,%.9g,%.9g", double(v.x), double(v.y), double(v.z));
  return text;
}

std::string number_text(float v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", double(v));
  return text;
}

}  // namespace

ViewCamera::ViewCamera(Start start) : start_(std::move(start)) { reset(); }

void ViewCamera::look_from_desc(const CameraDesc& c) {
  shown_ = c;
  moved_ = false;
  from_ = c.position;
  glm::vec3 forward = glm::normalize(c.forward);
  float distance = c.focus_distance.value_or(std::max(start_.bounds.empty() ? 1.0f : start_.bounds.radius(), 1e-3f));
  at_ = from_ + forward * distance;
  // Orbits turn about the world's up (glTF: +y) unless the camera looks along it
  up_ = std::abs(forward.y) < 0.99f ? glm::vec3(0.0f, 1.0f, 0.0f) : c.up;
  if (c.projection == Projection::Perspective)
    fov_ = c.yfov * 180.0f / kPi;
  else  // the orthographic view's height at the pivot
    fov_ = 2.0f * std::atan(c.ymag / distance) * 180.0f / kPi;
}

void ViewCamera::reset() {
  index_ = start_.initial_is_scene_camera ? start_.first : -1;
  base_ = index_ >= 0 ? start_.cameras[size_t(index_)] : start_.initial;
  look_from_desc(start_.initial);
}

void ViewCamera::scene_camera(int index) {
  if (index < 0 || index >= scene_camera_count()) return;
  index_ = index;
  base_ = start_.cameras[size_t(index)];
  look_from_desc(base_);
}

void ViewCamera::detach() {
  if (moved_) return;
  moved_ = true;
}

CameraDesc ViewCamera::desc() const {
  if (!moved_) return shown_;
  // As render_scene.cpp's camera options make it: the base camera, its position, direction
  // and up replaced, perspective at the field of view, focused on the pivot
  CameraDesc c = base_;
  c.position = from_;
  c.forward = glm::normalize(at_ - from_);
  c.up = up_;
  c.projection = Projection::Perspective;
  c.yfov = fov_ * 3.14159265f / 180.0f;
  if (start_.aperture) c.aperture_radius = *start_.aperture;
  c.focus_distance = start_.focus_distance ? *start_.focus_distance : glm::length(at_ - from_);
  return c;
}

std::string ViewCamera::render_args(int width, int height) const {
  std::string args;
  if (index_ >= 0) args += "--camera " + std::to_string(index_) + " ";
  if (moved_ || (index_ < 0 && start_.options_camera)) {
    args += "--look-from " + vec_text(from_) + " --look-at " + vec_text(at_) + " --up " + vec_text(up_) + " --fov " +
            number_text(fov_) + " ";
    if (start_.aperture) args += "--aperture " + number_text(*start_.aperture) + " ";
    if (start_.focus_distance) args += "--focus-distance " + number_text(*start_.focus_distance) + " ";
  }
  return args + "--width " + std::to_string(width) + " --height " + std::to_string(height);
}

namespace {

// `offset` turned by `yaw` about `up` and tilted by `pitch` towards it (kept off its poles)
glm::vec3 turned_offset(glm::vec3 offset, glm::vec3 up, float yaw, float pitch) {
  glm::vec3 u = glm::normalize(up);
  float r = glm::length(offset);
  glm::vec3 n = offset / r;
  float theta = std::acos(std::clamp(glm::dot(n, u), -1.0f, 1.0f));
  glm::vec3 h = n - glm::dot(n, u) * u;
  if (glm::length(h) < 1e-6f)
    h = std::abs(u.x) < 0.9f ? glm::cross(u, glm::vec3(1, 0, 0)) : glm::cross(u, glm::vec3(0, 1, 0));
  h = glm::normalize(h);
  glm::vec3 turned = std::cos(yaw) * h + std::sin(yaw) * glm::cross(u, h);
  theta = std::clamp(theta - pitch, 0.02f, kPi - 0.02f);
  return r * (std::cos(theta) * u + std::sin(theta) * turned);
}

}  // namespace

void ViewCamera::orbit(float yaw, float pitch) {
  detach();
  from_ = at_ + turned_offset(from_ - at_, up_, yaw, pitch);
}

void ViewCamera::look(float yaw, float pitch) {
  detach();
  at_ = from_ + turned_offset(at_ - from_, up_, yaw, -pitch);
}

void ViewCamera::fly(float forward, float right, float up) {
  detach();
  glm::vec3 f = glm::normalize(at_ - from_);
  glm::vec3 r = glm::normalize(glm::cross(f, up_));
  float step = 0.05f * std::max(start_.bounds.empty() ? 1.0f : start_.bounds.radius(), 1e-3f);
  glm::vec3 shift = step * (forward * f + right * r + up * glm::normalize(up_));
  from_ += shift;
  at_ += shift;
}

void ViewCamera::pan(float dx, float dy, int height) {
  detach();
  glm::vec3 forward = glm::normalize(at_ - from_);
  glm::vec3 right = glm::normalize(glm::cross(forward, up_));
  glm::vec3 up = glm::cross(right, forward);
  float per_pixel = 2.0f * glm::length(at_ - from_) * std::tan(0.5f * fov_ * kPi / 180.0f) / float(std::max(height, 1));
  glm::vec3 shift = (-dx * right + dy * up) * per_pixel;
  from_ += shift;
  at_ += shift;
}

void ViewCamera::dolly(float steps) {
  detach();
  glm::vec3 offset = from_ - at_;
  float r = glm::length(offset);
  float least = 1e-4f * std::max(start_.bounds.empty() ? 1.0f : start_.bounds.radius(), 1e-3f);
  float next = std::max(r * std::pow(0.85f, steps), least);
  from_ = at_ + offset * (next / r);
}

void ViewCamera::focus(glm::vec3 point) {
  if (!(glm::length(point - from_) > 1e-6f)) return;
  detach();
  at_ = point;
}

void ViewCamera::frame_all(float aspect) {
  if (start_.bounds.empty()) return;
  detach();
  glm::vec3 forward = glm::normalize(at_ - from_);
  float half = 0.5f * fov_ * kPi / 180.0f;
  float half_across = std::atan(std::tan(half) * aspect);
  float distance = start_.bounds.radius() / std::sin(std::min(half, half_across));
  at_ = start_.bounds.center();
  from_ = at_ - forward * distance;
}

}  // namespace candela
