#include "fit/report.h"

#include <cstdio>
#include <sstream>

#include <nlohmann/json.hpp>

namespace skybake::fit {

namespace {

using json = nlohmann::ordered_json;

json Json(const OpticalPathErrors& e) {
  return {{"points", e.points},
          {"max_relative", e.max_relative},
          {"rms_relative", e.rms_relative},
          {"max_relative_zenith_le_85_deg", e.max_relative_zenith_le_85},
          {"worst_at", {{"zenith_deg", e.worst_zenith_deg}, {"altitude_m", e.worst_altitude_m}}}};
}

json Coefficients(const Surface& s) {
  json c;
  auto names = ParameterNames(s.form);
  for (int k = 0; k < kShapeParameters; ++k)
    c[names[k]] = {s.coefficients[3 * k], s.coefficients[3 * k + 1], s.coefficients[3 * k + 2]};
  c["ln_tau_minus_1"] = s.coefficients[kLayerTopCoefficient];
  return c;
}

const char* Formula(FormKind kind) {
  if (kind == FormKind::kChapmanChord)
    return "m = D(1)/D(mu), D(mu) = mu + a*eps/(sqrt(mu^2 + eps) + b*mu), eps = exp(ln_epsilon(t))*(tau - t), "
           "a = exp(ln_a(t)), b = exp(ln_b(t)), tau = 1 + exp(ln_tau_minus_1)";
  return "m = 1/(mu + a*(b - theta_deg)^-c), a = exp(ln_a(t))*sqrt(tau - t), b = 90 + exp(ln_b_minus_90(t)), "
         "c = exp(ln_c(t)), tau = 1 + exp(ln_tau_minus_1)";
}

json OptionalNumber(const std::optional<double>& v) { return v ? json(*v) : json(nullptr); }

}  // namespace

std::string Provenance::OneLine() const { return "skybake " + version + ": " + command_line; }

std::string FitReportJson(const FitSet& set, const ReportContext& context) {
  json constituents = json::array();
  for (size_t i = 0; i < set.constituents.size(); ++i) {
    const ConstituentFit& c = set.constituents[i];
    json entry = {{"name", c.name},
                  {"identifier", c.identifier},
                  {"role", static_cast<int>(i) == set.air    ? json("air")
                           : static_cast<int>(i) == set.haze ? json("haze")
                                                             : json(nullptr)},
                  {"fitted", c.fitted}};
    if (!c.fitted) {
      entry["skip_reason"] = c.skip_reason;
      constituents.push_back(entry);
      continue;
    }
    const Surface& s = c.surface;
    entry["form"] = ToString(s.form);
    entry["formula"] = Formula(s.form);
    entry["altitude_range_m"] = {s.altitude_lo_m, s.altitude_hi_m};
    entry["coefficient_node_altitudes_m"] = {s.altitude_lo_m, 0.5 * (s.altitude_lo_m + s.altitude_hi_m),
                                             s.altitude_hi_m};
    entry["coefficients"] = Coefficients(s);
    entry["errors"] = {{"fit_grid", Json(c.fit_errors)}, {"validation_grid", Json(c.validation_errors)}};
    entry["iqbal_errors"] = {{"fit_grid", Json(c.iqbal_fit_errors)},
                             {"validation_grid", Json(c.iqbal_validation_errors)}};
    json candidates = json::array();
    for (const CandidateFit& k : c.candidates) {
      candidates.push_back({{"form", ToString(k.surface.form)},
                            {"coefficients", Coefficients(k.surface)},
                            {"errors", {{"fit_grid", Json(k.fit_grid)}, {"validation_grid", Json(k.validation_grid)}}},
                            {"solver", {{"final_cost", k.final_cost},
                                        {"iterations", k.iterations},
                                        {"termination", k.termination}}}});
    }
    entry["candidates"] = candidates;
    json lengths = json::array();
    for (const ZenithOpticalLength& z : c.zenith_optical_length)
      lengths.push_back({{"altitude_m", z.altitude_m}, {"value_m", OptionalNumber(z.value_m)}});
    entry["zenith_optical_length_m"] = lengths;
    json samples = json::array();
    for (const OpticalPathSample& p : c.samples)
      samples.push_back({{"zenith_deg", p.zenith_deg},
                         {"altitude_m", p.altitude_m},
                         {"relative_optical_path", p.relative_optical_path},
                         {"optical_length_m", OptionalNumber(p.optical_length_m)}});
    entry["exact_samples"] = samples;
    entry["unconverged_quadratures"] = c.unconverged_samples;
    constituents.push_back(entry);
  }

  json forms = json::array();
  for (FormKind f : set.options.forms) forms.push_back(ToString(f));
  json mesh = nullptr;
  if (context.mesh) {
    mesh = {{"air", context.mesh->air_name},
            {"haze", context.mesh->haze_name.empty() ? json(nullptr) : json(context.mesh->haze_name)},
            {"altitude_m", context.mesh->altitude_m},
            {"air_zenith_optical_length_m", context.mesh->air_zenith_optical_length_m},
            {"vertices", context.mesh->vertex_count()},
            {"triangles", context.mesh->indices.size() / 3}};
  }
  json report = {
      {"generated_by", {{"tool", "skybake"}, {"version", context.provenance.version},
                        {"command_line", context.provenance.command_line}}},
      {"atmosphere", {{"name", set.atmosphere_name},
                      {"bottom_radius_m", set.bottom_radius_m},
                      {"top_radius_m", set.top_radius_m}}},
      {"target", "relative_optical_path"},
      {"target_definition",
       "m(theta, h) = slant column / vertical column above the observer; optical length R(theta, h) = "
       "m(theta, h) * zenith_optical_length_m(h) where the density at h is non-zero"},
      {"zenith_range_deg", {0.0, 90.0}},
      {"requested_altitude_range_m", {set.options.altitude_min_m, set.options.altitude_max_m}},
      {"forms_tried", forms},
      {"selection", "lowest max_relative error on the validation grid"},
      {"grids",
       {{"fit", {{"zenith_deg", set.fit_zenith_deg}, {"altitudes", set.options.fit_altitudes | 1}}},
        {"validation", {{"zenith_step_deg", set.options.validation_zenith_step_deg},
                        {"altitudes", set.options.validation_altitudes}}}}},
      {"quadrature_relative_tolerance", set.options.quadrature.relative_tolerance},
      {"constituents", constituents},
      {"mesh", mesh},
      {"outputs", context.outputs}};
  if (!context.mesh_note.empty()) report["mesh_note"] = context.mesh_note;
  return report.dump(2) + "\n";
}

std::string ErrorTable(const FitSet& set) {
  std::ostringstream o;
  char line[512];
  std::snprintf(line, sizeof(line), "%-14s %-14s %-17s %9s %9s %9s %9s %9s | %9s %9s\n", "constituent", "form",
                "altitudes (m)", "fit max", "fit rms", "val max", "val rms", "val<=85", "iqbal max", "iqbal rms");
  o << "relative error of m = slant/vertical column (fit grid and denser validation grid)\n" << line;
  for (const ConstituentFit& c : set.constituents) {
    if (!c.fitted) {
      std::snprintf(line, sizeof(line), "%-14s not fitted: %s\n", c.name.c_str(), c.skip_reason.c_str());
      o << line;
      continue;
    }
    char range[64];
    std::snprintf(range, sizeof(range), "%.0f-%.0f", c.surface.altitude_lo_m, c.surface.altitude_hi_m);
    std::snprintf(line, sizeof(line), "%-14s %-14s %-17s %9.2e %9.2e %9.2e %9.2e %9.2e | %9.2e %9.2e\n",
                  c.name.c_str(), ToString(c.surface.form), range, c.fit_errors.max_relative,
                  c.fit_errors.rms_relative, c.validation_errors.max_relative, c.validation_errors.rms_relative,
                  c.validation_errors.max_relative_zenith_le_85, c.iqbal_validation_errors.max_relative,
                  c.iqbal_validation_errors.rms_relative);
    o << line;
  }
  bool any = false;
  for (const ConstituentFit& c : set.constituents) {
    if (c.candidates.size() < 2) continue;
    if (!any) o << "candidate forms (validation max):";
    any = true;
    o << " " << c.name << ":";
    for (const CandidateFit& k : c.candidates) {
      std::snprintf(line, sizeof(line), " %s %.2e", ToString(k.surface.form), k.validation_grid.max_relative);
      o << line;
    }
    o << ";";
  }
  if (any) o << "\n";
  if (set.constituents.empty()) o << "nothing to fit: the atmosphere has no (selected) constituents\n";
  return o.str();
}

}  // namespace skybake::fit
