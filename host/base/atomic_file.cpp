#include "base/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include "base/error.hpp"

namespace candela {
namespace {

namespace fs = std::filesystem;

fs::path folder_of(const std::string& path) {
  fs::path dir = fs::path(path).parent_path();
  return dir.empty() ? fs::path(".") : dir;
}

// Writes everything to fd, retrying short writes; false with errno set on failure
bool write_all(int fd, const char* data, size_t size) {
  while (size > 0) {
    ssize_t n = ::write(fd, data, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    data += n;
    size -= size_t(n);
  }
  return true;
}

}  // namespace

void check_writable_path(const std::string& path) {
  fs::path dir = folder_of(path);
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw Error("cannot write " + path + ": folder " + dir.string() + " does not exist");
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    throw Error("cannot write " + path + ": folder " + dir.string() + " is not writable");
  if (fs::is_directory(path, ec)) throw Error("cannot write " + path + ": it is a folder");
}

void write_file_atomically(const std::string& path, const void* data, size_t size) {
  static std::atomic<unsigned> counter{0};
  fs::path target(path);
  fs::path tmp = folder_of(path) / ("." + target.filename().string() + ".candela-" + std::to_string(::getpid()) + "-" +
                                    std::to_string(counter++));
  int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) throw Error("cannot write " + path + ": " + std::strerror(errno));
  bool ok = write_all(fd, static_cast<const char*>(data), size) && ::fsync(fd) == 0;
  int saved = errno;
  ok = ::close(fd) == 0 && ok;
  if (ok && ::rename(tmp.c_str(), target.c_str()) != 0) {
    ok = false;
    saved = errno;
  }
  if (!ok) {
    ::unlink(tmp.c_str());
    throw Error("cannot write " + path + ": " + std::strerror(saved ? saved : errno));
  }
  // The rename itself reaches the disk with the folder (best effort: not every filesystem
  // lets a folder be synced)
  int dir = ::open(folder_of(path).c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir >= 0) {
    ::fsync(dir);
    ::close(dir);
  }
}

}  // namespace candela
