#include "act_color/core/yaml_subset.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <utility>

namespace act_color {
namespace core {
namespace {

// One line of the document: its text after the indentation, without a comment and trailing
// blanks; `column` of each character kept implicitly as indent + 1 + index.
struct Line {
  int number = 0;
  int indent = 0;
  std::string text;
};

bool isBlank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

std::string trim(const std::string& s) {
  size_t b = 0, e = s.size();
  while (b < e && isBlank(s[b])) ++b;
  while (e > b && isBlank(s[e - 1])) --e;
  return s.substr(b, e - b);
}

class Parser {
 public:
  Parser(const std::string& text, const YamlLimits& limits) : limits_(limits) { split(text); }

  YamlNode document() {
    if (lines_.empty()) return YamlNode();  // empty document: an empty scalar
    size_t i = 0;
    YamlNode root = block(i, lines_[0].indent, 1);
    if (i < lines_.size()) fail(lines_[i].number, lines_[i].indent + 1, "unexpected indentation");
    return root;
  }

 private:
  [[noreturn]] static void fail(int line, int column, const std::string& what) { throw YamlError(line, column, what); }

  void countNode(int line, int column) {
    if (++nodes_ > limits_.max_nodes) {
      fail(line, column, "more than " + std::to_string(limits_.max_nodes) + " values (limit)");
    }
  }
  void checkDepth(int depth, int line, int column) const {
    if (depth > limits_.max_depth) {
      fail(line, column, "nested deeper than " + std::to_string(limits_.max_depth) + " levels (limit)");
    }
  }

  // Splits into lines: checks characters and indentation, strips comments, skips blank lines.
  // Lines end in LF, CR LF, or CR alone (old Mac editors) when the file has no LF; a UTF-8 byte
  // order mark before the first line is skipped.
  void split(const std::string& text) {
    static const std::string kByteOrderMark = "\xEF\xBB\xBF";
    const char line_end = text.find('\n') == std::string::npos && text.find('\r') != std::string::npos ? '\r' : '\n';
    int number = 0;
    size_t start = text.compare(0, kByteOrderMark.size(), kByteOrderMark) == 0 ? kByteOrderMark.size() : 0;
    bool first = true;
    while (start <= text.size()) {
      size_t end = text.find(line_end, start);
      if (end == std::string::npos) end = text.size();
      ++number;
      const std::string raw = text.substr(start, end - start);
      start = end + 1;
      Line line;
      line.number = number;
      size_t i = 0;
      while (i < raw.size() && raw[i] == ' ') ++i;
      if (i < raw.size() && raw[i] == '\t') fail(number, static_cast<int>(i) + 1, "a tab in the indentation");
      line.indent = static_cast<int>(i);
      // Characters, quotes and the comment.
      char quote = 0;
      size_t cut = raw.size();
      for (size_t k = i; k < raw.size(); ++k) {
        const unsigned char c = static_cast<unsigned char>(raw[k]);
        if (c < 0x20 && c != '\t' && c != '\r') fail(number, static_cast<int>(k) + 1, "a control character");
        if (quote == '"') {
          if (c == '\\') {
            ++k;
          } else if (c == '"') {
            quote = 0;
          }
        } else if (quote == '\'') {
          if (c == '\'') quote = 0;  // '' (an escaped quote) reopens at once
        } else if (c == '"' || c == '\'') {
          quote = static_cast<char>(c);
        } else if (c == '#' && (k == i || isBlank(raw[k - 1]))) {
          cut = k;
          break;
        }
      }
      if (quote != 0) fail(number, static_cast<int>(raw.size()) + 1, "unterminated quote");
      line.text = trim(raw.substr(i, cut - i));
      if (line.text.empty()) {
        if (end == text.size()) break;
        continue;
      }
      if (line.text[0] == '%') fail(number, line.indent + 1, "YAML directives are not supported");
      if (line.text == "---" || line.text.rfind("--- ", 0) == 0) {
        if (!first) fail(number, line.indent + 1, "only one document per file");
        first = false;
        if (line.text == "---") {
          if (end == text.size()) break;
          continue;
        }
        line.text = trim(line.text.substr(4));
        line.indent += 4;
      }
      if (line.text == "...") fail(number, line.indent + 1, "document end markers are not supported");
      first = false;
      lines_.push_back(std::move(line));
      if (end == text.size()) break;
    }
  }

  static bool isListItem(const std::string& t) { return t == "-" || t.rfind("- ", 0) == 0; }

