// The camera compiled for the device: the scene's resolved camera as a dev::Camera record
// for one image size.
#pragma once

#include "base/device_types.hpp"
#include "scene/scene.hpp"

namespace candela {

// Device record for an image of width x height. The vertical extent (yfov or ymag) is
// kept and the horizontal one follows from width / height.
dev::Camera make_device_camera(const CameraDesc& cam, int width, int height);

// The camera a render of `scene` uses (resolve_camera) as a device record for a width x
// height image; throws Error as resolve_camera does
dev::Camera compile_camera(const Scene& scene, int width, int height);

}  // namespace candela
