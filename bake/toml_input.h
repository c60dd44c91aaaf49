// Reading validated values from TOML files with one-line errors that name the
// source and the key path ("mars.toml: planet.top_radius_km = 6300 ..."):
// the pieces shared by the atmosphere files (bake/config.cpp) and the scene
// files (bake/scene.cpp), so that both report problems alike.
#pragma once

#include <algorithm>
#include <cstddef>
#include <filesystem>
#include <initializer_list>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include <toml++/toml.h>

#include "core/errors.h"

namespace skybake::toml_input {

// The shortest decimal that reads back as the same double, as messages quote it.
std::string FormatNumber(double value);
std::string TomlString(std::string_view text);
// A key as TOML spells it: bare where allowed, quoted otherwise.
std::string TomlKey(std::string_view key);
// Key paths of error messages: "a.b", "a[2]".
std::string Join(const std::string& path, std::string_view key);
std::string Index(const std::string& path, size_t i);
std::string OneLine(std::string text);
// The TOML document, or InputError "<source>:<line>: <problem>".
toml::table ParseDocument(std::string_view toml_text, const std::string& source_name);
// "a table", "string", "an array of 3", ... for "expected X, got Y".
std::string TypeName(const toml::node& node);
std::string KeyList(std::initializer_list<std::string_view> keys);

// Error reporting: every message is "<source>: <key path>: <problem>" or
// "<source>: <key path> = <value> <problem>", on one line.

class Reporter {
 public:
  explicit Reporter(std::string source) : source_(std::move(source)) {}

  [[noreturn]] void Fail(const std::string& path, const std::string& problem) const {
    throw InputError(OneLine(LocationPrefix(source_) + (path.empty() ? "" : path + ": ") + problem),
                     {source_, 0, path});
  }
  [[noreturn]] void FailValue(const std::string& path, double value,
                              const std::string& problem) const {
    throw InputError(OneLine(LocationPrefix(source_) + path + " = " + FormatNumber(value) + " " + problem),
                     {source_, 0, path});
  }

 private:
  std::string source_;
};

// An interval of acceptable values. Non-finite numbers are always rejected.
struct Interval {
  double lo;
  double hi;
  bool lo_closed;
  bool hi_closed;
  const char* text = nullptr;  // how to print it, where the bounds are not round numbers

  bool Contains(double v) const {
    return (lo_closed ? v >= lo : v > lo) && (hi_closed ? v <= hi : v < hi);
  }
  std::string Problem() const {
    if (hi == std::numeric_limits<double>::infinity() && lo == 0.0) return lo_closed ? "must be >= 0" : "must be > 0";
    std::string range = text ? text
                             : std::string(lo_closed ? "[" : "(") + FormatNumber(lo) + ", " +
                                   FormatNumber(hi) + (hi_closed ? "]" : ")");
    return "is outside " + range;
  }
};


void CheckNumber(const Reporter& report, const std::string& path, double value, const Interval& interval);

// Typed access to a TOML tree; every failure goes through the Reporter.
class TomlReader {
 public:
  explicit TomlReader(const std::string& source) : report_(source) {}

  void CheckKeys(const toml::table& table, const std::string& path,
                 std::initializer_list<std::string_view> allowed) const {
    for (auto&& [key, node] : table) {
      if (std::find(allowed.begin(), allowed.end(), key.str()) == allowed.end())
        report_.Fail(Join(path, key.str()), "unknown key (expected " + KeyList(allowed) + ")");
    }
  }

  const toml::table* OptionalTable(const toml::table& parent, const std::string& path,
                                   std::string_view key) const {
    const toml::node* node = parent.get(key);
    if (!node) return nullptr;
    if (!node->is_table()) report_.Fail(Join(path, key), "expected a table, got " + TypeName(*node));
    return node->as_table();
  }

  const toml::table& RequireTable(const toml::table& parent, const std::string& path,
                                  std::string_view key) const {
    const toml::table* table = OptionalTable(parent, path, key);
    if (!table) report_.Fail(Join(path, key), "missing required table");
    return *table;
  }

  const toml::node& Require(const toml::table& table, const std::string& path,
                            std::string_view key) const {
    const toml::node* node = table.get(key);
    if (!node) report_.Fail(Join(path, key), "missing required key");
    return *node;
  }

  // Exactly one of `keys` must be present; returns its index and node.
  std::pair<size_t, const toml::node*> ExactlyOne(
      const toml::table& table, const std::string& path,
      std::initializer_list<std::string_view> keys) const {
    std::optional<size_t> found;
    size_t i = 0;
    for (std::string_view key : keys) {
      if (table.get(key)) {
        if (found)
          report_.Fail(Join(path, key), "conflicts with " + Join(path, keys.begin()[*found]) +
                                            " (give exactly one of " + KeyList(keys) + ")");
        found = i;
      }
      ++i;
    }
    if (!found) report_.Fail(path, "missing one of " + KeyList(keys));
    return {*found, table.get(keys.begin()[*found])};
  }

  std::string ReadString(const toml::node& node, const std::string& path) const {
    if (!node.is_string()) report_.Fail(path, "expected a string, got " + TypeName(node));
    return node.as_string()->get();
  }

  std::string RequireString(const toml::table& table, const std::string& path,
                            std::string_view key) const {
    return ReadString(Require(table, path, key), Join(path, key));
  }

  // A number; TOML integers are accepted and converted.
  double ReadNumber(const toml::node& node, const std::string& path) const {
    if (const auto* f = node.as_floating_point()) return f->get();
    if (const auto* i = node.as_integer()) return static_cast<double>(i->get());
    report_.Fail(path, "expected a number, got " + TypeName(node));
  }

  double ReadNumber(const toml::node& node, const std::string& path,
                    const Interval& interval) const {
    double value = ReadNumber(node, path);
    CheckNumber(report_, path, value, interval);
    return value;
  }

 protected:
  Reporter report_;
};

}  // namespace skybake::toml_input
