// Reading the files a user or a scene names: only regular files (a FIFO, a device or a
// folder could block for ever, never end or make no sense), and a scene's own files only
// from inside its folder unless the user allows more.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace candela {

// Throws Error "WHAT not found: PATH" or "WHAT PATH is a FIFO/device/folder..., not a
// regular file" unless path names a regular file (symbolic links followed)
void check_regular_file(const std::string& path, const std::string& what);

// The whole of a regular file, at most max_bytes; Error naming `what` and path otherwise
std::string read_regular_file(const std::string& path, const std::string& what, uint64_t max_bytes);
// The same into *out (a glTF buffer, read in place rather than copied from a string)
void read_regular_file(const std::string& path, const std::string& what, uint64_t max_bytes,
                       std::vector<unsigned char>* out);

// Where the files a scene names (buffers, images, environment maps, grids) may come from
struct SceneFolder {
  std::string root;            // the scene file's folder; empty: the scene came from memory
  bool allow_outside = false;  // --allow-outside-paths: any relative or absolute path

  // The path of a file the scene names by `reference` (a relative path, already
  // percent-decoded). Unless allow_outside, an absolute path, a URI with a scheme (file:,
  // http:) and a path that leaves root (by "..", or by a symbolic link once resolved)
  // throw Error naming `what`. The file itself is not checked.
  std::string resolve(const std::string& reference, const std::string& what) const;
};

}  // namespace candela
