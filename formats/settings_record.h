// BakeSettings as the outputs record them: one JSON writer and one one-line
// text writer, so that every output spells a setting the same way (orders as
// a count or "auto", table sizes as arrays or as WxH). Each output keeps the
// fields and names its readers know (docs/manifest.md, docs/report.md,
// `bake --json`), chosen by SettingsFields and SettingsDetail.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "bake/bake.h"

namespace skybake {

enum class SettingsFields {
  // skybake.json "bake": orders asked for and used, the tail, the samples,
  // the higher-order divisor and the packing (the sizes are the tables').
  kManifest,
  // `bake --json`: orders, order tolerance, table sizes by table ("tables",
  // single_mie_scattering null when packed) and samples by integral ("samples").
  kBakeReport,
  // report.json rows: the table sizes and the knobs the quality ladder turns.
  kReportRow,
};

// The fields of `fields`, in the order written; `orders_used` only for
// kManifest (what the tables hold, where the orders are auto).
nlohmann::ordered_json SettingsJson(const BakeSettings& s, SettingsFields fields, int orders_used = 0);

enum class SettingsDetail {
  kOrdersAndThreads,  // `bench`: "T 256x64, E 64x16, S 32x128x32x8, 4 orders, all cores"
  kSamples,           // the report's ladder: "T ..., 128 ray / 16 sphere samples, orders >= 2 at 1/1"
};

// The table sizes (T transmittance, E irradiance, S scattering) and the
// detail asked for, on one line.
std::string DescribeSettings(const BakeSettings& s, SettingsDetail detail);

}  // namespace skybake
