// Incremental bakes: everything that determines the files of a bake, as one
// hash the manifest records ("inputs_sha256", docs/manifest.md), and the test
// that a set on disk is up to date for a bake's inputs, so that `skybake
// bake` can skip it in milliseconds (BakeAndWrite; `--force` bakes anyway).
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "bake/atmosphere.h"
#include "bake/scene.h"
#include "bake/spectral.h"
#include "formats/lut_files.h"
#include "formats/manifest.h"
#include "pipeline/bake_pipeline.h"

namespace skybake::pipeline {

// The SHA-256 (hex) of a canonical JSON document of what determines the
// files of `job`'s set:
// - the program's version (SKYBAKE_VERSION: a build of changed sources that
//   keeps the version is not told apart; --force);
// - the atmosphere as resolved, its canonical TOML (ToToml), not the file's
//   bytes: comments, spacing, key order and the units a value is written in
//   do not count, the values they resolve to do; for a spectral bake
//   (`batches`) also the atmosphere resolved at each batch's wavelengths,
//   which is what it bakes, the wavelengths and how the higher orders are
//   computed;
// - every bake setting but the thread count (the files are byte-identical
//   at any);
// - the scene as resolved (SceneToJson), where there is one;
// - what the writer makes of the tables: the formats, half (and a scene's
//   half tables), the KTX2 supercompression level, the runtime's languages.
// Not the command line (the manifest records it; it changes no table),
// --clean, --json, -q, or the output folder's name.
std::string BakeInputsSha256(const Atmosphere& atmosphere, const BakeJob& job, const SpectralBatches* batches,
                             const Scene* scene, const WriteOptions& write_options);

// The manifest of the set in `dir` if that set is up to date for inputs
// hashed as `inputs_sha256`: the manifest records the same hash and every
// file it lists is there, a regular file of the recorded size. The files'
// SHA-256 are not recomputed: hashing the default set's 58 MB of tables
// takes 30-50 ms of CPU alone, most of what a skipped bake may take (50
// ms), and the sizes catch what befalls a set in practice (a file deleted,
// truncated, half copied); `skybake info DIR` and every loader check the
// checksums. nullopt otherwise, also where `dir` holds no manifest or one
// that cannot be read.
std::optional<Manifest> ReadUpToDateSet(const std::filesystem::path& dir, const std::string& inputs_sha256);

}  // namespace skybake::pipeline
