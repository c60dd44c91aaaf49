#include "plot/image_library.h"

#include <dlfcn.h>

#include <filesystem>
#include <string>
#include <vector>

#include "core/errors.h"

namespace skybake {

namespace {

// Where the module is looked for, in order: installed beside the running
// executable's bin/ (PREFIX/lib/skybake), then the build tree's lib/.
std::vector<std::filesystem::path> ModuleCandidates() {
  const char* name = "libskybake_images.so";
  std::vector<std::filesystem::path> candidates;
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) candidates.push_back(exe.parent_path().parent_path() / SKYBAKE_INSTALL_LIBDIR / "skybake" / name);
  candidates.push_back(std::filesystem::path(SKYBAKE_IMAGE_MODULE_DIR) / name);
  return candidates;
}

const image_module::Functions& Load() {
  std::filesystem::path file;
  void* handle = nullptr;
  std::string tried;
  for (const std::filesystem::path& candidate : ModuleCandidates()) {
    file = candidate;
    handle = dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (handle != nullptr) break;
    tried += std::string(tried.empty() ? "" : "; ") + dlerror();
  }
  if (handle == nullptr) {
    throw IoError("cannot load the image module libskybake_images.so (" + tried +
                  "); build the skybake_images target");
  }
  using Entry = const image_module::Functions* (*)();
  auto entry = reinterpret_cast<Entry>(dlsym(handle, "SkybakeImageModule"));
  const image_module::Functions* functions = entry == nullptr ? nullptr : entry();
  if (functions == nullptr || functions->version != image_module::kVersion) {
    throw IoError(file.string() + ": is not this build's image module (rebuild the skybake_images target)");
  }
  // Never unloaded: the functions are used until the process ends.
  return *functions;
}

}  // namespace

const image_module::Functions& ImageModule() {
  static const image_module::Functions& functions = Load();
  return functions;
}

void ThrowIfImageError(const std::filesystem::path& path, const std::string& error) {
  if (!error.empty()) throw IoError(path.string() + ": " + error);
}

}  // namespace skybake
