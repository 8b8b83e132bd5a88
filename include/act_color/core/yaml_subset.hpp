#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace act_color {
namespace core {

// The part of YAML that calibration files use, read by a parser that cannot be made to crash,
// stall or allocate without bound by its input: block maps and block lists by indentation, flow
// lists and maps ([a, b], {k: v}, also over several lines), plain and quoted scalars, comments.
// Anchors, aliases, tags, block scalars, directives and multiple documents are refused. Linear in
// the input; the input's size, the nesting depth and the number of nodes are bounded first.
// Scalars stay text: the reader of each key types them (no YAML 1.1 surprises: `042` is not octal
// 34, `4294967297` does not wrap, `yes` is not true).
struct YamlLimits {
  size_t max_bytes = 4u << 20;  // 4 MiB: a dense elevation map of a 16 Mpx camera fits
  int max_depth = 16;
  size_t max_nodes = 1u << 20;
};

// A syntax error or a limit, with the line and column (1-based) where it was found.
class YamlError : public std::runtime_error {
 public:
  YamlError(int line, int column, const std::string& what)
      : std::runtime_error("line " + std::to_string(line) + ", column " + std::to_string(column) + ": " + what),
        line_(line),
        column_(column) {}
  int line() const { return line_; }
  int column() const { return column_; }

 private:
  int line_, column_;
};

struct YamlNode {
  enum class Kind { kScalar, kList, kMap };
  Kind kind = Kind::kScalar;
  std::string scalar;  // kScalar: the text (quotes removed, escapes applied)
  bool quoted = false;
  std::vector<YamlNode> items;                            // kList
  std::vector<std::pair<std::string, YamlNode>> entries;  // kMap, in file order (a repeated key is
                                                          // kept: the reader refuses it by name)
  int line = 0, column = 0;                               // where the node starts (1-based)

  bool isScalar() const { return kind == Kind::kScalar; }
  bool isList() const { return kind == Kind::kList; }
  bool isMap() const { return kind == Kind::kMap; }
  // The value of `key` in a map; nullptr when absent (or not a map).
  const YamlNode* find(const std::string& key) const;
};

// The document's root (a map, a list or a scalar). Throws YamlError.
YamlNode parseYaml(const std::string& text, const YamlLimits& limits = YamlLimits());

// Typed scalars, strictly: false when `text` is not one. A number: decimal, optional sign,
// fraction and exponent, finite; an integer: decimal digits without a leading zero, within int64
// (no wrap).
bool parseYamlNumber(const std::string& text, double* value);
bool parseYamlInteger(const std::string& text, long long* value);

}  // namespace core
}  // namespace act_color
