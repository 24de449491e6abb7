#include "daemon/cairnd_config.h"

#include "common/yaml_options_reader.h"

namespace cairn {

namespace {

Expected<CairndOptions> Load(const std::string& path, const std::vector<std::string>& overrides,
                             std::vector<std::string>* earlier_version_notes) {
  auto doc = LoadYamlWithOverrides(path, overrides);
  if (!doc.ok()) return doc.status();
  CairndOptions options;
  YamlOptionsReader reader(doc->root, path, doc->overridden_keys);
  if (earlier_version_notes != nullptr) reader.AcceptEarlierVersions();
  CAIRN_RETURN_IF_ERROR(reader.Read(options));
  if (earlier_version_notes != nullptr) *earlier_version_notes = reader.notes();
  if (options.mapping.enabled && !(options.stereo.enabled && options.vo.enabled)) {
    return InvalidArgumentError(path + ": mapping.enabled needs stereo.enabled (dense depth) and vo.enabled "
                                       "(the filter's poses)");
  }
  if (options.graph.enabled && !options.vo.enabled) {
    return InvalidArgumentError(path + ": graph.enabled needs vo.enabled (the filter's estimates and frame switches)");
  }
  if (options.graph.optimizer.own_robot < 'a' || options.graph.optimizer.own_robot > 'z') {
    return InvalidArgumentError(path + ": graph.optimizer.own_robot must be one lower-case letter (the robot's "
                                       "letter in graph keys)");
  }
  return options;
}

}  // namespace

Expected<CairndOptions> LoadCairndOptions(const std::string& path,
                                          const std::vector<std::string>& overrides) {
  return Load(path, overrides, nullptr);
}

Expected<CairndOptions> LoadEarlierRunOptions(const std::string& path, std::vector<std::string>* notes) {
  return Load(path, {}, notes);
}

}  // namespace cairn
