// glTF images: PNG and JPEG headers checked against the size limits before tinygltf's
// stb_image decodes them, WebP (EXT_texture_webp) decoded by OpenImageIO; an image that fails
// is left empty with the reason recorded.
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

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

enum class ImageFormat { Other, Png, Jpeg, Webp };

uint32_t little_endian(const unsigned char* p, int bytes) {
  uint32_t v = 0;
  for (int i = bytes - 1; i >= 0; --i) v = v << 8 | p[i];
  return v;
}

// A WebP's canvas size from its first chunk (RIFF container, then VP8, VP8L or VP8X)
bool webp_header(const unsigned char* p, size_t n, uint64_t* w, uint64_t* h) {
  if (n < 30 || std::memcmp(p, "RIFF", 4) != 0 || std::memcmp(p + 8, "WEBP", 4) != 0) return false;
  const unsigned char* d = p + 20;
  if (std::memcmp(p + 12, "VP8 ", 4) == 0 && d[3] == 0x9d && d[4] == 0x01 && d[5] == 0x2a) {
    *w = little_endian(d + 6, 2) & 0x3fff;
    *h = little_endian(d + 8, 2) & 0x3fff;
  } else if (std::memcmp(p + 12, "VP8L", 4) == 0 && d[0] == 0x2f) {
    uint32_t bits = little_endian(d + 1, 4);
    *w = (bits & 0x3fff) + 1;
    *h = ((bits >> 14) & 0x3fff) + 1;
  } else if (std::memcmp(p + 12, "VP8X", 4) == 0) {
    *w = little_endian(d + 4, 3) + uint64_t(1);
    *h = little_endian(d + 7, 3) + uint64_t(1);
  } else {
    return false;
  }
  return true;
}

// A WebP decoded by OpenImageIO from memory into 8-bit RGBA (alpha 255 without one); "" or why not
std::string decode_webp(const unsigned char* bytes, size_t size, tinygltf::Image* image) {
  OIIO::Filesystem::IOMemReader memory(const_cast<unsigned char*>(bytes), size);
  auto in = OIIO::ImageInput::create("webp");
  if (!in) return "OpenImageIO has no WebP reader";
  in->set_ioproxy(&memory);
  OIIO::ImageSpec spec;
  if (!in->open("image.webp", spec)) return in->geterror();
  int channels = spec.nchannels;
  if (spec.width <= 0 || spec.height <= 0 || channels < 1 || channels > 4) return "unexpected WebP layout";
  size_t texels = size_t(spec.width) * size_t(spec.height);
  std::vector<unsigned char> pixels(texels * size_t(channels));
  if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::UINT8, pixels.data())) return in->geterror();
  image->image.assign(4 * texels, 255);
  for (size_t i = 0; i < texels; ++i)
    for (int c = 0; c < 4; ++c) {
      if (c < channels) image->image[4 * i + size_t(c)] = pixels[i * size_t(channels) + size_t(c)];
      if (c < 3 && channels < 3) image->image[4 * i + size_t(c)] = pixels[i * size_t(channels)];  // grey
    }
  image->width = spec.width;
  image->height = spec.height;
  image->component = 4;
  image->bits = 8;
  image->pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
  return "";
}

// Format, width, height and bytes per channel from a PNG, JPEG or WebP header
ImageFormat image_header(const unsigned char* p, size_t n, uint64_t* w, uint64_t* h, int* channel_bytes) {
  if (webp_header(p, n, w, h)) {
    *channel_bytes = 1;
    return ImageFormat::Webp;
  }
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
    why = "is neither PNG nor JPEG nor WebP";
  } else if (w > kMaxImageBytes || h > kMaxImageBytes || w * h * 4 * uint64_t(channel_bytes) > kMaxImageBytes) {
    why = "is " + dims + ": too large (over 1 GiB decoded)";
  } else if (format == ImageFormat::Jpeg && w * h > kMaxJpegTexelsPerByte * uint64_t(size)) {
    why = "is a JPEG of " + dims + " in only " + std::to_string(size) + " bytes: it is truncated";
  } else if (format == ImageFormat::Webp) {
    why = decode_webp(bytes, size_t(size), image);
    if (why.empty()) return true;
    why = "could not be decoded: " + why;
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
