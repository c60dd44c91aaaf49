#include "report/quality_ladder.h"

#include <chrono>
#include <cstdio>

#include <Imath/half.h>

#include "core/errors.h"
#include "formats/lut_files.h"
#include "formats/settings_record.h"
#include "report/run_time_models.h"

namespace skybake::report {

namespace {

// Half of a size, kept at the setting's minimum (and even where it must be).
int Halved(int size, int minimum, bool even = false) {
  int half = std::max(size / 2, minimum);
  return even && half % 2 ? half + 1 : half;
}

struct Knob {
  std::string name;
  std::function<void(BakeSettings&, bool doubled)> scale;
};

std::vector<Knob> Knobs(bool quick) {
  std::vector<Knob> knobs = {
      {"transmittance+irradiance size",
       [](BakeSettings& s, bool doubled) {
         for (int* size : {&s.transmittance_width, &s.transmittance_height, &s.irradiance_width,
                           &s.irradiance_height}) {
           *size = doubled ? *size * 2 : Halved(*size, 2);
         }
       }},
  };
  if (quick) return knobs;
  knobs.push_back({"scattering r size", [](BakeSettings& s, bool doubled) {
                     s.scattering_r_size = doubled ? s.scattering_r_size * 2 : Halved(s.scattering_r_size, 2);
                   }});
  knobs.push_back({"scattering mu size", [](BakeSettings& s, bool doubled) {
                     s.scattering_mu_size = doubled ? s.scattering_mu_size * 2 : Halved(s.scattering_mu_size, 4, true);
                   }});
  knobs.push_back({"scattering mu_s+nu size", [](BakeSettings& s, bool doubled) {
                     s.scattering_mu_s_size = doubled ? s.scattering_mu_s_size * 2 : Halved(s.scattering_mu_s_size, 2);
                     s.scattering_nu_size = doubled ? s.scattering_nu_size * 2 : Halved(s.scattering_nu_size, 2);
                   }});
  knobs.push_back({"ray samples", [](BakeSettings& s, bool doubled) {
                     s.ray_samples = doubled ? s.ray_samples * 2 : Halved(s.ray_samples, 2);
                   }});
  knobs.push_back({"sphere samples", [](BakeSettings& s, bool doubled) {
                     s.sphere_samples = doubled ? s.sphere_samples * 2 : Halved(s.sphere_samples, 2);
                   }});
  return knobs;
}

struct Written {
  double seconds = 0.0;
  std::uint64_t bytes = 0;
};

Written WriteTables(const LutSet& tables, const std::filesystem::path& dir, bool half) {
  WriteOptions options;
  options.half = half;
  auto start = std::chrono::steady_clock::now();
  WriteReport report = WriteLutSet(tables, dir, options);
  Written w;
  w.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  for (const WrittenFile& f : report.files) w.bytes += f.bytes;
  return w;
}

// A bake and the write of its set, without the runtime and the command
// line, so that every configuration writes the files a plain `skybake bake`
// of it would: the tables and the manifest, float, EXR and KTX2.
struct LadderBake {
  LutSet tables;
  BakeReport report;
  double bake_seconds = 0.0;  // the phases before the write
  Written files;
};

// Each timed.
LadderBake BakeAndWriteTables(const Atmosphere& atmosphere, const BakeSettings& settings,
                              const std::filesystem::path& dir) {
  LadderBake b;
  b.tables = Bake(atmosphere, settings, &b.report);
  b.bake_seconds = b.report.total_seconds;
  const auto write_start = std::chrono::steady_clock::now();
  const WriteReport written = WriteLutSet(b.tables, dir, WriteOptions{});
  b.files.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - write_start).count();
  for (const WrittenFile& f : written.files) b.files.bytes += f.bytes;
  return b;
}

std::vector<GroupErrors> MeasureTables(const LutSet& tables, const ReferenceSet& reference) {
  Twin twin(MakeTwinTables(tables));
  return MeasureErrors(reference, [&](const ReferenceCase& c) { return EvaluateTwin(twin, c); });
}

}  // namespace

