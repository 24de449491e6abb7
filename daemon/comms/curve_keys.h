#pragma once
// CURVE key pairs of the team's robots (Z85 text, 40 characters each). A robot's secret key lives
// in `<name>.key`, readable by its owner only; its public key in `<name>.pub`, which goes into the
// team file of every robot. Both are one `field value` pair per line; lines starting with `#` are comments.

#include <string>

#include "common/status.h"

namespace cairn {

struct CurveKeyPair {
  std::string public_key;  // Z85
  std::string secret_key;  // Z85
};

class CurveKeys {
 public:
  static Expected<CurveKeyPair> Generate();
  // Writes <dir>/<name>.key (mode 0600 from its creation) and <dir>/<name>.pub (0644), synced.
  // An existing key is never replaced unless `overwrite`: a robot's identity is its key.
  static Status Write(const std::string& dir, const std::string& name, const CurveKeyPair& keys, bool overwrite);
  // A `.key` file: both keys, valid, matching each other, and not readable by group or others.
  static Expected<CurveKeyPair> LoadSecret(const std::string& path);
  // A `.pub` file.
  static Expected<std::string> LoadPublic(const std::string& path);
  static bool IsValidKey(const std::string& z85);
  // The 32 bytes a Z85 key stands for (empty when it is not a valid key).
  static std::string Decode(const std::string& z85);
};

}  // namespace cairn
