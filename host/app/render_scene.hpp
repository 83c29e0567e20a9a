// The scene a render draws: the loaded glTF with the command line's overrides (background,
// environment map, camera, default light) and the image size it implies.
#pragma once

#include "app/render_command.hpp"
#include "gltf/gltf_loader.hpp"
#include "scene/scene.hpp"

namespace candela {

// Throws Error for camera options that no scene makes valid (run before loading)
void check_camera_options(const RenderArgs& args);

// What the command line asks of reading the scene file
LoadOptions render_load_options(const RenderArgs& args);

// Loads args->scene (or poses `document` at args->anim_time), applies the overrides and
// prints the scene's warnings (not for a later frame of a sequence: args->repeat); fills in
// args->strategy from the scene when the command line gives none
Scene load_render_scene(RenderArgs* args, const GltfDocument* document = nullptr);

// Image size: --width/--height, else derived from the camera's aspect ratio, else 512
void resolve_image_size(const RenderArgs& args, const Scene& scene, int* width, int* height);

}  // namespace candela
