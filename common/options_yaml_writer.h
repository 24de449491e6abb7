#pragma once
// Writes an options struct as YAML, each key with its unit and allowed range as a comment. Used to
// save the effective configuration of a run next to its outputs and to document every key.

#include <sstream>
#include <string>

#include "common/options_visitor.h"

namespace cairn {

class OptionsYamlWriter final : public OptionsVisitor {
 public:
  template <class Options>
  static std::string Write(Options& options) {
    OptionsYamlWriter w;
    options.Visit(w);
    return w.out_.str();
  }

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
  void ValidateSection(const Status&) override {}

 private:
  void Line(std::string_view key, const std::string& value, const std::string& comment);
  std::ostringstream out_;
  int depth_ = 0;
};

}  // namespace cairn
