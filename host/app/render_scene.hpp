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

// --shutter OPEN:CLOSE: frames relative to the frame's time, OPEN < CLOSE (Error otherwise)
struct Shutter {
  double open = 0.0, close = 0.0;
};
Shutter parse_shutter(const std::string& text);

// Motion blur: the moment at the middle of the shutter, which poses `scene` (lights,
// materials, the camera's fallback) around a frame at `frame_time` seconds
double shutter_middle(const RenderArgs& args, double frame_time);

// Motion blur: `scene` (posed at the shutter's middle, its camera settled) gets the
// document's poses at args.shutter_steps + 1 moments evenly across the shutter around the
// frame at args.anim_time: each mesh's positions and normals, and the camera (resolved for
// the image's aspect ratio; a file without a camera keeps `scene`'s). Throws Error when a
// pose's meshes differ from the scene's in number or vertex count.
void add_motion_poses(const RenderArgs& args, const GltfDocument& document, Scene* scene);

// Image size: --width/--height, else derived from the camera's aspect ratio, else 512
void resolve_image_size(const RenderArgs& args, const Scene& scene, int* width, int* height);

}  // namespace candela
