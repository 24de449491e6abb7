#include "stereo/pfm_io.h"

#include <bit>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>

namespace cairn {
namespace {

float SwapFloat(float v) {
  uint32_t u;
  std::memcpy(&u, &v, 4);
  u = (u >> 24) | ((u >> 8) & 0xFF00u) | ((u << 8) & 0xFF0000u) | (u << 24);
  std::memcpy(&v, &u, 4);
  return v;
}

}  // namespace

Status WritePfm(const std::string& path, const FloatImage& image) {
  if (image.width < 1 || image.height < 1 ||
      image.data.size() != static_cast<size_t>(image.width) * image.height) {
    return InvalidArgumentError("WritePfm " + path + ": image size does not match its data");
  }
  std::ofstream f(path, std::ios::binary);
  if (!f) return IoError("cannot open " + path + " for writing");
  f << "Pf\n" << image.width << ' ' << image.height << "\n-1.0\n";
  std::vector<float> row(static_cast<size_t>(image.width));
  for (int y = image.height - 1; y >= 0; --y) {
    for (int x = 0; x < image.width; ++x) {
      const float v = image.at(x, y);
      row[x] = std::endian::native == std::endian::little ? v : SwapFloat(v);
    }
    f.write(reinterpret_cast<const char*>(row.data()), static_cast<std::streamsize>(row.size() * 4));
  }
  if (!f) return IoError("write to " + path + " failed");
  return Status::Ok();
}

Expected<FloatImage> ReadPfm(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return NotFoundError("cannot open PFM file " + path);
  std::string magic;
  FloatImage img;
  double scale = 0.0;
  f >> magic >> img.width >> img.height >> scale;
  if (!f || magic != "Pf") {
    return DataLossError(path + ": not a one-channel PFM file (expected header 'Pf W H scale')");
  }
  if (img.width < 1 || img.height < 1 || img.width > 65536 || img.height > 65536 || scale == 0.0) {
    return DataLossError(path + ": bad PFM size or scale");
  }
  f.get();  // the single whitespace byte after the scale
  const bool little = scale < 0.0;
  const size_t n = static_cast<size_t>(img.width) * img.height;
  std::vector<float> raw(n);
  f.read(reinterpret_cast<char*>(raw.data()), static_cast<std::streamsize>(n * 4));
  if (static_cast<size_t>(f.gcount()) != n * 4) {
    return DataLossError(path + ": truncated PFM data (" + std::to_string(f.gcount()) + " of " +
                         std::to_string(n * 4) + " bytes)");
  }
  const bool swap = little != (std::endian::native == std::endian::little);
  img.data.resize(n);
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x) {
      const float v = raw[static_cast<size_t>(img.height - 1 - y) * img.width + x];
      img.data[static_cast<size_t>(y) * img.width + x] = swap ? SwapFloat(v) : v;
    }
  }
  return img;
}

}  // namespace cairn