  // A block map or list whose lines start at `indent`, from lines_[i].
  YamlNode block(size_t& i, int indent, int depth) {
    const Line& first = lines_[i];
    checkDepth(depth, first.number, first.indent + 1);
    return isListItem(first.text) ? blockList(i, indent, depth) : blockMap(i, indent, depth);
  }

  YamlNode blockList(size_t& i, int indent, int depth) {
    YamlNode list;
    list.kind = YamlNode::Kind::kList;
    list.line = lines_[i].number;
    list.column = indent + 1;
    countNode(list.line, list.column);
    while (i < lines_.size() && lines_[i].indent == indent && isListItem(lines_[i].text)) {
      const Line& line = lines_[i];
      const std::string rest = trim(line.text.substr(1));
      const int column = line.indent + 1 + static_cast<int>(line.text.size() - rest.size());
      if (rest.empty()) {
        ++i;
        if (i >= lines_.size() || lines_[i].indent <= indent) fail(line.number, line.indent + 1, "empty list item");
        list.items.push_back(block(i, lines_[i].indent, depth + 1));
      } else {
        if (keyEnd(rest) != std::string::npos) {
          fail(line.number, column, "maps inside block lists are not supported: write the item as {key: value}");
        }
        list.items.push_back(inlineValue(i, rest, column, depth + 1));
      }
    }
    if (i < lines_.size() && lines_[i].indent > indent) {
      fail(lines_[i].number, lines_[i].indent + 1, "unexpected indentation");
    }
    return list;
  }

  // Where the key of "key: value" ends (the ':'), npos when the text is no such pair. Quoted
  // keys and colons inside quotes are skipped.
  static size_t keyEnd(const std::string& t) {
    if (t.empty() || t[0] == '[' || t[0] == '{') return std::string::npos;
    size_t k = 0;
    if (t[0] == '"' || t[0] == '\'') {
      const char q = t[0];
      for (k = 1; k < t.size(); ++k) {
        if (q == '"' && t[k] == '\\') {
          ++k;
        } else if (t[k] == q) {
          if (q == '\'' && k + 1 < t.size() && t[k + 1] == '\'') {
            ++k;
            continue;
          }
          break;
        }
      }
      ++k;
    }
    for (; k < t.size(); ++k) {
      if (t[k] == ':' && (k + 1 == t.size() || isBlank(t[k + 1]))) return k;
    }
    return std::string::npos;
  }

  YamlNode blockMap(size_t& i, int indent, int depth) {
    YamlNode map;
    map.kind = YamlNode::Kind::kMap;
    map.line = lines_[i].number;
    map.column = indent + 1;
    countNode(map.line, map.column);
    while (i < lines_.size() && lines_[i].indent == indent) {
      const Line& line = lines_[i];
      if (isListItem(line.text)) fail(line.number, line.indent + 1, "a list item where a key was expected");
      const size_t colon = keyEnd(line.text);
      if (colon == std::string::npos) fail(line.number, line.indent + 1, "expected 'key: value'");
      std::string key = trim(line.text.substr(0, colon));
      if (!key.empty() && (key[0] == '"' || key[0] == '\'')) {
        key = quotedScalar(key, 0, line.number, line.indent + 1, nullptr);
      } else if (key.empty() || std::string("&*!|>@`?").find(key[0]) != std::string::npos) {
        fail(line.number, line.indent + 1, "expected a plain or quoted key");
      }
      const std::string rest = trim(line.text.substr(colon + 1));
      const int column = line.indent + 1 + static_cast<int>(line.text.size() - rest.size());
      if (rest.empty()) {
        ++i;
        // The value is the block below: more indented, or a list at the key's own indentation.
        if (i < lines_.size() &&
            (lines_[i].indent > indent || (lines_[i].indent == indent && isListItem(lines_[i].text)))) {
          map.entries.emplace_back(key, block(i, lines_[i].indent, depth + 1));
        } else {
          fail(line.number, column, "key '" + key + "' has no value");
        }
      } else {
        map.entries.emplace_back(key, inlineValue(i, rest, column, depth + 1));
      }
    }
    if (i < lines_.size() && lines_[i].indent > indent) {
      fail(lines_[i].number, lines_[i].indent + 1, "unexpected indentation");
    }
    return map;
  }