LadderPlan MakeLadder(const BakeSettings& base, bool quick) {
  LadderPlan plan;
  plan.base = base;
  plan.max_orders = quick ? 3 : 8;
  // The base is baked on its own, so any count of orders serves; the ladder's
  // orders 1..max_orders come from a separate bake.
  if (base.orders < 1) throw UsageError("--orders: the report's base bake needs a count of orders, not auto");
  for (const Knob& knob : Knobs(quick)) {
    for (bool doubled : {false, true}) {
      LadderStep step;
      step.knob = knob.name;
      step.name = knob.name + (doubled ? " x2" : " x1/2");
      step.settings = base;
      knob.scale(step.settings, doubled);
      step.settings.Validate();
      plan.variants.push_back(step);
    }
  }
  if (!quick) {
    // The preview bake (skybake bake --preview) of the base: its smaller
    // tables and fewer samples at once, the point a live editor works at.
    LadderStep preview;
    preview.knob = "preview";
    preview.name = "preview (--preview)";
    preview.settings = PreviewBakeSettings(base);
    preview.settings.Validate();
    plan.variants.push_back(preview);
  }
  LadderStep half;
  half.knob = "storage";
  half.name = "half";
  half.settings = base;
  half.half = true;
  plan.variants.push_back(half);
  return plan;
}

LutSet RoundToHalf(LutSet tables) {
  for (glsl::Texture* t : {&tables.transmittance, &tables.irradiance, &tables.scattering,
                           &tables.single_mie_scattering}) {
    for (float& v : t->texels) v = static_cast<float>(Imath::half(v));
  }
  return tables;
}

std::vector<LadderEntry> RunLadder(const Atmosphere& atmosphere, const LadderPlan& plan,
                                   const ReferenceSet& reference, const std::filesystem::path& scratch_dir,
                                   const std::function<void(const std::string&)>& progress, LutSet* base_tables) {
  auto say = [&](const std::string& line) {
    if (progress) progress(line);
  };
  std::vector<LadderEntry> entries;

  // The base: exactly what `skybake bake` makes with these settings (with the
  // extrapolated tail of the orders it does not compute, by default).
  say("bake the base: " + DescribeSettings(plan.base, SettingsDetail::kSamples));
  LadderBake base_bake = BakeAndWriteTables(atmosphere, plan.base, scratch_dir);
  LutSet& base = base_bake.tables;
  const BakeReport& base_report = base_bake.report;
  const Written& base_files = base_bake.files;
  const double base_bake_seconds = base_bake.bake_seconds;
  {
    LadderEntry e;
    e.step.knob = "base";
    e.step.name = "orders " + std::to_string(plan.base.orders) + (base_report.extrapolated_tail > 0.0 ? " + tail" : "");
    e.step.settings = plan.base;
    e.is_base = true;
    e.bake_seconds = base_bake_seconds + base_files.seconds;
    e.bytes = base_files.bytes;
    e.errors = MeasureTables(base, reference);
    entries.push_back(e);
  }

  // Orders 1..max, exactly that many each (no tail), from one bake.
  BakeSettings orders_settings = plan.base;
  orders_settings.orders = plan.max_orders;
  orders_settings.extrapolate_tail = false;
  say("bake " + DescribeSettings(plan.base, SettingsDetail::kSamples) + ", orders 1-" +
      std::to_string(plan.max_orders) + " without the tail");
  Bake(atmosphere, orders_settings, nullptr, nullptr, {[&](int order, const LutSet& tables, double seconds) {
    LadderEntry e;
    e.step.knob = "orders";
    e.step.name = "orders " + std::to_string(order) + (order > 1 ? ", no tail" : "");
    e.step.settings = tables.settings;
    e.bake_seconds = seconds + base_files.seconds;
    e.bytes = base_files.bytes;
    e.errors = MeasureTables(tables, reference);
    entries.push_back(e);
    char line[64];
    std::snprintf(line, sizeof line, "order %d done after %.1f s", order, seconds);
    say(line);
  }});

  for (const LadderStep& step : plan.variants) {
    LadderEntry e;
    e.step = step;
    if (step.half) {
      say("half storage of the base tables");
      Written w = WriteTables(base, scratch_dir, true);
      e.bake_seconds = base_bake_seconds + w.seconds;
      e.bytes = w.bytes;
      e.errors = MeasureTables(RoundToHalf(base), reference);
    } else {
      say("bake " + step.name + ": " + DescribeSettings(step.settings, SettingsDetail::kSamples));
      const LadderBake b = BakeAndWriteTables(atmosphere, step.settings, scratch_dir);
      e.bake_seconds = b.bake_seconds + b.files.seconds;
      e.bytes = b.files.bytes;
      e.errors = MeasureTables(b.tables, reference);
    }
    entries.push_back(e);
  }
  if (base_tables) *base_tables = std::move(base);
  return entries;
}

}  // namespace skybake::report
