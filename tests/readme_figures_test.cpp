// The figures the README and docs/*.md quote from commands, checked against
// the program: each marked block (<!-- figures:NAME begin ... --> ...
// <!-- figures:NAME end -->, written by scripts/figures.sh) that is cheap to
// reproduce is parsed and compared with a real bake, `skybake presets` or
// `skybake bake --help`. A failure here means a page is stale: rerun
// `scripts/figures.sh fast` and review the diff.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "formats/manifest.h"
#include "test_util.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using testing::ReadText;
using testing::RunCommand;
using testing::ShellQuote;
using testing::Skybake;
using testing::TempDir;

const fs::path kSourceDir = SKYBAKE_SOURCE_DIR;
const char* const kTables[] = {"transmittance", "irradiance", "scattering", "single_mie_scattering"};

// The text between figures:NAME's begin and end markers in a page.
std::string Block(const std::string& page, const std::string& name) {
  std::string text = ReadText(kSourceDir / page);
  std::string begin = "<!-- figures:" + name + " begin", end = "<!-- figures:" + name + " end -->";
  size_t b = text.find(begin), e = text.find(end);
  if (b == std::string::npos || e == std::string::npos || e < b) {
    ADD_FAILURE() << page << " has no figures:" << name << " block";
    return "";
  }
  b = text.find('\n', b);
  return text.substr(b + 1, e - b - 1);
}

std::string Trim(const std::string& s) {
  size_t b = s.find_first_not_of(" \t"), e = s.find_last_not_of(" \t");
  return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}

// The data rows of the first Markdown table in `text` (header and rule left
// out), each as its trimmed cells.
std::vector<std::vector<std::string>> TableRows(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  int table_line = 0;
  for (const std::string& line : testing::Lines(text)) {
    if (line.rfind("|", 0) != 0) {
      if (table_line > 0) break;
      continue;
    }
    if (table_line++ < 2) continue;
    std::vector<std::string> cells;
    size_t start = 1;
    for (size_t bar; (bar = line.find('|', start)) != std::string::npos; start = bar + 1) {
      cells.push_back(Trim(line.substr(start, bar - start)));
    }
    rows.push_back(cells);
  }
  return rows;
}

// "12 194 121" -> 12194121 (the docs group thousands with spaces).
long long Integer(const std::string& cell) {
  std::string digits;
  for (char c : cell) {
    if (c != ' ') digits += c;
  }
  size_t used = 0;
  long long value = std::stoll(digits, &used);
  EXPECT_EQ(used, digits.size()) << "not an integer: " << cell;
  return value;
}

json BakeJson(const TempDir& dir, const std::string& options) {
  std::string out, err;
  int code = RunCommand(Skybake() + " bake earth -o " + ShellQuote((dir.path() / "set").string()) + " -q --json " +
                            options,
                        dir, &out, &err);
  EXPECT_EQ(code, 0) << err;
  return code == 0 ? json::parse(out) : json::object();
}

long long FileBytes(const json& report, const std::string& file) {
  for (const json& f : report["files"]) {
    if (f["file"] == file) return f["bytes"].get<long long>();
  }
  ADD_FAILURE() << "the bake wrote no " << file;
  return -1;
}

std::string Dimensions(const json& sizes) {
  std::string text;
  for (const json& d : sizes) text += (text.empty() ? "" : "×") + std::to_string(d.get<int>());
  return text;
}

// EXR sizes are of zip-compressed float bits: the bake's float loops are
// compiled for the building CPU (SKYBAKE_NATIVE_ARCH), and a CPU with other
// vector units may round a few texels differently and compress to a few bytes
// more or less. They are held to 0.01% (a stale figure is off by more);
// KTX2 sizes, fixed by the dimensions, exactly.
void ExpectExrSize(long long documented, long long baked, const std::string& what) {
  EXPECT_LE(std::abs(documented - baked), baked / 10000) << what << ": documented " << documented << ", baked " << baked
                                                        << " (rerun scripts/figures.sh sizes)";
}

