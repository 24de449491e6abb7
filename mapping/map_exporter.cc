#include "mapping/map_exporter.h"

#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <opencv2/core.hpp>

#include "io/image_codec.h"

namespace cairn {
namespace {

// The count after `prefix` on a header line; false when it is not a number.
bool Count(const std::string& line, size_t prefix, size_t* n) {
  const char* b = line.data() + prefix;
  const char* e = line.data() + line.size();
  return std::from_chars(b, e, *n).ec == std::errc() && *n < (size_t{1} << 32);
}

std::string Extension(const std::string& path) { return std::filesystem::path(path).extension().string(); }

// One binary record: x y z (float32), rgb packed (PCL's float-typed uint32), obstacle (uint8).
struct PackedPoint {
  float x, y, z;
  uint32_t rgb;
  uint8_t obstacle;
};
constexpr size_t kRecord = 17;

std::string Records(const std::vector<CloudPoint>& points) {
  std::string out(points.size() * kRecord, '\0');
  for (size_t i = 0; i < points.size(); ++i) {
    const CloudPoint& p = points[i];
    const PackedPoint r{p.p.x(), p.p.y(), p.p.z(),
                        (static_cast<uint32_t>(p.r) << 16) | (static_cast<uint32_t>(p.g) << 8) | p.b, p.obstacle};
    char* d = out.data() + i * kRecord;
    std::memcpy(d, &r.x, 4);
    std::memcpy(d + 4, &r.y, 4);
    std::memcpy(d + 8, &r.z, 4);
    std::memcpy(d + 12, &r.rgb, 4);
    std::memcpy(d + 16, &r.obstacle, 1);
  }
  return out;
}

CloudPoint FromRecord(const char* d) {
  PackedPoint r{};
  std::memcpy(&r.x, d, 4);
  std::memcpy(&r.y, d + 4, 4);
  std::memcpy(&r.z, d + 8, 4);
  std::memcpy(&r.rgb, d + 12, 4);
  std::memcpy(&r.obstacle, d + 16, 1);
  CloudPoint p;
  p.p = Eigen::Vector3f(r.x, r.y, r.z);
  p.r = static_cast<uint8_t>(r.rgb >> 16);
  p.g = static_cast<uint8_t>(r.rgb >> 8);
  p.b = static_cast<uint8_t>(r.rgb);
  p.obstacle = r.obstacle;
  return p;
}

Status WriteAll(const std::string& path, const std::string& header, const std::string& body) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  if (!f) return IoError("cannot create " + path);
  f << header;
  f.write(body.data(), static_cast<std::streamsize>(body.size()));
  f.close();
  if (!f) return IoError("writing " + path + " failed");
  return Status::Ok();
}

}  // namespace

Status MapExporter::WritePcd(const std::vector<CloudPoint>& points, const std::string& path) {
  std::ostringstream h;
  h << "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z rgb obstacle\n"
       "SIZE 4 4 4 4 1\nTYPE F F F U U\nCOUNT 1 1 1 1 1\nWIDTH "
    << points.size() << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << points.size() << "\nDATA binary\n";
  return WriteAll(path, h.str(), Records(points));
}

Status MapExporter::WritePly(const std::vector<CloudPoint>& points, const std::string& path) {
  std::string body(points.size() * 16, '\0');
  for (size_t i = 0; i < points.size(); ++i) {
    const CloudPoint& p = points[i];
    char* d = body.data() + i * 16;
    const float xyz[3] = {p.p.x(), p.p.y(), p.p.z()};
    std::memcpy(d, xyz, 12);
    d[12] = static_cast<char>(p.r);
    d[13] = static_cast<char>(p.g);
    d[14] = static_cast<char>(p.b);
    d[15] = static_cast<char>(p.obstacle);
  }
  std::ostringstream h;
  h << "ply\nformat binary_little_endian 1.0\ncomment cairn map\nelement vertex " << points.size()
    << "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\n"
       "property uchar blue\nproperty uchar obstacle\nend_header\n";
  return WriteAll(path, h.str(), body);
}

Status MapExporter::WriteCloud(const std::vector<CloudPoint>& points, const std::string& path) {
  const std::string ext = Extension(path);
  if (ext == ".pcd") return WritePcd(points, path);
  if (ext == ".ply") return WritePly(points, path);
  return InvalidArgumentError("cloud export: unknown extension '" + ext + "' of " + path + " (.pcd or .ply)");
}

