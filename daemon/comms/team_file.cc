#include "daemon/comms/team_file.h"

#include <cctype>
#include <set>

#include <yaml-cpp/yaml.h>

#include "common/yaml_options_reader.h"

namespace cairn {
namespace {

std::string Where(const std::string& source, const YAML::Node& node) {
  const YAML::Mark mark = node.Mark();
  if (mark.line < 0) return source;
  return source + ":" + std::to_string(mark.line + 1);
}

}  // namespace

Status TeamMember::Validate() const {
  if (name.empty() || name.size() > 32) return InvalidArgumentError("name must hold 1 to 32 characters");
  for (char c : name) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_'))
      return InvalidArgumentError("name '" + name + "' may only hold letters, digits, '-' and '_'");
  }
  if (letter.size() != 1 || letter[0] < 'a' || letter[0] > 'z')
    return InvalidArgumentError("letter '" + letter + "' must be one lower-case letter (the robot's graph keys)");
  if (address.rfind("tcp://", 0) != 0 || address.find(':', 6) == std::string::npos)
    return InvalidArgumentError("address '" + address + "' must read tcp://HOST:PORT");
  if (public_key.size() != 40)
    return InvalidArgumentError("public_key must be 40 Z85 characters (cairn keys generate prints it), not " +
                                std::to_string(public_key.size()));
  return Status::Ok();
}

Expected<TeamFile> TeamFile::Load(const std::string& path) {
  auto text = ReadListFile(path, "team file");
  if (!text.ok()) return text.status();
  return Parse(*text, path);
}

Expected<TeamFile> TeamFile::Parse(const std::string& text, const std::string& source) {
  auto list = ParseListDocument(text, source, "members");
  if (!list.ok()) return list.status();
  const YAML::Node members = *list;
  TeamFile file;
  file.path = source;
  std::set<std::string> names, letters, addresses;
  std::vector<std::string> errors;
  for (size_t i = 0; i < members.size(); ++i) {
    const YAML::Node m = members[i];
    const std::string where = source + " members[" + std::to_string(i) + "]";
    if (!m.IsMap()) {
      errors.push_back(Where(source, m) + ": members[" + std::to_string(i) + "] must be a mapping");
      continue;
    }
    TeamMember member;
    YamlOptionsReader reader(m, where);
    if (Status s = reader.Read(member); !s.ok()) {
      errors.push_back(s.message());
      continue;
    }
    if (!names.insert(member.name).second) errors.push_back(Where(source, m) + ": name '" + member.name + "' twice");
    if (!letters.insert(member.letter).second)
      errors.push_back(Where(source, m) + ": letter '" + member.letter + "' twice");
    if (!addresses.insert(member.address).second)
      errors.push_back(Where(source, m) + ": address '" + member.address + "' twice");
    file.members.push_back(std::move(member));
  }
  if (!errors.empty()) {
    std::string all;
    for (const std::string& e : errors) all += (all.empty() ? "" : "\n") + e;
    return InvalidArgumentError(all);
  }
  return file;
}

const TeamMember* TeamFile::Find(const std::string& name) const {
  for (const TeamMember& m : members) {
    if (m.name == name) return &m;
  }
  return nullptr;
}

const TeamMember* TeamFile::FindLetter(char letter) const {
  for (const TeamMember& m : members) {
    if (m.letter.size() == 1 && m.letter[0] == letter) return &m;
  }
  return nullptr;
}

}  // namespace cairn
