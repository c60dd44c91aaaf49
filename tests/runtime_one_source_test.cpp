// One source: every function of the GLSL runtime is defined once among the
// project's hand-maintained files. The CPU twin and the bake compile the GLSL
// itself (shaders_runtime/runtime.h, primitives.h); the HLSL, MSL and WGSL are
// generated (shaders_runtime/generated/, each marked so, and checked against a
// fresh translation by the ctest runtime_translation_fresh). A second
// hand-written definition of a runtime function, in any language anywhere in
// the tree, fails here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "tests/test_util.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;

bool IsIdentifierChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

// The index just past the parenthesis matching the one at `open`, or npos.
size_t PastMatchingParenthesis(const std::string& text, size_t open) {
  int depth = 0;
  for (size_t i = open; i < text.size(); ++i) {
    if (text[i] == '(') ++depth;
    if (text[i] == ')' && --depth == 0) return i + 1;
    if (text[i] == ';' || text[i] == '{' || text[i] == '}') return std::string::npos;
  }
  return std::string::npos;
}

// Definitions of function `name` in C-like source or WGSL: `name(...)`
// followed by an optional `-> type` (WGSL) or `const` (C++), then `{`.
int CountDefinitions(const std::string& text, const std::string& name) {
  int count = 0;
  for (size_t at = text.find(name); at != std::string::npos; at = text.find(name, at + 1)) {
    if (at > 0 && (IsIdentifierChar(text[at - 1]) || text[at - 1] == '.')) continue;
    size_t i = at + name.size();
    while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
    if (i >= text.size() || text[i] != '(') continue;
    i = PastMatchingParenthesis(text, i);
    if (i == std::string::npos) continue;
    while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
    if (text.compare(i, 2, "->") == 0) {  // a WGSL return type
      while (i < text.size() && text[i] != '{' && text[i] != ';' && text[i] != '(' && text[i] != ')') ++i;
    } else if (text.compare(i, 5, "const") == 0) {
      i += 5;
      while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
    }
    if (i < text.size() && text[i] == '{') ++count;
  }
  return count;
}

// The functions the GLSL runtime defines (every *.glsl of shaders_runtime).
std::set<std::string> RuntimeFunctionNames(const fs::path& runtime_dir) {
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(runtime_dir)) {
    if (entry.path().extension() != ".glsl") continue;
    for (const std::string& line : testing::Lines(testing::ReadText(entry.path()))) {
      // A definition starts at column 0 with its return type: "Number Name(".
      if (line.empty() || !std::isalpha(static_cast<unsigned char>(line[0]))) continue;
      const size_t open = line.find('(');
      const size_t space = line.find(' ');
      if (open == std::string::npos || space == std::string::npos || space > open) continue;
      const std::string name = line.substr(space + 1, open - space - 1);
      if (!name.empty() && std::all_of(name.begin(), name.end(), IsIdentifierChar)) names.insert(name);
    }
  }
  return names;
}

// The hand-maintained files that could hold a shader or C++ function.
std::vector<fs::path> HandMaintainedSources(const fs::path& root) {
  const std::set<std::string> extensions = {".glsl", ".h",   ".hpp", ".cpp", ".hlsl", ".hlsli", ".ush",
                                            ".usf",  ".metal", ".wgsl", ".mjs", ".js", ".py"};
  const std::set<std::string> skipped = {".git", "node_modules", "generated", "out"};
  std::vector<fs::path> files;
  for (auto it = fs::recursive_directory_iterator(root); it != fs::recursive_directory_iterator(); ++it) {
    const std::string name = it->path().filename().string();
    if (it->is_directory() && (skipped.count(name) || name.rfind("build", 0) == 0)) {
      it.disable_recursion_pending();
      continue;
    }
    if (it->is_regular_file() && extensions.count(it->path().extension().string())) files.push_back(it->path());
  }
  return files;
}

TEST(RuntimeOneSource, CountDefinitionsTellsDefinitionsFromCalls) {
  EXPECT_EQ(CountDefinitions("Number Foo(Number a) { return a; }\nNumber b = Foo(1.0);", "Foo"), 1);
  EXPECT_EQ(CountDefinitions("fn Foo(a: f32) -> vec3<f32> {\n return vec3<f32>(a); }", "Foo"), 1);
  EXPECT_EQ(CountDefinitions("float3 Foo(float3 a, out float3 b)\n{\n}\nvoid main() { if (Foo(x, y).x > 0) {} }",
                             "Foo"),
            1);
  EXPECT_EQ(CountDefinitions("double Foo(const vec3& a) const { return 0; }", "Foo"), 1);
  EXPECT_EQ(CountDefinitions("x = Foo(a); if (Foo(b)) { y = MyFoo(c); } obj.Foo(d) {", "Foo"), 0);
}

TEST(RuntimeOneSource, EachRuntimeFunctionIsDefinedOnceInTheHandMaintainedTree) {
  const fs::path root = SKYBAKE_SOURCE_DIR;
  const std::set<std::string> names = RuntimeFunctionNames(root / "shaders_runtime");
  // The runtime's entry points and a sample of its internals must be found,
  // or the scan below would pass vacuously.
  for (const char* expected : {"GetSkyRadiance", "GetSkyRadianceToPointWithShadow", "GetSunAndSkyIrradiance",
                               "GetScatteringTextureUvwzFromRMuMuSNu", "RayleighPhaseFunction", "SafeSqrt"}) {
    EXPECT_TRUE(names.count(expected)) << expected;
  }
  ASSERT_GE(names.size(), 50u);
  std::map<std::string, std::vector<std::string>> defined_in;
  const std::vector<fs::path> files = HandMaintainedSources(root);
  ASSERT_GE(files.size(), 100u);
  for (const fs::path& file : files) {
    const std::string text = testing::ReadText(file);
    for (const std::string& name : names) {
      for (int k = CountDefinitions(text, name); k > 0; --k) {
        defined_in[name].push_back(fs::relative(file, root).string());
      }
    }
  }
  // Each function lives in one GLSL source of the runtime (overloads, such as
  // a scalar and a vec3 form, side by side in it) and nowhere else.
  for (const std::string& name : names) {
    const std::vector<std::string>& where = defined_in[name];
    std::string list;
    for (const std::string& w : where) list += " " + w;
    ASSERT_FALSE(where.empty()) << name;
    for (const std::string& w : where) {
      EXPECT_EQ(w, where[0]) << name << " is defined in:" << list;
      EXPECT_EQ(fs::path(w).parent_path(), "shaders_runtime") << name << " is defined in:" << list;
      EXPECT_EQ(fs::path(w).extension(), ".glsl") << name << " is defined in:" << list;
    }
  }
}

// The translations say they are generated and from what, so that nobody
// maintains them by hand.
TEST(RuntimeOneSource, TranslationsAreMarkedGenerated) {
  const fs::path generated = fs::path(SKYBAKE_SOURCE_DIR) / "shaders_runtime" / "generated";
  int files = 0;
  for (const auto& entry : fs::directory_iterator(generated)) {
    ++files;
    const std::string text = testing::ReadText(entry.path());
    EXPECT_NE(text.find("generated by shaders_runtime/translate/translate.mjs"), std::string::npos)
        << entry.path();
    EXPECT_NE(text.find("Do not edit"), std::string::npos) << entry.path();
  }
  EXPECT_EQ(files, 5);
}

}  // namespace
}  // namespace skybake
