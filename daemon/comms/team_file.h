#pragma once
// The team file: every member of the team with its graph letter, the address its cairnd binds and
// its CURVE public key. Every robot carries the same file; a robot talks to the members listed
// and refuses everyone else.
//
//   members:
//     - {name: rover, letter: a, address: "tcp://10.0.0.11:7700", public_key: "<40 Z85 characters>"}

#include <string>
#include <vector>

#include "common/options_visitor.h"
#include "common/status.h"

namespace cairn {

struct TeamMember {
  std::string name;
  std::string letter;
  std::string address;
  std::string public_key;

  void Visit(OptionsVisitor& v) {
    v.Text("name", name);
    v.Text("letter", letter);
    v.Text("address", address);
    v.Text("public_key", public_key);
  }
  Status Validate() const;
};

struct TeamFile {
  std::string path;
  std::vector<TeamMember> members;

  // Errors name the file, the line and the key (a missing, unknown or malformed one, a duplicate
  // name, letter or address).
  static Expected<TeamFile> Load(const std::string& path);
  static Expected<TeamFile> Parse(const std::string& text, const std::string& source_name);
  const TeamMember* Find(const std::string& name) const;
  const TeamMember* FindLetter(char letter) const;
};

}  // namespace cairn
