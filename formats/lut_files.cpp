#include "formats/lut_files.h"

#include <algorithm>
#include <atomic>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "core/errors.h"
#include "core/file_io.h"
#include "formats/lut_tables.h"
#include "formats/manifest.h"
#include "formats/sha256.h"

namespace fs = std::filesystem;

namespace skybake {

namespace {

// The format LoadLutSet reads when none is asked for: KTX2 (no decompression)
// if it is complete on disk, else OpenEXR.
FileFormat ChooseFormat(const Manifest& manifest, const std::vector<TableDescription>& tables) {
  for (FileFormat format : {FileFormat::kKtx2, FileFormat::kExr}) {
    bool complete = true;
    for (const TableDescription& t : tables) {
      const ManifestFile* f = manifest.Find(t.name, format);
      complete = complete && f != nullptr && fs::exists(manifest.Directory() / f->file);
    }
    if (complete) return format;
  }
  // Nothing complete: take the first format listed, whose missing file then
  // makes the error.
  return manifest.table_files.empty() ? FileFormat::kExr : manifest.table_files.front().format;
}

bool IsHalf(const TableDescription& table, const WriteOptions& options) {
  return options.half ||
         std::find(options.half_tables.begin(), options.half_tables.end(), table.name) != options.half_tables.end();
}

// The staged writing of WriteLutSet.
WriteReport WriteStagedSet(const LutSet& luts, const std::vector<TableDescription>& tables, const fs::path& dir,
                           const WriteOptions& options) {
  ManifestWriter manifest(luts, options.command_line, options.inputs_sha256);
  WriteReport report;
  // The whole set is staged and renamed at the end, so a failure or an
  // interrupt part-way leaves the previous set (files and manifest) as it was.
  StagedFiles staged;
  // Each table file is encoded, hashed and written (under its temporary
  // name) by one worker, its bytes freed as soon as they are written; the
  // manifest lists them in a fixed order. The workers, one per core, take
  // the files largest first, EXR (whose encoding is most of the writing)
  // before KTX2, each taking the next file when done, so that the longest
  // encodings start at once instead of after smaller ones.
  struct Encoded {
    const TableDescription* table;
    FileFormat format;
    TableImage image;  // its values released once encoded
    std::size_t bytes = 0;
    std::string sha256;
  };
  std::vector<Encoded> files;
  for (const TableDescription& table : tables) {
    for (FileFormat format : options.formats) files.push_back({&table, format, {}, 0, {}});
  }
  std::vector<std::size_t> order(files.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  auto texels = [&](std::size_t i) {
    const TableDescription& t = *files[i].table;
    return std::size_t(t.width) * t.height * t.depth;
  };
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    if (texels(a) != texels(b)) return texels(a) > texels(b);
    return files[a].format == FileFormat::kExr && files[b].format != FileFormat::kExr;
  });
  std::atomic<std::size_t> next{0};
  const int workers = std::min<int>(int(files.size()), tbb::this_task_arena::max_concurrency());
  tbb::parallel_for(0, workers, [&](int) {
    for (std::size_t k = next++; k < order.size(); k = next++) {
      Encoded& f = files[order[k]];
      f.image = MakeTableFileImage(luts, *f.table, f.format, options);
      const std::vector<std::uint8_t> bytes = EncodeTableImage(f.image);
      f.image.values = {};
      f.bytes = bytes.size();
      f.sha256 = Sha256Hex(bytes.data(), bytes.size());
      staged.Write(dir / (f.table->name + FileExtension(f.format)),
                   std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
    }
  });
  for (const Encoded& f : files) {
    const std::string file = f.table->name + FileExtension(f.format);
    manifest.AddTableFile(*f.table, file, f.image, f.bytes, f.sha256);
    report.files.push_back({f.table->name, file, f.bytes});
  }
  for (const TableDescription& table : tables) {
    if (IsHalf(table, options)) {
      const TableImage image = MakeTableImage(luts, table, options.formats.front(), PixelType::kFloat);
      report.half_errors.emplace_back(table.name, MeasureHalfError(image.values.data(), image.values.size()));
    }
  }
  for (const ShaderFile& shader : options.shaders) {
    staged.Write(dir / shader.file, shader.text);
    manifest.AddShaderFile(shader.file, shader.text, shader.description);
    report.files.push_back({"", shader.file, shader.text.size()});
  }
  // Last, so a reader that finds the new manifest finds the files it lists.
  const std::string text = manifest.Text();
  staged.Write(dir / kManifestFileName, text);
  staged.Commit();
  report.files.push_back({"", kManifestFileName, text.size()});
  return report;
}

std::string NameList(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : ", ") + name;
  return text;
}

}  // namespace

