#include "sim/world_file.h"

#include "common/options_yaml_writer.h"
#include "common/yaml_options_reader.h"

namespace cairn::sim {

Expected<WorldOptions> LoadWorldFile(const std::string& path) {
  auto doc = LoadYamlWithOverrides(path, {});
  if (!doc.ok()) return doc.status();
  WorldOptions world;
  YamlOptionsReader reader(doc->root, path);
  CAIRN_RETURN_IF_ERROR(reader.Read(world));
  return world;
}

std::string WorldFileText(const WorldOptions& world) {
  WorldOptions copy = world;
  return "# cairn simulator world (cairn sim --world FILE)\n" + OptionsYamlWriter::Write(copy);
}

}  // namespace cairn::sim
