// The camera compiled for the device (camera.hpp).
#include "compile/camera.hpp"

#include <cmath>

namespace candela {

dev::Camera make_device_camera(const CameraDesc& cam, int width, int height) {
  glm::vec3 f = glm::normalize(cam.forward);
  glm::vec3 r = glm::cross(f, cam.up);
  if (!(glm::length(r) > 1e-6f)) {
    // Up is parallel to the view: use the world axis least aligned with it
    glm::vec3 a = glm::abs(f);
    glm::vec3 axis = a.x <= a.y && a.x <= a.z ? glm::vec3(1, 0, 0)
                     : a.y <= a.z             ? glm::vec3(0, 1, 0)
                                              : glm::vec3(0, 0, 1);
    r = glm::cross(f, axis);
  }
  r = glm::normalize(r);
  glm::vec3 u = glm::cross(r, f);
  // Half-extents of the image at depth 1 (perspective) or in scene units (orthographic)
  bool ortho = cam.projection == Projection::Orthographic;
  float half_y = ortho ? cam.ymag : std::tan(0.5f * cam.yfov);
  float half_x = half_y * float(width) / float(height);
  dev::Camera c{};
  c.type = ortho ? CAMERA_ORTHOGRAPHIC : CAMERA_PERSPECTIVE;
  c.lens_radius = ortho ? 0.0f : cam.aperture_radius;
  c.focus_distance = cam.focus_distance.value_or(1.0f);
  for (int i = 0; i < 3; ++i) {
    c.origin[i] = cam.position[i];
    c.forward[i] = f[i];
    c.right[i] = r[i] * half_x;
    c.up[i] = u[i] * half_y;
  }
  return c;
}

dev::Camera compile_camera(const Scene& scene, int width, int height) {
  return make_device_camera(resolve_camera(scene, float(width) / float(height)), width, height);
}

}  // namespace candela