Status MapExporter::WriteOctree(const octomap::OcTree& tree, const std::string& path) {
  const std::string ext = Extension(path);
  bool ok = false;
  if (ext == ".bt") {
    octomap::OcTree copy(tree);
    ok = copy.writeBinary(path);
  } else if (ext == ".ot") {
    ok = tree.write(path);
  } else {
    return InvalidArgumentError("octree export: unknown extension '" + ext + "' of " + path + " (.bt or .ot)");
  }
  return ok ? Status::Ok() : IoError("writing " + path + " failed");
}

Status MapExporter::WriteGridMap(const GridMap& g, const std::string& png_path) {
  if (Extension(png_path) != ".png") return InvalidArgumentError("grid export needs a .png path, got " + png_path);
  if (g.width <= 0 || g.height <= 0 || g.values.size() != static_cast<size_t>(g.width) * static_cast<size_t>(g.height)) {
    return InvalidArgumentError("grid export: empty or inconsistent grid");
  }
  cv::Mat img(g.height, g.width, CV_8UC1);
  for (int y = 0; y < g.height; ++y) {
    for (int x = 0; x < g.width; ++x) {
      const float v = g.at(x, y);
      img.at<uint8_t>(g.height - 1 - y, x) = std::isnan(v) ? 205 : (v > 1.0f ? 0 : 254);
    }
  }
  CAIRN_RETURN_IF_ERROR(ImageCodec::Write(png_path, img));
  const std::filesystem::path p(png_path);
  std::ostringstream y;
  y.precision(9);
  y << "image: " << p.filename().string() << "\nmode: trinary\nresolution: " << g.resolution << "\norigin: ["
    << g.origin_x << ", " << g.origin_y << ", 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n";
  std::filesystem::path yaml = p;
  yaml.replace_extension(".yaml");
  return WriteAll(yaml.string(), y.str(), "");
}

Expected<std::vector<CloudPoint>> MapExporter::ReadCloud(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return NotFoundError("cannot open " + path);
  const std::string ext = Extension(path);
  std::string line;
  size_t n = 0;
  bool ply = false;
  if (ext == ".pcd") {
    while (std::getline(f, line)) {
      if (line.rfind("POINTS ", 0) == 0 && !Count(line, 7, &n)) return DataLossError(path + ": bad POINTS line");
      if (line.rfind("FIELDS", 0) == 0 && line != "FIELDS x y z rgb obstacle") {
        return DataLossError(path + ": only clouds written by cairn (x y z rgb obstacle) are read");
      }
      if (line == "DATA binary") break;
      if (line.rfind("DATA", 0) == 0) return DataLossError(path + ": only binary PCD is read");
    }
  } else if (ext == ".ply") {
    ply = true;
    while (std::getline(f, line)) {
      if (line.rfind("element vertex ", 0) == 0 && !Count(line, 15, &n)) return DataLossError(path + ": bad vertex count");
      if (line == "end_header") break;
    }
  } else {
    return InvalidArgumentError("unknown cloud extension of " + path);
  }
  if (!f) return DataLossError(path + ": header ends early");
  const size_t rec = ply ? 16 : kRecord;
  std::string body(n * rec, '\0');
  f.read(body.data(), static_cast<std::streamsize>(body.size()));
  if (static_cast<size_t>(f.gcount()) != body.size()) return DataLossError(path + ": fewer points than the header says");
  std::vector<CloudPoint> out(n);
  for (size_t i = 0; i < n; ++i) {
    const char* d = body.data() + i * rec;
    if (ply) {
      float xyz[3];
      std::memcpy(xyz, d, 12);
      out[i].p = Eigen::Vector3f(xyz[0], xyz[1], xyz[2]);
      out[i].r = static_cast<uint8_t>(d[12]);
      out[i].g = static_cast<uint8_t>(d[13]);
      out[i].b = static_cast<uint8_t>(d[14]);
      out[i].obstacle = static_cast<uint8_t>(d[15]);
    } else {
      out[i] = FromRecord(d);
    }
  }
  return out;
}

}  // namespace cairn