TEST(NewcomerDefects, D10_DocumentedFileSizesMatchABake) {
  TempDir dir;
  json report = BakeJson(dir, "");
  std::string block = Block("docs/files.md", "file-sizes");
  auto rows = TableRows(block);
  ASSERT_EQ(rows.size(), 4u) << block;
  long long total = 0;
  for (size_t i = 0; i < rows.size(); ++i) {
    const std::string table = kTables[i];
    const auto& row = rows[i];
    ASSERT_EQ(row.size(), 8u);
    EXPECT_EQ(row[0], table);
    EXPECT_EQ(row[1], Dimensions(report["tables"][table])) << table << ": the default table size";
    ExpectExrSize(Integer(row[2]), FileBytes(report, table + ".exr"), table + ".exr, float");
    EXPECT_EQ(Integer(row[4]), FileBytes(report, table + ".ktx2")) << table << ".ktx2, float";
    total += FileBytes(report, table + ".exr") + FileBytes(report, table + ".ktx2");
  }
  std::smatch m;
  ASSERT_TRUE(std::regex_search(block, m, std::regex("All table files: ([0-9 ]+) bytes in float"))) << block;
  ExpectExrSize(Integer(m[1]), total, "all table files, float");
}

TEST(NewcomerDefects, D10_DocumentedHalfFiguresMatchAConversion) {
  TempDir dir;
  json report = BakeJson(dir, "--format exr");
  std::string block = Block("docs/files.md", "file-sizes");
  auto rows = TableRows(block);
  ASSERT_EQ(rows.size(), 4u);
  long long half_total = 0;
  for (size_t i = 0; i < rows.size(); ++i) {
    const std::string table = kTables[i];
    const auto& row = rows[i];
    ASSERT_EQ(row.size(), 8u);
    std::map<std::string, json> converted;
    for (const std::string format : {"exr", "ktx2"}) {
      std::string out, err;
      fs::path in = dir.path() / "set" / (table + ".exr"), half = dir.path() / (table + ".half." + format);
      ASSERT_EQ(RunCommand(Skybake() + " convert " + ShellQuote(in.string()) + " " + ShellQuote(half.string()) +
                               " --half --json",
                           dir, &out, &err),
                0)
          << err;
      converted[format] = json::parse(out);
    }
    ExpectExrSize(Integer(row[3]), converted["exr"]["bytes"].get<long long>(), table + ".exr, half");
    EXPECT_EQ(Integer(row[5]), converted["ktx2"]["bytes"].get<long long>()) << table << ".ktx2, half";

    half_total += converted["exr"]["bytes"].get<long long>() + converted["ktx2"]["bytes"].get<long long>();

    const json& error = converted["exr"]["half_error"];
    char max_error[32];
    std::snprintf(max_error, sizeof max_error, "%.2e", error["max_relative_error"].get<double>());
    EXPECT_EQ(row[6], max_error) << table << ": largest relative error of half";
    std::smatch m;
    ASSERT_TRUE(std::regex_match(row[7], m, std::regex(R"(([0-9 ]+) \(([0-9 ]+)\) of ([0-9 ]+))"))) << row[7];
    long long values = static_cast<long long>(converted["exr"]["channels"].size());
    for (const json& d : report["tables"][table]) values *= d.get<long long>();
    EXPECT_EQ(Integer(m[3]), values) << table << ": all values";
    // Counts of tiny values move with the bake's rounding too (see above): 1%.
    long long below = error["below_floor"].get<long long>(), flushed = error["flushed_to_zero"].get<long long>();
    EXPECT_LE(std::abs(Integer(m[1]) - below), below / 100) << table << ": values below 2^-14, baked " << below;
    EXPECT_LE(std::abs(Integer(m[2]) - flushed), flushed / 100) << table << ": flushed to 0, baked " << flushed;
  }
  std::smatch m;
  ASSERT_TRUE(std::regex_search(block, m, std::regex("bytes in float, ([0-9 ]+) bytes in half"))) << block;
  ExpectExrSize(Integer(m[1]), half_total, "all table files, half");
}

