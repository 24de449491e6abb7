#pragma once
// Reads an options struct from a YAML document through its Visit() description. Every error is
// collected (not only the first) and names the file, line and full key: missing keys, unknown
// keys, wrong types and values outside their range. Values set on the command line with
// `--set a.b=value` are reported as coming from there.

#include <set>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "common/options_visitor.h"
#include "common/status.h"

namespace cairn {

class YamlOptionsReader final : public OptionsVisitor {
 public:
  // `source_name` is how errors name the document (normally its file path).
  YamlOptionsReader(YAML::Node root, std::string source_name,
                    std::set<std::string> overridden_keys = {});

  // Reads `options` from the document root, then reports keys nobody asked for.
  template <class Options>
  Status Read(Options& options) {
    options.Visit(*this);
    if constexpr (requires { { options.Validate() } -> std::same_as<Status>; }) {
      ValidateSection(options.Validate());
    }
    ReportUnknownKeys(stack_.back());
    return Result();
  }

  const std::vector<std::string>& errors() const { return errors_; }

  // For a copy written by an earlier version (an output folder's config.yaml): missing keys keep
  // their defaults and unknown keys are skipped, each listed in notes() instead of failing.
  void AcceptEarlierVersions() { earlier_versions_ = true; }
  const std::vector<std::string>& notes() const { return notes_; }

  void Number(std::string_view key, double& value, double min, double max,
              std::string_view unit) override;
  void Flag(std::string_view key, bool& value) override;
  void Text(std::string_view key, std::string& value) override;
  void Numbers(std::string_view key, std::vector<double>& values, size_t min_count,
               size_t max_count, double min, double max, std::string_view unit) override;

 protected:
  void IntegerImpl(std::string_view key, int64_t& value, int64_t min, int64_t max,
                   std::string_view unit) override;
  void ChoiceImpl(std::string_view key, int& index, std::span<const std::string_view> names) override;
  bool BeginSection(std::string_view key) override;
  void EndSection() override;
  void ValidateSection(const Status& status) override;

 private:
  struct Frame {
    YAML::Node node;
    std::string path;  // dotted path of this mapping, "" at the root
    std::set<std::string> consumed;
  };

  // The scalar/sequence under `key`, or an invalid node after recording "missing".
  YAML::Node Lookup(std::string_view key);
  std::string FullKey(std::string_view key) const;
  std::string Where(const YAML::Node& node, const std::string& full_key) const;
  void Error(const YAML::Node& node, std::string_view key, const std::string& what);
  void ReportUnknownKeys(const Frame& frame);
  Status Result() const;

  std::string source_;
  std::set<std::string> overridden_;
  std::vector<Frame> stack_;
  std::vector<std::string> errors_;
  std::vector<std::string> notes_;
  bool earlier_versions_ = false;
};

// Loads a YAML file (or reports where it does not parse), applies `key.path=value` overrides and
// returns the document with the set of overridden keys.
struct YamlDocument {
  YAML::Node root;
  std::set<std::string> overridden_keys;
};
Expected<YamlDocument> LoadYamlWithOverrides(const std::string& path,
                                             const std::vector<std::string>& overrides);

// A file of one list (`key:` followed by entries, e.g. a team file): the whole text of `path`
// (`what` names the file's kind in the error), and the list's non-empty sequence from `text`
// (named `source` in errors, with the line of an unknown key).
Expected<std::string> ReadListFile(const std::string& path, const std::string& what);
Expected<YAML::Node> ParseListDocument(const std::string& text, const std::string& source, const std::string& key);

}  // namespace cairn
