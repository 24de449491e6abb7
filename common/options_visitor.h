#pragma once
// Module options are plain structs that describe their own fields once, with key, unit and
// allowed range, through `void Visit(OptionsVisitor& v)`. A YAML reader, a writer of the effective
// configuration and the documentation generator are all visitors, so the description never drifts
// from the code and no module depends on a YAML library.
//
//   struct QueueOptions {
//     int64_t depth = 64;
//     void Visit(OptionsVisitor& v) { v.Integer("depth", depth, 1, 1 << 20, "samples"); }
//   };
//
// An options struct may also offer `Status Validate() const` for checks across fields.

#include <concepts>
#include <cstdint>
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "common/status.h"

namespace cairn {

class OptionsVisitor {
 public:
  virtual ~OptionsVisitor() = default;

  virtual void Number(std::string_view key, double& value, double min, double max,
                      std::string_view unit) = 0;
  virtual void Flag(std::string_view key, bool& value) = 0;
  virtual void Text(std::string_view key, std::string& value) = 0;
  // A list of numbers with a count in [min_count, max_count], each in [min, max].
  virtual void Numbers(std::string_view key, std::vector<double>& values, size_t min_count,
                       size_t max_count, double min, double max, std::string_view unit) = 0;

  template <std::integral I>
  void Integer(std::string_view key, I& value, int64_t min, int64_t max, std::string_view unit) {
    int64_t v = static_cast<int64_t>(value);
    IntegerImpl(key, v, min, max, unit);
    value = static_cast<I>(v);
  }

  // One of a fixed set of names, mapped to an enum.
  template <class E>
  void Choice(std::string_view key, E& value,
              std::initializer_list<std::pair<std::string_view, E>> choices) {
    std::vector<std::string_view> names;
    int index = 0, i = 0;
    for (const auto& [name, e] : choices) {
      names.push_back(name);
      if (e == value) index = i;
      ++i;
    }
    ChoiceImpl(key, index, names);
    value = (choices.begin() + index)->second;
  }

  // A nested options struct under `key`.
  template <class Sub>
  void Section(std::string_view key, Sub& sub) {
    if (BeginSection(key)) {
      sub.Visit(*this);
      if constexpr (requires { { sub.Validate() } -> std::same_as<Status>; }) {
        ValidateSection(sub.Validate());
      }
      EndSection();
    }
  }

 protected:
  virtual void IntegerImpl(std::string_view key, int64_t& value, int64_t min, int64_t max,
                           std::string_view unit) = 0;
  virtual void ChoiceImpl(std::string_view key, int& index,
                          std::span<const std::string_view> names) = 0;
  // Returns false when the section cannot be entered (the visitor has recorded why).
  virtual bool BeginSection(std::string_view key) = 0;
  virtual void EndSection() = 0;
  // Called with the result of a section's Validate(); a reader records failures with the section's
  // location.
  virtual void ValidateSection(const Status& status) = 0;
};

}  // namespace cairn
