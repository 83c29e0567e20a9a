// tinygltf compiled from its header for the fuzz build, so that its parser carries the
// same sanitizer and coverage instrumentation as candela's own code. The normal build
// links Debian's libtinygltf, built from this same header; stb_image comes from libstb.
#define TINYGLTF_IMPLEMENTATION
#include <tiny_gltf.h>
