// The shared TOML reading pieces (bake/toml_input.h).
#include "bake/toml_input.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <sstream>

#include "bake/config.h"

namespace skybake::toml_input {

// The shortest decimal that reads back as the same double (17 significant
// digits at most), in fixed notation for everyday magnitudes and scientific
// otherwise: messages quote "1.2" and "6360000", and ToToml round-trips.
std::string FormatNumber(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char buffer[48];
  int digits = 0;  // after the point in scientific notation; 16 always round-trips
  for (;; ++digits) {
    std::snprintf(buffer, sizeof buffer, "%.*e", digits, value);
    if (digits == 16 || std::strtod(buffer, nullptr) == value) break;
  }
  int exponent = std::atoi(std::strchr(buffer, 'e') + 1);
  if (exponent >= -4 && exponent < 16)
    std::snprintf(buffer, sizeof buffer, "%.*f", std::max(0, digits - exponent), value);
  return buffer;
}

std::string TomlString(std::string_view text) {
  std::string out = "\"";
  for (char c : text) {
    unsigned char u = static_cast<unsigned char>(c);
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\t': out += "\\t"; break;
      case '\r': out += "\\r"; break;
      default:
        if (u < 0x20 || u == 0x7f) {
          char escape[8];
          std::snprintf(escape, sizeof escape, "\\u%04x", u);
          out += escape;
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

// A key as TOML spells it: bare where allowed, quoted otherwise. Used both in
// the writer and in key paths of error messages.
std::string TomlKey(std::string_view key) {
  bool bare = !key.empty() && std::all_of(key.begin(), key.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
           c == '_' || c == '-';
  });
  return bare ? std::string(key) : TomlString(key);
}

std::string Join(const std::string& path, std::string_view key) {
  return path.empty() ? TomlKey(key) : path + "." + TomlKey(key);
}

std::string Index(const std::string& path, size_t i) {
  return path + "[" + std::to_string(i) + "]";
}

std::string OneLine(std::string text) {
  std::replace_if(text.begin(), text.end(), [](char c) { return c == '\n' || c == '\r'; }, ' ');
  return text;
}

toml::table ParseDocument(std::string_view toml_text, const std::string& source_name) {
  try {
    return toml::parse(toml_text, source_name);
  } catch (const toml::parse_error& error) {
    const int line = static_cast<int>(error.source().begin.line);
    throw InputError(OneLine(LocationPrefix(source_name, line) + std::string(error.description())),
                     {source_name, line});
  }
}

// ---------------------------------------------------------------------------
void CheckNumber(const Reporter& report, const std::string& path, double value,
                 const Interval& interval) {
  if (!std::isfinite(value)) report.FailValue(path, value, "is not a finite number");
  if (!interval.Contains(value)) report.FailValue(path, value, interval.Problem());
}

std::string TypeName(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::table: return "a table";
    case toml::node_type::array:
      return "an array of " + std::to_string(node.as_array()->size());
    case toml::node_type::string: return "string";
    case toml::node_type::integer: return "integer";
    case toml::node_type::floating_point: return "float";
    case toml::node_type::boolean: return "boolean";
    case toml::node_type::date: return "date";
    case toml::node_type::time: return "time";
    case toml::node_type::date_time: return "date-time";
    case toml::node_type::none: break;
  }
  return "nothing";
}

std::string KeyList(std::initializer_list<std::string_view> keys) {
  std::string text;
  for (std::string_view key : keys) text += (text.empty() ? "" : ", ") + std::string(key);
  return text;
}

}  // namespace skybake::toml_input
