// glTF images: PNG and JPEG headers checked against the size limits before tinygltf's
// stb_image decodes them; an image that fails is left empty with the reason recorded.
#include <cstring>
#include <map>

#include "gltf/limits.hpp"
#include "gltf/reader.hpp"

namespace candela::gltf {
namespace {

uint32_t big_endian(const unsigned char* p, int bytes) {
  uint32_t v = 0;
  for (int i = 0; i < bytes; ++i) v = v << 8 | p[i];
  return v;
}

enum class ImageFormat { Other, Png, Jpeg };

// Format, width, height and bytes per channel from a PNG or JPEG header
ImageFormat image_header(const unsigned char* p, size_t n, uint64_t* w, uint64_t* h, int* channel_bytes) {
  static const unsigned char kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (n >= 26 && std::memcmp(p, kPng, 8) == 0 && std::memcmp(p + 12, "IHDR", 4) == 0) {
    *w = big_endian(p + 16, 4);
    *h = big_endian(p + 20, 4);
    *channel_bytes = p[24] == 16 ? 2 : 1;
    return ImageFormat::Png;
  }
  if (n < 4 || p[0] != 0xFF || p[1] != 0xD8) return ImageFormat::Other;
  // JPEG: marker segments up to the frame header (SOF0-SOF15 but DHT, JPG and DAC)
  for (size_t i = 2; i + 4 <= n;) {
    unsigned char m = p[i + 1];
    if (p[i] != 0xFF) return ImageFormat::Other;
    if (m == 0xFF) {
      ++i;  // fill byte
    } else if (m == 0x01 || (m >= 0xD0 && m <= 0xD7)) {
      i += 2;  // no length
    } else if (m >= 0xC0 && m <= 0xCF && m != 0xC4 && m != 0xC8 && m != 0xCC) {
      if (i + 9 > n) return ImageFormat::Other;
      *h = big_endian(p + i + 5, 2);
      *w = big_endian(p + i + 7, 2);
      *channel_bytes = 1;
      return ImageFormat::Jpeg;
    } else if (m == 0xDA || m == 0xD9) {
      return ImageFormat::Other;  // a scan or the end before any frame
    } else {
      i += 2 + big_endian(p + i + 2, 2);
    }
  }
  return ImageFormat::Other;
}

}  // namespace

// tinygltf's image decoding (to RGBA) behind those checks. An image that fails them or
// does not decode is left empty, never an error: `errors` (std::map<int, std::string>,
// the user data) records why, and a texture using it falls back or is dropped.
bool load_checked_image(tinygltf::Image* image, const int index, std::string*, std::string* warn, int req_width,
                        int req_height, const unsigned char* bytes, int size, void* errors) {
  std::string why;
  uint64_t w = 0, h = 0;
  int channel_bytes = 1;
  ImageFormat format = size > 0 ? image_header(bytes, size_t(size), &w, &h, &channel_bytes) : ImageFormat::Other;
  std::string dims = std::to_string(w) + " x " + std::to_string(h);
  if (format == ImageFormat::Other) {
    why = "is neither PNG nor JPEG";
  } else if (w > kMaxImageBytes || h > kMaxImageBytes || w * h * 4 * uint64_t(channel_bytes) > kMaxImageBytes) {
    why = "is " + dims + ": too large (over 1 GiB decoded)";
  } else if (format == ImageFormat::Jpeg && w * h > kMaxJpegTexelsPerByte * uint64_t(size)) {
    why = "is a JPEG of " + dims + " in only " + std::to_string(size) + " bytes: it is truncated";
  } else {
    std::string decode_err;
    if (tinygltf::LoadImageData(image, index, &decode_err, warn, req_width, req_height, bytes, size, nullptr))
      return true;
    while (!decode_err.empty() && (decode_err.back() == '\n' || decode_err.back() == ' ')) decode_err.pop_back();
    why = "could not be decoded: " + decode_err;
  }
  (*static_cast<std::map<int, std::string>*>(errors))[index] = why;
  image->image.clear();
  image->width = image->height = 0;
  return true;
}

}  // namespace candela::gltf
