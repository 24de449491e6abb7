#include "common/options_yaml_writer.h"

#include <iomanip>
#include <limits>

namespace cairn {
namespace {

std::string Num(double v) {
  std::ostringstream s;
  s << std::setprecision(std::numeric_limits<double>::max_digits10) << v;
  std::string t = s.str();
  // Shortest form that still reads back exactly.
  for (int p = 1; p < 17; ++p) {
    std::ostringstream shorter;
    shorter << std::setprecision(p) << v;
    if (std::stod(shorter.str()) == v) return shorter.str();
  }
  return t;
}

std::string RangeComment(const std::string& min, const std::string& max, std::string_view unit) {
  std::string c = "[" + min + ", " + max + "]";
  if (!unit.empty()) c += " " + std::string(unit);
  return c;
}

std::string Quote(const std::string& s) {
  std::string q = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') q += '\\';
    q += c;
  }
  return q + "\"";
}

}  // namespace

void OptionsYamlWriter::Line(std::string_view key, const std::string& value,
                             const std::string& comment) {
  out_ << std::string(static_cast<size_t>(depth_) * 2, ' ') << key << ":";
  if (!value.empty()) out_ << " " << value;
  if (!comment.empty()) out_ << "  # " << comment;
  out_ << "\n";
}

void OptionsYamlWriter::Number(std::string_view key, double& value, double min, double max,
                               std::string_view unit) {
  Line(key, Num(value), RangeComment(Num(min), Num(max), unit));
}

void OptionsYamlWriter::IntegerImpl(std::string_view key, int64_t& value, int64_t min,
                                    int64_t max, std::string_view unit) {
  Line(key, std::to_string(value), RangeComment(std::to_string(min), std::to_string(max), unit));
}

void OptionsYamlWriter::Flag(std::string_view key, bool& value) {
  Line(key, value ? "true" : "false", "");
}

void OptionsYamlWriter::Text(std::string_view key, std::string& value) { Line(key, Quote(value), ""); }

void OptionsYamlWriter::Numbers(std::string_view key, std::vector<double>& values,
                                size_t min_count, size_t max_count, double min, double max,
                                std::string_view unit) {
  std::string list = "[";
  for (size_t i = 0; i < values.size(); ++i) list += (i ? ", " : "") + Num(values[i]);
  list += "]";
  const std::string count = min_count == max_count
                                ? std::to_string(min_count)
                                : std::to_string(min_count) + ".." + std::to_string(max_count);
  Line(key, list, count + " values in " + RangeComment(Num(min), Num(max), unit));
}

void OptionsYamlWriter::ChoiceImpl(std::string_view key, int& index,
                                   std::span<const std::string_view> names) {
  std::string all;
  for (const auto& n : names) all += (all.empty() ? "" : " | ") + std::string(n);
  Line(key, std::string(names[static_cast<size_t>(index)]), all);
}

bool OptionsYamlWriter::BeginSection(std::string_view key) {
  Line(key, "", "");
  ++depth_;
  return true;
}

void OptionsYamlWriter::EndSection() { --depth_; }

}  // namespace cairn