// The defect that the README had: a fixed --orders 3 adds no tail, though
// the README said every fixed count does. The documented row must say so.
TEST(NewcomerDefects, D10_OrdersTailTableMatchesABake) {
  TempDir dir;
  json report = BakeJson(dir, "--orders 3");
  auto rows = TableRows(Block("docs/accuracy.md", "orders-tail"));
  std::vector<std::string> labels;
  for (const auto& row : rows) labels.push_back(row.at(0));
  EXPECT_EQ(labels, (std::vector<std::string>{"1", "2", "3", "4", "4, `--no-tail`", "5", "6", "auto"}));
  ASSERT_GE(rows.size(), 3u);
  const auto& row = rows[2];
  ASSERT_EQ(row.size(), 5u);
  EXPECT_EQ(Integer(row[1]), report["orders_used"].get<long long>());
  EXPECT_NEAR(std::stod(row[2]), report["order_ratio"].get<double>(), 1e-4);
  if (report["extrapolated_tail"].get<double>() > 0.0) {
    EXPECT_NEAR(std::stod(row[3]), 100.0 * report["extrapolated_tail"].get<double>(), 0.01) << row[3];
  } else {
    EXPECT_EQ(row[3], "none");
  }
  double remaining = std::stod(row[4]);
  EXPECT_NEAR(remaining, report["remaining_error"].get<double>(), 0.01 * remaining);
}

TEST(NewcomerDefects, D10_PresetListMatches) {
  TempDir dir;
  std::string out, err;
  ASSERT_EQ(RunCommand(Skybake() + " presets --json", dir, &out, &err), 0) << err;
  json presets = json::parse(out);
  auto rows = TableRows(Block("docs/cli.md", "presets"));
  ASSERT_EQ(rows.size(), presets.size()) << "docs/cli.md lists " << rows.size() << " presets, skybake presets "
                                         << presets.size();
  for (size_t i = 0; i < rows.size(); ++i) {
    ASSERT_EQ(rows[i].size(), 2u);
    EXPECT_EQ(rows[i][0], "`" + presets[i]["name"].get<std::string>() + "`");
    EXPECT_EQ(rows[i][1], presets[i]["description"].get<std::string>());
  }
}

// The (option, default) pairs `skybake bake --help` states: CLI11's
// "--option TYPE=VALUE" (or "TYPE:{CHOICES}=VALUE"), or "(default VALUE)" in
// the description, which CLI11 moves to the next line when the option column
// is full.
std::map<std::string, std::string> HelpDefaults(const std::string& help) {
  std::vector<std::string> lines;
  for (const std::string& line : testing::Lines(help)) {
    bool continuation = line.size() > 20 && line.find_first_not_of(' ') >= 20 && Trim(line)[0] != '-';
    if (continuation && !lines.empty()) {
      lines.back() += " " + Trim(line);
    } else {
      lines.push_back(line);
    }
  }
  std::map<std::string, std::string> defaults;
  const std::regex option(R"(\s+(?:-\w,)?(--[\w-]+)(?: (\w+)(?::\{[^}]*\})?)?(?:=(\S+))?(?: x (\d))?(?:\s+(.*))?)");
  const std::regex stated(R"(\(default ([^;)]*))");
  for (const std::string& line : lines) {
    std::smatch m, d;
    if (!std::regex_match(line, m, option) || m[1] == "--help") continue;
    std::string value = m[3].matched ? m[3].str() : "", description = m[5];
    if (!m[3].matched && std::regex_search(description, d, stated)) value = d[1];
    if (value.empty()) continue;
    value.erase(std::remove(value.begin(), value.end(), '['), value.end());
    value.erase(std::remove(value.begin(), value.end(), ']'), value.end());
    defaults[m[1]] = value;
  }
  return defaults;
}