TableImage MakeTableFileImage(const LutSet& luts, const TableDescription& table, FileFormat format,
                              const WriteOptions& options) {
  TableImage image = MakeTableImage(luts, table, format, IsHalf(table, options) ? PixelType::kHalf : PixelType::kFloat);
  ChooseFileStorage(&image, options.ktx2_zstd_level);
  return image;
}

std::vector<std::string> SetFileNames(const LutSet& luts, const WriteOptions& options) {
  std::vector<std::string> names;
  for (const TableDescription& table : DescribeTables(luts)) {
    for (FileFormat format : options.formats) names.push_back(table.name + FileExtension(format));
  }
  for (const ShaderFile& shader : options.shaders) names.push_back(shader.file);
  names.push_back(kManifestFileName);
  return names;
}

std::vector<std::string> StaleSetFiles(const fs::path& dir, const std::vector<std::string>& new_files, bool clean) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return {};
  const std::vector<std::string> listed = ListedFileNames(dir);
  std::vector<std::string> stale;
  for (const std::string& name : EntriesNotIn(dir, new_files)) {
    // A folder's name ends in '/', so it is never one of the listed files.
    if (std::find(listed.begin(), listed.end(), name) != listed.end() || IsTemporaryFileName(name)) {
      stale.push_back(name);
    }
  }
  if (!stale.empty() && !clean) {
    throw IoError(dir.string() + ": holds files of an earlier set that the new set would not list: " +
                      NameList(stale) + " (--clean removes them; files no skybake set listed are left alone)",
                  ErrorLocation(dir.string()));
  }
  return stale;
}

WriteReport WriteLutSet(const LutSet& luts, const fs::path& dir, const WriteOptions& options) {
  if (options.formats.empty()) throw InternalError("WriteLutSet: no file format requested");
  const std::vector<TableDescription> tables = DescribeTables(luts);
  const std::vector<std::string> stale = StaleSetFiles(dir, SetFileNames(luts, options), options.clean);

  std::error_code ec;
  const bool created = !fs::exists(dir, ec);
  EnsureWritableDirectory(dir);
  try {
    WriteReport report = WriteStagedSet(luts, tables, dir, options);
    for (const std::string& name : stale) {
      fs::remove(dir / name, ec);
      if (ec) throw IoError((dir / name).string() + ": cannot remove (--clean): " + ec.message());
    }
    return report;
  } catch (...) {
    if (created && fs::is_empty(dir, ec)) fs::remove(dir, ec);
    throw;
  }
}

LutSet LoadLutSet(const fs::path& dir, const LoadOptions& options) {
  Manifest manifest = ReadManifest(dir);
  LutSet luts = std::move(manifest.luts);
  const std::vector<TableDescription> tables = DescribeTables(luts);
  const FileFormat format = options.format ? *options.format : ChooseFormat(manifest, tables);
  for (const TableDescription& table : tables) {
    const ManifestFile* entry = manifest.Find(table.name, format);
    if (entry == nullptr) {
      throw IoError(manifest.path.string() + ": lists no " + ToString(format) + " file for the " + table.name +
                    " table (bake with --format " + ToString(format) + ")");
    }
    const fs::path path = dir / entry->file;
    const std::vector<std::uint8_t> bytes = ReadListedFile(manifest, *entry);
    const TableImage image = DecodeTableImage(bytes, path.string());
    if (image.format != entry->format || image.pixel_type != entry->pixel_type) {
      throw IoError(path.string() + ": is " + ToString(image.format) + " " + ToString(image.pixel_type) +
                    ", the manifest says " + ToString(entry->format) + " " + ToString(entry->pixel_type));
    }
    CopyTableImage(image, table, &TableTexture(luts, table.name), path.string());
  }
  return luts;
}

}  // namespace skybake
