#include "common/yaml_options_reader.h"

#include <cmath>
#include <fstream>
#include <sstream>

namespace cairn {
namespace {

std::string Range(double min, double max, std::string_view unit) {
  std::ostringstream s;
  s << "[" << min << ", " << max << "]";
  if (!unit.empty()) s << " " << unit;
  return s.str();
}

std::string Describe(const YAML::Node& node) {
  if (node.IsScalar()) return "'" + node.Scalar() + "'";
  if (node.IsSequence()) return "a list";
  if (node.IsMap()) return "a mapping";
  return "nothing";
}

}  // namespace

YamlOptionsReader::YamlOptionsReader(YAML::Node root, std::string source_name,
                                     std::set<std::string> overridden_keys)
    : source_(std::move(source_name)), overridden_(std::move(overridden_keys)) {
  if (!root.IsMap()) {
    errors_.push_back(source_ + ": the document is not a mapping of keys");
    root = YAML::Node(YAML::NodeType::Map);
  }
  stack_.push_back(Frame{root, "", {}});
}

std::string YamlOptionsReader::FullKey(std::string_view key) const {
  const std::string& parent = stack_.back().path;
  return parent.empty() ? std::string(key) : parent + "." + std::string(key);
}

std::string YamlOptionsReader::Where(const YAML::Node& node, const std::string& full_key) const {
  if (overridden_.count(full_key) != 0) return "--set " + full_key;
  const YAML::Mark mark = node.Mark();
  if (mark.line < 0) return source_;
  return source_ + ":" + std::to_string(mark.line + 1) + ":" + std::to_string(mark.column + 1);
}

void YamlOptionsReader::Error(const YAML::Node& node, std::string_view key, const std::string& what) {
  const std::string full = FullKey(key);
  errors_.push_back(Where(node, full) + ": key '" + full + "' " + what);
}

YAML::Node YamlOptionsReader::Lookup(std::string_view key) {
  Frame& frame = stack_.back();
  frame.consumed.insert(std::string(key));
  const YAML::Node& map = frame.node;  // const lookup: never inserts the key
  YAML::Node child = map[std::string(key)];
  if (!child.IsDefined() || child.IsNull()) {
    const std::string full = FullKey(key);
    (earlier_versions_ ? notes_ : errors_).push_back(Where(frame.node, frame.path) + ": missing key '" + full + "'");
    return YAML::Node(YAML::NodeType::Undefined);
  }
  return child;
}

void YamlOptionsReader::Number(std::string_view key, double& value, double min, double max,
                               std::string_view unit) {
  YAML::Node n = Lookup(key);
  if (!n.IsDefined()) return;
  double v = 0.0;
  if (!n.IsScalar() || !YAML::convert<double>::decode(n, v) || !std::isfinite(v)) {
    Error(n, key, "must be a finite number, not " + Describe(n));
    return;
  }
  if (v < min || v > max) {
    Error(n, key, "= " + n.Scalar() + " is outside " + Range(min, max, unit));
    return;
  }
  value = v;
}

void YamlOptionsReader::IntegerImpl(std::string_view key, int64_t& value, int64_t min, int64_t max,
                                    std::string_view unit) {
  YAML::Node n = Lookup(key);
  if (!n.IsDefined()) return;
  int64_t v = 0;
  if (!n.IsScalar() || !YAML::convert<int64_t>::decode(n, v)) {
    Error(n, key, "must be an integer, not " + Describe(n));
    return;
  }
  if (v < min || v > max) {
    Error(n, key, "= " + n.Scalar() + " is outside " +
                      Range(static_cast<double>(min), static_cast<double>(max), unit));
    return;
  }
  value = v;
}

void YamlOptionsReader::Flag(std::string_view key, bool& value) {
  YAML::Node n = Lookup(key);
  if (!n.IsDefined()) return;
  bool v = false;
  if (!n.IsScalar() || !YAML::convert<bool>::decode(n, v)) {
    Error(n, key, "must be true or false, not " + Describe(n));
    return;
  }
  value = v;
}

void YamlOptionsReader::Text(std::string_view key, std::string& value) {
  YAML::Node n = Lookup(key);
  if (!n.IsDefined()) return;
  if (!n.IsScalar()) {
    Error(n, key, "must be a string, not " + Describe(n));
    return;
  }
  value = n.Scalar();
}

void YamlOptionsReader::Numbers(std::string_view key, std::vector<double>& values,
                                size_t min_count, size_t max_count, double min, double max,
                                std::string_view unit) {
  YAML::Node n = Lookup(key);
  if (!n.IsDefined()) return;
  if (!n.IsSequence()) {
    Error(n, key, "must be a list of numbers, not " + Describe(n));
    return;
  }
  if (n.size() < min_count || n.size() > max_count) {
    const std::string expected = min_count == max_count
                                     ? std::to_string(min_count)
                                     : std::to_string(min_count) + " to " + std::to_string(max_count);
    Error(n, key, "has " + std::to_string(n.size()) + " values, expected " + expected);
    return;
  }
  std::vector<double> out;
  out.reserve(n.size());
  for (size_t i = 0; i < n.size(); ++i) {
    double v = 0.0;
    const YAML::Node item = n[i];
    if (!item.IsScalar() || !YAML::convert<double>::decode(item, v) || !std::isfinite(v)) {
      Error(item, key, "item " + std::to_string(i) + " must be a finite number, not " + Describe(item));
      return;
    }
    if (v < min || v > max) {
      Error(item, key, "item " + std::to_string(i) + " = " + item.Scalar() + " is outside " +
                           Range(min, max, unit));
      return;
    }
    out.push_back(v);
  }
  values = std::move(out);
}

void YamlOptionsReader::ChoiceImpl(std::string_view key, int& index,
                                   std::span<const std::string_view> names) {
  YAML::Node n = Lookup(key);
  if (!n.IsDefined()) return;
  if (n.IsScalar()) {
    for (size_t i = 0; i < names.size(); ++i) {
      if (n.Scalar() == names[i]) {
        index = static_cast<int>(i);
        return;
      }
    }
  }
  std::string allowed;
  for (const auto& name : names) allowed += (allowed.empty() ? "" : ", ") + std::string(name);
  Error(n, key, "= " + Describe(n) + " is not one of: " + allowed);
}

bool YamlOptionsReader::BeginSection(std::string_view key) {
  YAML::Node n = Lookup(key);
  if (!n.IsDefined()) return false;
  if (!n.IsMap()) {
    Error(n, key, "must be a mapping of keys, not " + Describe(n));
    return false;
  }
  stack_.push_back(Frame{n, FullKey(key), {}});
  return true;
}

void YamlOptionsReader::EndSection() {
  ReportUnknownKeys(stack_.back());
  stack_.pop_back();
}

void YamlOptionsReader::ValidateSection(const Status& status) {
  if (status.ok()) return;
  const Frame& frame = stack_.back();
  const std::string name = frame.path.empty() ? "the document" : "section '" + frame.path + "'";
  errors_.push_back(Where(frame.node, frame.path) + ": " + name + ": " + status.message());
}

void YamlOptionsReader::ReportUnknownKeys(const Frame& frame) {
  for (const auto& item : frame.node) {
    const std::string key = item.first.as<std::string>("");
    if (frame.consumed.count(key) != 0) continue;
    const std::string full = frame.path.empty() ? key : frame.path + "." + key;
    (earlier_versions_ ? notes_ : errors_).push_back(Where(item.first, full) + ": unknown key '" + full + "'");
  }
}

Status YamlOptionsReader::Result() const {
  if (errors_.empty()) return Status::Ok();
  std::string message;
  for (const auto& e : errors_) message += (message.empty() ? "" : "\n") + e;
  return InvalidArgumentError(message);
}

Expected<YamlDocument> LoadYamlWithOverrides(const std::string& path,
                                             const std::vector<std::string>& overrides) {
  std::ifstream in(path);
  if (!in) return NotFoundError(path + ": cannot open the configuration file");
  YamlDocument doc;
  try {
    doc.root = YAML::Load(in);
  } catch (const YAML::Exception& e) {
    return InvalidArgumentError(path + ":" + std::to_string(e.mark.line + 1) + ":" +
                                std::to_string(e.mark.column + 1) + ": not valid YAML: " + e.msg);
  }
  if (!doc.root.IsMap()) return InvalidArgumentError(path + ": the document is not a mapping of keys");
  for (const std::string& o : overrides) {
    const size_t eq = o.find('=');
    if (eq == std::string::npos || eq == 0) {
      return InvalidArgumentError("--set " + o + ": expected key.path=value");
    }
    const std::string key = o.substr(0, eq);
    YAML::Node value;
    try {
      value = YAML::Load(o.substr(eq + 1));
    } catch (const YAML::Exception& e) {
      return InvalidArgumentError("--set " + o + ": the value is not valid YAML: " + e.msg);
    }
    // Walk to the parent mapping; every key on the way must already exist so that a typo in an
    // override is an error rather than a silently ignored new key.
    YAML::Node node = doc.root;
    std::stringstream parts(key);
    std::string part, walked;
    std::vector<std::string> segments;
    while (std::getline(parts, part, '.')) segments.push_back(part);
    for (size_t i = 0; i < segments.size(); ++i) {
      walked += (walked.empty() ? "" : ".") + segments[i];
      const YAML::Node& current = node;
      if (!current.IsMap() || !current[segments[i]].IsDefined()) {
        return InvalidArgumentError("--set " + o + ": unknown key '" + walked + "' in " + path);
      }
      if (i + 1 == segments.size()) {
        node[segments[i]] = value;
      } else {
        node.reset(current[segments[i]]);
      }
    }
    doc.overridden_keys.insert(key);
  }
  return doc;
}

Expected<std::string> ReadListFile(const std::string& path, const std::string& what) {
  std::ifstream in(path);
  if (!in) return NotFoundError(path + ": cannot read the " + what);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

Expected<YAML::Node> ParseListDocument(const std::string& text, const std::string& source, const std::string& key) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    return InvalidArgumentError(source + ":" + std::to_string(e.mark.line + 1) + ": not YAML: " + e.msg);
  }
  if (!root.IsMap()) return InvalidArgumentError(source + ": expected a mapping with the key '" + key + "'");
  for (const auto& entry : root) {
    // A key that is itself a list or a mapping (YAML's complex keys) names nothing.
    const std::string name = entry.first.IsScalar() ? entry.first.Scalar() : "(not a name)";
    if (name != key) {
      const YAML::Mark mark = entry.first.Mark();
      return InvalidArgumentError(source + (mark.line < 0 ? "" : ":" + std::to_string(mark.line + 1)) +
                                  ": unknown key '" + name + "'");
    }
  }
  const YAML::Node list = root[key];
  if (!list || !list.IsSequence() || list.size() == 0)
    return InvalidArgumentError(source + ": '" + key + "' must list at least one entry");
  return list;
}

}  // namespace cairn