  // The value after "key: " or "- " on lines_[i] (a flow collection may go on over the next
  // lines); advances i past what it used.
  YamlNode inlineValue(size_t& i, const std::string& text, int column, int depth) {
    const int number = lines_[i].number;
    checkDepth(depth, number, column);
    const char c = text[0];
    if (c == '[' || c == '{') return flowCollection(i, text, column, depth);
    ++i;
    if (std::string("&*!|>%@`").find(c) != std::string::npos) {
      fail(number, column, std::string("'") + c + "': anchors, aliases, tags and block scalars are not supported");
    }
    YamlNode node;
    node.line = number;
    node.column = column;
    countNode(number, column);
    if (c == '"' || c == '\'') {
      size_t used = 0;
      node.scalar = quotedScalar(text, 0, number, column, &used);
      node.quoted = true;
      if (!trim(text.substr(used)).empty()) fail(number, column + static_cast<int>(used), "text after a quoted value");
    } else {
      node.scalar = text;
    }
    return node;
  }

  // A quoted scalar starting at s[at]; *used (if given) receives the index after the closing quote.
  static std::string quotedScalar(const std::string& s, size_t at, int line, int column, size_t* used) {
    const char q = s[at];
    std::string out;
    size_t k = at + 1;
    for (; k < s.size(); ++k) {
      const char c = s[k];
      if (q == '"' && c == '\\') {
        if (++k >= s.size()) break;
        switch (s[k]) {
          case 'n':
            out += '\n';
            break;
          case 't':
            out += '\t';
            break;
          case '"':
          case '\\':
          case '/':
            out += s[k];
            break;
          default:
            fail(line, column + static_cast<int>(k - at), std::string("unknown escape '\\") + s[k] + "'");
        }
      } else if (c == q) {
        if (q == '\'' && k + 1 < s.size() && s[k + 1] == '\'') {
          out += '\'';
          ++k;
        } else {
          if (used) *used = k + 1;
          return out;
        }
      } else {
        out += c;
      }
    }
    fail(line, column, "unterminated quote");
  }

  // A flow collection, joined over lines until its brackets close.
  YamlNode flowCollection(size_t& i, const std::string& first_text, int column, int depth) {
    flow_.clear();
    flow_pos_.clear();
    auto append = [&](const std::string& t, int line, int col) {
      for (size_t k = 0; k < t.size(); ++k) {
        flow_ += t[k];
        flow_pos_.emplace_back(line, col + static_cast<int>(k));
      }
    };
    append(first_text, lines_[i].number, column);
    const int start_line = lines_[i].number;
    ++i;
    int open = 0;
    size_t scanned = 0;
    auto balanced = [&] {
      char quote = 0;
      for (; scanned < flow_.size(); ++scanned) {
        const char c = flow_[scanned];
        if (quote) {
          if (quote == '"' && c == '\\') {
            ++scanned;
          } else if (c == quote) {
            quote = 0;
          }
        } else if (c == '"' || c == '\'') {
          quote = c;
        } else if (c == '[' || c == '{') {
          ++open;
        } else if (c == ']' || c == '}') {
          --open;
        }
      }
      return open <= 0;
    };
    while (!balanced()) {
      if (i >= lines_.size()) fail(start_line, column, "unclosed '" + std::string(1, first_text[0]) + "'");
      append(" ", lines_[i].number, 0);
      append(lines_[i].text, lines_[i].number, lines_[i].indent + 1);
      ++i;
    }
    size_t at = 0;
    YamlNode node = flowValue(at, depth);
    skipSpaces(at);
    if (at < flow_.size()) failAt(at, "text after the closing bracket");
    return node;
  }

  [[noreturn]] void failAt(size_t at, const std::string& what) const {
    const auto& p = flow_pos_[std::min(at, flow_pos_.size() - 1)];
    fail(p.first, p.second, what);
  }
  void skipSpaces(size_t& at) const {
    while (at < flow_.size() && isBlank(flow_[at])) ++at;
  }

  YamlNode flowValue(size_t& at, int depth) {
    skipSpaces(at);
    if (at >= flow_.size()) failAt(at, "a value is missing");
    const auto& p = flow_pos_[at];
    checkDepth(depth, p.first, p.second);
    YamlNode node;
    node.line = p.first;
    node.column = p.second;
    countNode(node.line, node.column);
    const char c = flow_[at];
    if (c == '[' || c == '{') {
      const bool list = c == '[';
      const char close = list ? ']' : '}';
      node.kind = list ? YamlNode::Kind::kList : YamlNode::Kind::kMap;
      ++at;
      skipSpaces(at);
      if (at < flow_.size() && flow_[at] == close) {
        ++at;
        return node;
      }
      while (true) {
        if (list) {
          node.items.push_back(flowValue(at, depth + 1));
        } else {
          skipSpaces(at);
          YamlNode key = flowScalar(at, true);
          skipSpaces(at);
          if (at >= flow_.size() || flow_[at] != ':') failAt(at, "expected ':' after the key");
          ++at;
          node.entries.emplace_back(key.scalar, flowValue(at, depth + 1));
        }
        skipSpaces(at);
        if (at >= flow_.size()) failAt(at, std::string("expected ',' or '") + close + "'");
        if (flow_[at] == close) {
          ++at;
          return node;
        }
        if (flow_[at] != ',') failAt(at, std::string("expected ',' or '") + close + "'");
        ++at;
      }
    }
    YamlNode scalar = flowScalar(at, false);
    scalar.line = node.line;
    scalar.column = node.column;
    return scalar;
  }

