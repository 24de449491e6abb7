#include "tools/submap_truth.h"

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "mapping/submap_codec.h"
#include "tools/commands.h"

namespace cairn::tools {

Status ReadSubmapTruth(const std::string& dir, std::vector<SubmapTruth>* out) {
  const std::string index = dir + "/submaps/index.csv";
  std::ifstream in(index);
  if (!in) return NotFoundError(index + ": cannot open (a cairnd output folder with mapping on?)");
  std::string line;
  std::getline(in, line);
  int row = 1;
  while (std::getline(in, line)) {
    ++row;
    std::vector<std::string> f;
    std::stringstream fields(line);
    std::string item;
    while (std::getline(fields, item, ',')) f.push_back(item);
    if (f.size() < 7 || f[3].empty()) continue;  // no truth for this origin
    std::vector<double> v;
    if (!ParseNumberList(f[3] + "," + f[4] + "," + f[5] + "," + f[6], &v) || v.size() != 4)
      return InvalidArgumentError(index + ":" + std::to_string(row) + ": bad true pose");
    SubmapTruth s;
    s.robot = f[0];
    s.id = std::strtoull(f[1].c_str(), nullptr, 10);
    s.T_world_submap = FourDofTransform(v[0], v[1], v[2], v[3]);
    out->push_back(std::move(s));
  }
  return Status::Ok();
}

Status ReadSubmapsWithTruth(const std::string& dir, std::vector<SubmapWithTruth>* out) {
  std::vector<SubmapTruth> truth;
  if (Status s = ReadSubmapTruth(dir, &truth); !s.ok()) return s;
  for (const SubmapTruth& t : truth) {
    char name[32];
    std::snprintf(name, sizeof(name), "-%06llu.submap", static_cast<unsigned long long>(t.id));
    auto submap = SubmapCodec::ReadFile(dir + "/submaps/" + t.robot + name);
    if (!submap.ok() && submap.status().code() == StatusCode::kNotFound) continue;
    if (!submap.ok()) return submap.status();
    SubmapWithTruth s;
    static_cast<SubmapTruth&>(s) = t;
    s.submap = *submap;
    out->push_back(std::move(s));
  }
  return Status::Ok();
}

}  // namespace cairn::tools
