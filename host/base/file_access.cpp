// Regular files only, and a scene's files from its own folder (file_access.hpp).
#include "base/file_access.hpp"

#include <sys/stat.h>

#include <cctype>
#include <filesystem>
#include <fstream>

#include "base/error.hpp"

namespace candela {
namespace {

namespace fs = std::filesystem;

const char* kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

// "scheme:" at the start of a reference (RFC 3986: a letter, then letters, digits, + - .)
bool has_scheme(const std::string& ref) {
  if (ref.empty() || !std::isalpha(static_cast<unsigned char>(ref[0]))) return false;
  for (size_t i = 1; i < ref.size(); ++i) {
    char c = ref[i];
    if (c == ':') return i > 1;  // one letter: a Windows drive, handled as absolute below
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '+' && c != '-' && c != '.') return false;
  }
  return false;
}

bool drive_letter(const std::string& ref) {
  return ref.size() >= 2 && std::isalpha(static_cast<unsigned char>(ref[0])) && ref[1] == ':';
}

// Whether `inner` (absolute, normal) is `outer` or below it
bool inside(const fs::path& inner, const fs::path& outer) {
  auto i = inner.begin(), o = outer.begin();
  for (; o != outer.end(); ++o, ++i) {
    if (o->empty()) continue;  // a trailing separator
    if (i == inner.end() || *i != *o) return false;
  }
  return true;
}

}  // namespace

void check_regular_file(const std::string& path, const std::string& what) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw Error(what + " not found: " + path);
  if (!S_ISREG(st.st_mode)) throw Error(what + " " + path + " is " + kind_of(st.st_mode) + ", not a regular file");
}

namespace {

// The file into `data` (a std::string or a byte vector), resized to fit
template <typename Bytes>
void read_into(const std::string& path, const std::string& what, uint64_t max_bytes, Bytes* data) {
  check_regular_file(path, what);
  std::error_code ec;
  uintmax_t size = fs::file_size(path, ec);
  if (ec) throw Error("cannot read " + what + " " + path + ": " + ec.message());
  if (size > max_bytes) throw Error(what + " " + path + " is larger than " + std::to_string(max_bytes >> 20) + " MiB");
  data->resize(size_t(size));
  std::ifstream in(path, std::ios::binary);
  if (!in || !in.read(reinterpret_cast<char*>(data->data()), std::streamsize(size)) ||
      in.gcount() != std::streamsize(size))
    throw Error("cannot read " + what + " " + path);
}

}  // namespace

std::string read_regular_file(const std::string& path, const std::string& what, uint64_t max_bytes) {
  std::string data;
  read_into(path, what, max_bytes, &data);
  return data;
}

void read_regular_file(const std::string& path, const std::string& what, uint64_t max_bytes,
                       std::vector<unsigned char>* out) {
  read_into(path, what, max_bytes, out);
}

std::string SceneFolder::resolve(const std::string& reference, const std::string& what) const {
  if (root.empty()) throw Error(what + " '" + reference + "': a scene read from memory cannot name files");
  if (allow_outside) return (fs::path(root) / reference).string();
  const char* hint = " (--allow-outside-paths allows it)";
  if (reference.empty()) throw Error(what + " has an empty file name");
  if (has_scheme(reference))
    throw Error(what + " '" + reference + "' is a URI with a scheme; a scene names its files by relative paths" + hint);
  if (fs::path(reference).is_absolute() || drive_letter(reference) || reference[0] == '\\')
    throw Error(what + " '" + reference + "' is an absolute path; a scene names its files inside its folder" + hint);
  std::error_code ec;
  fs::path base = fs::weakly_canonical(fs::absolute(root), ec);
  if (ec) throw Error("cannot resolve the scene's folder " + root + ": " + ec.message());
  fs::path joined = fs::absolute(fs::path(root) / reference).lexically_normal();
  fs::path lexical_base = fs::absolute(root).lexically_normal();
  if (!inside(joined, lexical_base)) throw Error(what + " '" + reference + "' leaves the scene's folder" + hint);
  fs::path real = fs::weakly_canonical(joined, ec);  // symbolic links resolved
  if (ec) real = joined;
  if (!inside(real, base))
    throw Error(what + " '" + reference + "' is a link to " + real.string() + ", outside the scene's folder" + hint);
  return joined.string();
}

}  // namespace candela