  // A scalar inside a flow collection: quoted, or plain up to , [ ] { } (and ':' for a key).
  YamlNode flowScalar(size_t& at, bool key) {
    YamlNode node;
    if (at >= flow_.size()) failAt(at, "a value is missing");
    const char c = flow_[at];
    if (c == '"' || c == '\'') {
      size_t used = 0;
      const auto& p = flow_pos_[at];
      node.scalar = quotedScalar(flow_, at, p.first, p.second, &used);
      node.quoted = true;
      at = used;
      return node;
    }
    if (std::string("&*!|>%@`").find(c) != std::string::npos) {
      failAt(at, std::string("'") + c + "': anchors, aliases, tags and block scalars are not supported");
    }
    const size_t begin = at;
    while (at < flow_.size()) {
      const char d = flow_[at];
      if (d == ',' || d == '[' || d == ']' || d == '{' || d == '}') break;
      if (key && d == ':') break;
      ++at;
    }
    node.scalar = trim(flow_.substr(begin, at - begin));
    if (node.scalar.empty()) failAt(begin, "a value is missing");
    return node;
  }

  const YamlLimits& limits_;
  std::vector<Line> lines_;
  size_t nodes_ = 0;
  std::string flow_;
  std::vector<std::pair<int, int>> flow_pos_;
};

}  // namespace

const YamlNode* YamlNode::find(const std::string& key) const {
  if (kind != Kind::kMap) return nullptr;
  for (const auto& e : entries) {
    if (e.first == key) return &e.second;
  }
  return nullptr;
}

YamlNode parseYaml(const std::string& text, const YamlLimits& limits) {
  if (text.size() > limits.max_bytes) {
    throw YamlError(1, 1,
                    std::to_string(text.size()) + " bytes, more than the " + std::to_string(limits.max_bytes) +
                        " a calibration file may have (limit)");
  }
  Parser parser(text, limits);
  return parser.document();
}

bool parseYamlNumber(const std::string& text, double* value) {
  // [sign] digits [. digits] [e [sign] digits], at least one digit before the exponent.
  size_t k = 0;
  if (k < text.size() && (text[k] == '+' || text[k] == '-')) ++k;
  size_t digits = 0;
  const size_t int_begin = k;
  while (k < text.size() && std::isdigit(static_cast<unsigned char>(text[k]))) ++k, ++digits;
  const size_t int_digits = k - int_begin;
  if (k < text.size() && text[k] == '.') {
    ++k;
    while (k < text.size() && std::isdigit(static_cast<unsigned char>(text[k]))) ++k, ++digits;
  }
  if (digits == 0) return false;
  if (int_digits > 1 && text[int_begin] == '0') return false;  // 042: YAML 1.1 octal, refused
  if (k < text.size() && (text[k] == 'e' || text[k] == 'E')) {
    ++k;
    if (k < text.size() && (text[k] == '+' || text[k] == '-')) ++k;
    const size_t exp_begin = k;
    while (k < text.size() && std::isdigit(static_cast<unsigned char>(text[k]))) ++k;
    if (k == exp_begin) return false;
  }
  if (k != text.size()) return false;
  errno = 0;
  const double v = std::strtod(text.c_str(), nullptr);
  if (!std::isfinite(v)) return false;
  *value = v;
  return true;
}

bool parseYamlInteger(const std::string& text, long long* value) {
  size_t k = 0;
  if (k < text.size() && (text[k] == '+' || text[k] == '-')) ++k;
  if (k >= text.size()) return false;
  if (text[k] == '0' && k + 1 < text.size()) return false;  // leading zero: refused, not octal
  for (size_t j = k; j < text.size(); ++j) {
    if (!std::isdigit(static_cast<unsigned char>(text[j]))) return false;
  }
  errno = 0;
  char* end = nullptr;
  const long long v = std::strtoll(text.c_str(), &end, 10);
  if (errno == ERANGE || end != text.c_str() + text.size()) return false;
  *value = v;
  return true;
}

}  // namespace core
}  // namespace act_color
