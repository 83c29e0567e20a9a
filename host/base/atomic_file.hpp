// Outputs that are either written whole or not at all: the bytes go to a temporary file in
// the target's folder, are checked and flushed to disk, and the file is renamed over the
// target.
#pragma once

#include <cstddef>
#include <string>

namespace candela {

// Writes `size` bytes to path atomically. On any failure (no space, no permission, a
// folder in the way) the temporary file is removed, an existing file at path is left as it
// was, and Error names path and the reason in one line.
void write_file_atomically(const std::string& path, const void* data, size_t size);
inline void write_file_atomically(const std::string& path, const std::string& text) {
  write_file_atomically(path, text.data(), text.size());
}

// Throws Error unless path's folder exists, is a folder and can be written, and path itself
// is not a folder
void check_writable_path(const std::string& path);

}  // namespace candela
