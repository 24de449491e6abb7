#include "daemon/comms/curve_keys.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include <zmq.h>

namespace cairn {
namespace {

constexpr size_t kZ85KeyLength = 40;

// The `field value` lines of a key file; errors name the file and line.
Expected<std::map<std::string, std::string>> ReadFields(const std::string& path) {
  std::ifstream in(path);
  if (!in) return NotFoundError(path + ": cannot open (" + std::strerror(errno) + ")");
  std::map<std::string, std::string> fields;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    std::istringstream words(line);
    std::string field, value, extra;
    // Only whole-line comments: '#' is a Z85 digit.
    if (!(words >> field) || field[0] == '#') continue;
    const std::string where = path + ":" + std::to_string(number);
    if (!(words >> value) || (words >> extra)) {
      return InvalidArgumentError(where + ": expected `" + field + " <key>` (one Z85 key of 40 characters)");
    }
    if (field != "public-key" && field != "secret-key") {
      return InvalidArgumentError(where + ": unknown field '" + field + "' (public-key, secret-key)");
    }
    if (fields.count(field) != 0) return InvalidArgumentError(where + ": '" + field + "' given twice");
    if (!CurveKeys::IsValidKey(value)) {
      return InvalidArgumentError(where + ": '" + field + "' is not a Z85 CURVE key of 40 characters");
    }
    fields[field] = value;
  }
  return fields;
}

Status WriteSynced(const std::string& path, const std::string& text, mode_t mode, bool overwrite) {
  // O_EXCL unless replacing: a second `generate` must not silently change a robot's identity.
  const int flags = O_WRONLY | O_CREAT | O_CLOEXEC | (overwrite ? O_TRUNC : O_EXCL);
  const int fd = ::open(path.c_str(), flags, mode);
  if (fd < 0) {
    if (errno == EEXIST) return AlreadyExistsError(path + ": exists already (--force replaces it)");
    return IoError(path + ": cannot create (" + std::strerror(errno) + ")");
  }
  // A replaced file keeps its old mode otherwise.
  Status status = Status::Ok();
  if (::fchmod(fd, mode) != 0) status = IoError(path + ": chmod: " + std::strerror(errno));
  size_t done = 0;
  while (status.ok() && done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      status = IoError(path + ": write: " + std::strerror(errno));
      break;
    }
    done += static_cast<size_t>(n);
  }
  if (status.ok() && ::fsync(fd) != 0) status = IoError(path + ": fsync: " + std::strerror(errno));
  ::close(fd);
  return status;
}

}  // namespace

bool CurveKeys::IsValidKey(const std::string& z85) { return !Decode(z85).empty(); }

std::string CurveKeys::Decode(const std::string& z85) {
  if (z85.size() != kZ85KeyLength) return "";
  uint8_t bytes[32];
  if (zmq_z85_decode(bytes, z85.c_str()) == nullptr) return "";
  // zmq_z85_decode accepts values past 2^32 in a group; encoding back catches them.
  char again[kZ85KeyLength + 1];
  if (zmq_z85_encode(again, bytes, sizeof(bytes)) == nullptr || z85 != again) return "";
  return std::string(reinterpret_cast<const char*>(bytes), sizeof(bytes));
}

Expected<CurveKeyPair> CurveKeys::Generate() {
  char public_key[kZ85KeyLength + 1];
  char secret_key[kZ85KeyLength + 1];
  if (zmq_curve_keypair(public_key, secret_key) != 0) {
    return UnavailableError(std::string("zmq_curve_keypair: ") + zmq_strerror(zmq_errno()) +
                            " (libzmq without CURVE support?)");
  }
  return CurveKeyPair{public_key, secret_key};
}

Status CurveKeys::Write(const std::string& dir, const std::string& name, const CurveKeyPair& keys, bool overwrite) {
  if (!IsValidKey(keys.public_key) || !IsValidKey(keys.secret_key)) {
    return InvalidArgumentError("the key pair of '" + name + "' is not valid Z85");
  }
  const std::string secret = "# cairn CURVE key pair of robot '" + name +
                             "': keep it on this robot only (team.secret_key_file)\npublic-key " + keys.public_key +
                             "\nsecret-key " + keys.secret_key + "\n";
  const std::string pub = "# cairn CURVE public key of robot '" + name + "': its public_key in the team file\n" +
                          "public-key " + keys.public_key + "\n";
  if (Status s = WriteSynced(dir + "/" + name + ".key", secret, 0600, overwrite); !s.ok()) return s;
  return WriteSynced(dir + "/" + name + ".pub", pub, 0644, true);
}

Expected<CurveKeyPair> CurveKeys::LoadSecret(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return NotFoundError(path + ": " + std::strerror(errno));
  if ((st.st_mode & 077) != 0) {
    char mode[8];
    std::snprintf(mode, sizeof(mode), "%04o", static_cast<unsigned>(st.st_mode & 07777));
    return FailedPreconditionError(path + ": the secret key is readable by others (mode " + mode +
                                   "); chmod 600 it");
  }
  auto fields = ReadFields(path);
  if (!fields.ok()) return fields.status();
  for (const char* field : {"public-key", "secret-key"}) {
    if (fields->count(field) == 0) return InvalidArgumentError(path + ": no '" + field + "' line");
  }
  CurveKeyPair keys{fields->at("public-key"), fields->at("secret-key")};
  char derived[kZ85KeyLength + 1];
  if (zmq_curve_public(derived, keys.secret_key.c_str()) != 0 || keys.public_key != derived) {
    return InvalidArgumentError(path + ": its public-key is not the one of its secret-key");
  }
  return keys;
}

Expected<std::string> CurveKeys::LoadPublic(const std::string& path) {
  auto fields = ReadFields(path);
  if (!fields.ok()) return fields.status();
  if (fields->count("secret-key") != 0) {
    return InvalidArgumentError(path + ": holds a secret key; a .pub file must not");
  }
  if (fields->count("public-key") == 0) return InvalidArgumentError(path + ": no 'public-key' line");
  return fields->at("public-key");
}

}  // namespace cairn