TEST(NewcomerDefects, D10_DocumentedDefaultsMatchHelp) {
  TempDir dir;
  std::string help, err;
  ASSERT_EQ(RunCommand(Skybake() + " bake --help", dir, &help, &err), 0) << err;
  std::map<std::string, std::string> stated = HelpDefaults(help);
  // The parser itself: the defaults every page relies on must be found.
  ASSERT_EQ(stated.count("--orders"), 1u) << help;
  ASSERT_EQ(stated.count("--scattering-size"), 1u) << help;
  ASSERT_EQ(stated.count("--spectral-higher-orders"), 1u) << help;

  std::map<std::string, std::string> documented;
  for (const auto& row : TableRows(Block("docs/cli.md", "bake-defaults"))) {
    ASSERT_EQ(row.size(), 2u);
    auto unquote = [](const std::string& s) { return s.size() >= 2 ? s.substr(1, s.size() - 2) : s; };
    documented[unquote(row[0])] = unquote(row[1]);
  }
  EXPECT_EQ(documented, stated) << "docs/cli.md's bake defaults against skybake bake --help "
                                   "(rerun scripts/figures.sh cli)";
}

// The case counts docs/accuracy.md and docs/report.md give, against the
// committed case set.
TEST(NewcomerDefects, D10_CaseSetCountsMatch) {
  std::map<std::string, long long> groups;
  long long cases = -1;  // the header
  for (const std::string& line : testing::Lines(ReadText(kSourceDir / "reference/cases/earth.csv"))) {
    if (cases++ >= 0) ++groups[line.substr(0, line.find(','))];
  }
  std::string report = ReadText(kSourceDir / "docs/report.md");
  std::string table = report.substr(report.find("| group | rows |"));
  std::map<std::string, long long> documented;
  for (const auto& row : TableRows(table)) {
    ASSERT_GE(row.size(), 2u);
    documented[row[0].substr(1, row[0].size() - 2)] = Integer(row[1]);
  }
  EXPECT_EQ(documented, groups) << "docs/report.md's case-set table";
  std::string accuracy = ReadText(kSourceDir / "docs/accuracy.md");
  for (const std::string& text : {report, accuracy}) {
    std::smatch m;
    ASSERT_TRUE(std::regex_search(text, m, std::regex(R"((\d+) queries)")));
    EXPECT_EQ(std::stoll(m[1]), cases);
  }
}

// Every marked block has both markers and names a part of scripts/figures.sh
// that writes it, so a reader knows which command regenerates it.
TEST(NewcomerDefects, D10_EveryMarkedBlockNamesItsCommand) {
  const std::set<std::string> parts = {"sizes", "orders", "cli", "stress", "bench", "report"};
  std::string script = ReadText(kSourceDir / "scripts/figures.py");
  int blocks = 0;
  std::vector<fs::path> pages = {kSourceDir / "README.md"};
  for (const auto& entry : fs::directory_iterator(kSourceDir / "docs")) {
    if (entry.path().extension() == ".md") pages.push_back(entry.path());
  }
  const std::regex begin(R"(<!-- figures:([\w-]+) begin: scripts/figures\.sh (\w+) -->)");
  for (const fs::path& page : pages) {
    std::string text = ReadText(page);
    for (std::sregex_iterator it(text.begin(), text.end(), begin), end; it != end; ++it) {
      ++blocks;
      std::string name = (*it)[1], part = (*it)[2];
      EXPECT_EQ(parts.count(part), 1u) << page << ": figures:" << name << " names no part: " << part;
      EXPECT_NE(text.find("<!-- figures:" + name + " end -->", it->position()), std::string::npos)
          << page << ": figures:" << name << " has no end marker";
      EXPECT_NE(script.find("\"" + name + "\", \"" + part + "\""), std::string::npos)
          << "scripts/figures.py's part " << part << " does not write figures:" << name;
    }
  }
  EXPECT_GE(blocks, 7);
}

// docs/manifest.md states the schema version skybake writes, in its title
// and in its table of keys.
TEST(NewcomerDefects, D10_ManifestPageStatesTheSchemaVersionWritten) {
  const std::string text = ReadText(kSourceDir / "docs/manifest.md");
  const std::string version = std::to_string(kManifestSchemaVersion);
  EXPECT_NE(text.find("(schema version " + version + ")"), std::string::npos) << "docs/manifest.md's title";
  EXPECT_NE(text.find("| `schema_version` | `" + version + "` |"), std::string::npos)
      << "docs/manifest.md's table of keys";
}

}  // namespace
}  // namespace skybake
