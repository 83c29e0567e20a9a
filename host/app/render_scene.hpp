// The scene a render draws: the loaded glTF with the command line's overrides (background,
// environment map, camera, default light) and the image size it implies.
#pragma once

#include "app/render_command.hpp"
#include "scene/scene.hpp"

namespace candela {

// Throws Error for camera options that no scene makes valid (run before loading)
void check_camera_options(const RenderArgs& args);

// Loads args->scene, applies the overrides and prints the scene's warnings; fills in
// args->strategy from the scene when the command line gives none
Scene load_render_scene(RenderArgs* args);

// Image size: --width/--height, else derived from the camera's aspect ratio, else 512
void resolve_image_size(const RenderArgs& args, const Scene& scene, int* width, int* height);

}  // namespace candela
