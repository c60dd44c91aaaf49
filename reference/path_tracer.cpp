// The reference path tracer. One wavelength at a time: each of the three
// wavelengths traces its own paths, with free paths sampled from its own
// extinction, so every weight stays bounded by single-scattering albedos and
// ground albedos and the three estimates (and their errors) are independent.
// (A single path shared by the wavelengths would need spectral MIS to keep
// the ratios of transmittances between 440 and 680 nm, a factor of e^-5
// along a low horizon ray, from blowing up the variance.)
#include "reference/path_tracer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "bake/bake.h"
#include "bake/config.h"
#include "core/constants.h"
#include "core/errors.h"
#include "reference/phase_sampling.h"
#include "reference/random.h"
#include "reference/ray_segment.h"
#include "shaders_runtime/runtime.h"

namespace skybake::reference {

namespace {

using glm::dvec3;

// Ray segments at the start of each path that use a forced collision: the
// first only, as forcing later ones costs as much time as it saves variance
// in daylight (docs/reference.md). In twilight, when direction guides are
// built, every segment that escapes to space is forced: an analog flight
// would rarely stop in the thin lit shell.
constexpr int kForcedSegments = 1;

// On the view ray and the forced segments, distances are drawn from a
// mixture: with this share from extinction x transmittance, otherwise from
// that density weighted by an estimate of the light scattered toward the
// ray at each piece (SourcePieces; on a daylight path's forced segment, the
// sunlight alone, SunlitPieces), so that after sunset, when only a thin
// high shell is lit, paths still find it.
constexpr double kUnguidedShare = 0.5;

// Directions after a scattering event are drawn from a mixture with the same
// aim: with this share from the phase function, otherwise from the
// direction guides around the vertex (GuideMixture), when the sun's zenith
// cosine where the view ray starts is below kGuideSunCosine (in daylight
// the phase function alone does well). The guides hold kGuideOrders orders
// of scattered light: a third changed nothing measurable (docs/reference.md).
constexpr double kPhaseShare = 0.25;
constexpr double kGuideSunCosine = 0.1;
constexpr int kGuideOrders = 2;

// In twilight Russian roulette keeps at least this share of the paths it
// tests: with survival w / w0 alone, a path whose weight fell a hundredfold
// on its way up through thin air came back once in a hundred with a
// hundredfold weight, the heavy tail of the deep-twilight estimates.
constexpr double kTwilightSurvival = 0.5;

enum Estimator : uint64_t { kRadianceEstimator = 1, kIrradianceEstimator = 2 };

struct Tally {
  int64_t vertices = 0;
  int64_t truncated = 0;
};

// The path logic at one wavelength.
class Tracer {
 public:
  Tracer(const LayeredMedium& medium, const SunlightTable& sunlight, const DirectionGuideField* directions,
         const Settings& settings, const dvec3& sun, int wavelength)
      : medium_(medium),
        sunlight_(sunlight),
        directions_(directions),
        settings_(settings),
        sun_(sun),
        w_(wavelength),
        solar_(medium.atmosphere().solar_irradiance[wavelength]),
        albedo_(medium.atmosphere().ground_albedo[wavelength]),
        sigma_(medium.constituent_count()) {}

  // Sky radiance along the view segment, one path; u stratifies the distance
  // of its first vertex.
  double Radiance(const RaySegment& view, const dvec3& direction, const RaySegment::Mixture& view_density, double u,
                  Pcg32& rng, Tally& tally) {
    double t, weight;
    if (!view.SampleMixture(medium_, view_density, u, &t, &weight)) return 0.0;
    dvec3 x = view.origin() + t * direction;
    double r = RadiusAlongRay(view.r(), view.mu(), t);
    double sigma_s = medium_.Scattering(r, w_, sigma_.data());
    ++tally.vertices;
    return Trace(x, r, direction, weight * sigma_s, sigma_s, 1, true, rng, tally);
  }

  // Radiance arriving at `camera` from `direction`, times `weight`.
  double Incoming(const dvec3& camera, const dvec3& direction, double weight, Pcg32& rng, Tally& tally) {
    const glsl::AtmosphereParameters& g = medium_.geometry();
    double r = glm::length(camera);
    double mu = std::clamp(glm::dot(camera, direction) / r, -1.0, 1.0);
    double t_in, t_out;
    if (!InsideTopSphere(g, r, mu, &t_in, &t_out)) return 0.0;
    return Trace(camera + t_in * direction, 0.0, direction, weight, 0.0, 0, false, rng, tally);
  }

  // The direction guides around the point x (none without a field).
  GuideMixture GuideAt(const dvec3& x) const {
    if (!directions_) return GuideMixture();
    const double r = glm::length(x);
    return directions_->At(r, glm::dot(x, sun_) / r);
  }

  // Per piece of `segment` (along `direction`), the tabulated sunlight at
  // its middle.
  std::vector<double> SunlitPieces(const RaySegment& segment, const dvec3& direction) const {
    std::vector<double> weights;
    for (double t : segment.PieceMiddles()) {
      const dvec3 x = segment.origin() + t * direction;
      const double r = glm::length(x);
      weights.push_back(sunlight_.At(r, glm::dot(x, sun_) / r)[w_]);
    }
    return weights;
  }

  // Per piece of `segment` (along `direction`), an estimate at its middle of
  // the light a vertex there scatters into the ray: the sunlight
  // (SunlitPieces) times the phase function, plus the light the direction
  // guides there say arrives, spread evenly over the sphere: the guide of
  // MakeMixture.
  std::vector<double> SourcePieces(const RaySegment& segment, const dvec3& direction) {
    std::vector<double> weights = SunlitPieces(segment, direction);
    const std::vector<double> middles = segment.PieceMiddles();
    for (std::size_t k = 0; k < middles.size(); ++k) {
      const dvec3 x = segment.origin() + middles[k] * direction;
      const double sigma_s = medium_.Scattering(glm::length(x), w_, sigma_.data());
      const double direct = sigma_s > 0.0 ? PhaseMixture(glm::dot(sun_, direction), sigma_s) : 0.0;
      const GuideMixture guide = GuideAt(x);
      weights[k] = direct * weights[k] + (guide.usable() ? guide.Incoming() / (4.0 * kPi) : 0.0);
    }
    return weights;
  }

  // E_sun x visible fraction of the disc x transmittance to the top, seen
  // from radius r where the sun's zenith cosine is mu_s.
  double Sunlight(double r, double mu_s, Pcg32& rng) const {
    const glsl::AtmosphereParameters& g = medium_.geometry();
    r = std::clamp(r, g.bottom_radius, g.top_radius);
    double visible = glsl::SunVisibleFraction(g, r, mu_s);
    if (!(visible > 0.0) || solar_ == 0.0) return 0.0;
    double mu = SunRayCosine(g, r, mu_s);
    double length = glsl::DistanceToTopAtmosphereBoundary(g, r, mu);
    double transmittance =
        settings_.sun_transmittance == SunTransmittanceMethod::kQuadrature
            ? std::exp(-medium_.OpticalDepth(r, mu, 0.0, length, kVertexTolerance).value[w_])
            : medium_.RatioTrackingTransmittance(r, mu, length, w_, rng);
    return solar_ * visible * transmittance;
  }

 private:
  bool Continues(int events, Tally& tally) const {
    if (settings_.max_order > 0) return events < settings_.max_order;
    if (events < kMaxEventsPerPath) return true;
    ++tally.truncated;
    return false;
  }

  // Russian roulette against the weight the path started with: survival
  // probability q = weight / reference (at least kTwilightSurvival in
  // twilight), survivors weighted by 1 / q.
  bool Survives(double& weight, double reference, Pcg32& rng) const {
    if (!(weight > 0.0)) return false;
    double q = weight / reference;
    if (q >= 1.0) return true;
    if (directions_) q = std::max(q, kTwilightSurvival);
    if (rng.Uniform() >= q) return false;
    weight /= q;
    return true;
  }

  double PhaseMixture(double cos_theta, double sigma_s) const {
    double p = 0.0;
    for (int c = 0; c < medium_.constituent_count(); ++c) {
      if (sigma_[c] > 0.0) p += sigma_[c] * medium_.phase(c).Evaluate(cos_theta);
    }
    return p / sigma_s;
  }

  // Follows a path. If `at_vertex`, it starts at a scattering vertex at x
  // (radius r) reached along `direction`, `weight` multiplying the integral
  // of phase x incident radiance there (sigma_ holds the scattering
  // coefficients); otherwise it starts with a ray from x along `direction`,
  // `weight` multiplying the radiance arriving along it. `events` counts the
  // scattering and reflection events so far.
  double Trace(dvec3 x, double r, dvec3 direction, double weight, double sigma_s, int events, bool at_vertex,
               Pcg32& rng, Tally& tally) {
    const glsl::AtmosphereParameters& g = medium_.geometry();
    const double reference = weight;
    int forced = directions_ ? kMaxEventsPerPath : kForcedSegments;
    double sum = 0.0;
    for (;;) {
      if (at_vertex) {
        if (!(sigma_s > 0.0)) return sum;
        double mu_s = std::clamp(glm::dot(x, sun_) / glm::length(x), -1.0, 1.0);
        double sunlight = Sunlight(r, mu_s, rng);
        if (sunlight > 0.0) sum += weight * PhaseMixture(glm::dot(sun_, direction), sigma_s) * sunlight;
        if (!Continues(events, tally) || !Survives(weight, reference, rng)) return sum;
        // Choose the constituent in proportion to its scattering, then its
        // phase: the pdf is the mixture phase, so the weight is unchanged.
        double pick = rng.Uniform() * sigma_s;
        int c = -1;
        for (int i = 0; i < medium_.constituent_count(); ++i) {
          if (!(sigma_[i] > 0.0)) continue;
          c = i;  // the last scatterer catches rounding at the top of the range
          if (pick < sigma_[i]) break;
          pick -= sigma_[i];
        }
        const GuideMixture guide = GuideAt(x);
        const GuideFrame frame = guide.usable() ? GuideFrame(x, sun_) : GuideFrame();
        dvec3 next;
        if (guide.usable() && rng.Uniform() >= kPhaseShare) {
          const double u_guide = rng.Uniform(), u_cell = rng.Uniform(), u1 = rng.Uniform();
          next = guide.Sample(frame, u_guide, u_cell, u1, rng.Uniform());
        } else {
          next = DirectionAround(direction, SamplePhaseCosine(medium_.phase(c), rng), rng.Uniform());
        }
        if (guide.usable()) {
          // The mixture's density against the phase function it stands for.
          const double phase = PhaseMixture(glm::dot(direction, next), sigma_s);
          weight *= phase / (kPhaseShare * phase + (1.0 - kPhaseShare) * guide.Pdf(frame, next));
        }
        direction = next;
        at_vertex = false;
      }

      if (forced > 0) {
        // Forced collision: on a ray that escapes to space, an analog free
        // flight would find nothing with probability T (often > 0.8);
        // sampling the distance within the segment instead multiplies the
        // weight by 1 - T and never wastes the path. Rays toward the ground
        // keep the analog choice between the medium and the ground.
        --forced;
        RaySegment segment(medium_, x, direction, 0.0, RaySegment::Table::kSampling);
        if (!segment.hits_ground()) {
          double t, transmittance_over_pdf;
          const RaySegment::Mixture density = segment.MakeMixture(
              w_, directions_ ? SourcePieces(segment, direction) : SunlitPieces(segment, direction), kUnguidedShare);
          if (!segment.SampleMixture(medium_, density, rng.Uniform(), &t, &transmittance_over_pdf)) return sum;
          ++events;
          ++tally.vertices;
          x = segment.origin() + t * direction;
          r = RadiusAlongRay(segment.r(), segment.mu(), t);
          sigma_s = medium_.Scattering(r, w_, sigma_.data());
          weight *= transmittance_over_pdf * sigma_s;
          at_vertex = true;
          continue;
        }
      }

      double r_x = glm::length(x);
      double mu = std::clamp(glm::dot(x, direction) / r_x, -1.0, 1.0);
      RayEvent event = medium_.SampleFreeFlight(r_x, mu, std::numeric_limits<double>::infinity(), w_, rng);
      if (event.end == RayEnd::kSpace || event.end == RayEnd::kLimit) return sum;
      ++events;
      ++tally.vertices;
      if (event.end == RayEnd::kGround) {
        dvec3 normal = glm::normalize(x + event.distance * direction);
        x = normal * g.bottom_radius;
        if (!(albedo_ > 0.0)) return sum;
        double mu_s = std::clamp(glm::dot(normal, sun_), -1.0, 1.0);
        if (mu_s > 0.0) sum += weight * albedo_ / kPi * Sunlight(g.bottom_radius, mu_s, rng) * mu_s;
        if (!Continues(events, tally)) return sum;
        weight *= albedo_;
        if (!Survives(weight, reference, rng)) return sum;
        double u1 = rng.Uniform(), u2 = rng.Uniform();
        direction = SampleCosineHemisphere(normal, u1, u2);
        continue;
      }
      x += event.distance * direction;
      r = RadiusAlongRay(r_x, mu, event.distance);
      sigma_s = medium_.Scattering(r, w_, sigma_.data());
      weight *= sigma_s / event.extinction;
      at_vertex = true;
    }
  }

  const LayeredMedium& medium_;
  const SunlightTable& sunlight_;
  const DirectionGuideField* directions_;  // null: phase sampling alone
  const Settings& settings_;
  dvec3 sun_;
  int w_;
  double solar_, albedo_;
  std::vector<double> sigma_;  // per-constituent scattering at the current vertex
};

// Directions for the sky irradiance: a mixture of cosine-weighted sampling
// about the normal and a lobe around the sun (the most forward-peaked phase
// function of the atmosphere), combined by the mixture pdf (one-sample MIS,
// balance heuristic), so the bright circumsolar sky is not left to chance;
// in twilight half of the directions come from the direction guides at the
// camera, which know that the light comes from the lit air low toward the
// sun.
class IrradianceSampler {
 public:
  IrradianceSampler(const LayeredMedium& medium, const dvec3& normal, const dvec3& sun)
      : normal_(normal), sun_(sun) {
    for (int c = 0; c < medium.constituent_count(); ++c) {
      const PhaseFunction& p = medium.phase(c);
      bool lobed = p.kind == PhaseKind::kHenyeyGreenstein || p.kind == PhaseKind::kCornetteShanks;
      if (lobed && p.g > 0.3 && (!has_lobe_ || p.g > lobe_.g)) {
        lobe_ = p;
        has_lobe_ = true;
      }
    }
    lobe_probability_ = has_lobe_ ? kLobeProbability : 0.0;
  }

  // A direction from the stratified (u1, u2) and the technique choice u,
  // with the guides `guide` in `frame` where usable; `weight` = cos / pdf (0
  // below the surface).
  dvec3 Sample(double u, double u1, double u2, const GuideMixture& guide, const GuideFrame& frame, Pcg32& rng,
               double* weight) const {
    const double guide_share = guide.usable() ? kGuideShare : 0.0;
    dvec3 direction;
    if (u < guide_share) {
      const double u_guide = rng.Uniform(), u_cell = rng.Uniform(), v1 = rng.Uniform();
      direction = guide.Sample(frame, u_guide, u_cell, v1, rng.Uniform());
    } else {
      u = (u - guide_share) / (1.0 - guide_share);
      direction = u < lobe_probability_ ? DirectionAround(sun_, SamplePhaseCosine(lobe_, rng), u2)
                                        : SampleCosineHemisphere(normal_, u1, u2);
    }
    double cosine = glm::dot(normal_, direction);
    if (!(cosine > 0.0)) {
      *weight = 0.0;
      return direction;
    }
    double pdf = (1.0 - lobe_probability_) * cosine / kPi;
    if (has_lobe_) pdf += lobe_probability_ * lobe_.Evaluate(glm::dot(sun_, direction));
    if (guide_share > 0.0) pdf = (1.0 - guide_share) * pdf + guide_share * guide.Pdf(frame, direction);
    *weight = cosine / pdf;
    return direction;
  }

 private:
  static constexpr double kLobeProbability = 0.3, kGuideShare = 0.5;
  dvec3 normal_, sun_;
  PhaseFunction lobe_;
  bool has_lobe_ = false;
  double lobe_probability_ = 0.0;
};

// Mean and standard error of the mean from per-block sums.
Estimate FromBlocks(const std::vector<Spectrum>& sums) {
  Estimate e;
  const double blocks = static_cast<double>(sums.size());
  for (const Spectrum& s : sums) e.mean += s;
  e.mean /= blocks * kPathsPerBlock;
  Spectrum squares(0.0);
  for (const Spectrum& s : sums) {
    Spectrum d = s / double(kPathsPerBlock) - e.mean;
    squares += d * d;
  }
  e.standard_error = glm::sqrt(squares / (blocks * (blocks - 1.0)));
  return e;
}

}  // namespace

int64_t Settings::Blocks() const { return std::max<int64_t>(2, (paths + kPathsPerBlock - 1) / kPathsPerBlock); }

void Settings::Validate() const {
  if (paths < 1 || paths > (int64_t(1) << 40)) {
    throw InputError("paths = " + std::to_string(paths) + " must be in [1, 2^40]");
  }
  if (max_order < 0 || max_order > kMaxEventsPerPath) {
    throw InputError("max order = " + std::to_string(max_order) + " must be in [0, " +
                     std::to_string(kMaxEventsPerPath) + "] (0: all orders)");
  }
  if (threads < 0 || threads > kMaxThreads) {
    throw InputError("threads = " + std::to_string(threads) + " must be in [0, " + std::to_string(kMaxThreads) +
                     "] (0: all cores)");
  }
}

RayQuery MakeRayQuery(const Query& query, double bottom_radius_m) {
  Query q = query;
  q.altitude_m = std::max(q.altitude_m, 0.0);
  QueryGeometry g = MakeQueryGeometry(q, bottom_radius_m);
  RayQuery r;
  r.camera = g.camera;
  r.view = g.view;
  r.sun = g.sun;
  r.distance_m = q.distance_m;
  r.has_normal = q.has_normal;
  r.normal = g.normal;
  return r;
}

namespace {
Atmosphere Checked(const Atmosphere& atmosphere) {
  Validate(atmosphere, atmosphere.name.empty() ? "atmosphere" : atmosphere.name);
  // What the solver itself relies on, whatever the configuration layer checks.
  const std::string name = atmosphere.name.empty() ? "atmosphere" : atmosphere.name;
  auto require = [&](bool ok, const std::string& problem) {
    if (!ok) throw InputError(name + ": " + problem);
  };
  require(atmosphere.bottom_radius_m > 0.0 && std::isfinite(atmosphere.bottom_radius_m),
          "bottom radius must be positive");
  require(atmosphere.top_radius_m > atmosphere.bottom_radius_m && std::isfinite(atmosphere.top_radius_m),
          "top radius must exceed the bottom radius");
  require(atmosphere.sun_angular_radius_rad >= 0.0 && atmosphere.sun_angular_radius_rad < 1.0,
          "sun angular radius must be in [0, 1) rad");
  for (int w = 0; w < kWavelengthCount; ++w) {
    require(atmosphere.ground_albedo[w] >= 0.0 && atmosphere.ground_albedo[w] <= 1.0,
            "ground albedo must be in [0, 1]");
    require(atmosphere.solar_irradiance[w] >= 0.0 && std::isfinite(atmosphere.solar_irradiance[w]),
            "solar irradiance must be finite and non-negative");
  }
  for (const Constituent& c : atmosphere.constituents) {
    for (int w = 0; w < kWavelengthCount; ++w) {
      require(c.scattering_per_m[w] >= 0.0 && std::isfinite(c.scattering_per_m[w]) &&
                  c.absorption_per_m[w] >= 0.0 && std::isfinite(c.absorption_per_m[w]),
              c.name + ": coefficients must be finite and non-negative");
    }
    bool lobed = c.phase.kind == PhaseKind::kHenyeyGreenstein || c.phase.kind == PhaseKind::kCornetteShanks;
    require(!lobed || std::abs(c.phase.g) < 1.0, c.name + ": phase g must be in (-1, 1)");
    if (c.density.kind == DensityProfile::Kind::kTabulated) {
      require(!c.density.altitudes_m.empty() && c.density.altitudes_m.size() == c.density.densities.size(),
              c.name + ": tabulated density needs as many densities as altitudes");
    }
  }
  return atmosphere;
}
}  // namespace

PathTracer::PathTracer(const Atmosphere& atmosphere) : medium_(Checked(atmosphere)), sunlight_(medium_) {}

const std::vector<DirectionGuideField>& PathTracer::TwilightGuides() const {
  std::call_once(guides_->built, [&] {
    for (int w = 0; w < kWavelengthCount; ++w) {
      DirectionGuideField field(medium_, sunlight_, nullptr, w);
      for (int pass = 1; pass < kGuideOrders; ++pass) field = DirectionGuideField(medium_, sunlight_, &field, w);
      guides_->per_wavelength.push_back(std::move(field));
    }
  });
  return guides_->per_wavelength;
}

Spectrum PathTracer::SunTransmittance(const dvec3& point, const dvec3& sun, Spectrum* error) const {
  const glsl::AtmosphereParameters& g = medium_.geometry();
  *error = Spectrum(0.0);
  double r = glm::length(point);
  double mu_s = std::clamp(glm::dot(point, sun) / r, -1.0, 1.0);
  double visible = glsl::SunVisibleFraction(g, r, mu_s);
  if (!(visible > 0.0)) return Spectrum(0.0);
  double mu = SunRayCosine(g, r, mu_s);
  double t_in, t_out;
  if (!InsideTopSphere(g, r, mu, &t_in, &t_out)) return Spectrum(visible);
  OpticalDepthEstimate tau = medium_.OpticalDepth(r, mu, t_in, t_out, kReportedTolerance);
  Spectrum transmittance = glm::exp(-tau.value);
  *error = visible * transmittance * tau.error;
  return visible * transmittance;
}

Result PathTracer::Evaluate(const Query& query, const Settings& settings, uint64_t stream) const {
  return Evaluate(MakeRayQuery(query, medium_.bottom_radius()), settings, stream);
}

Result PathTracer::Evaluate(const RayQuery& query, const Settings& settings, uint64_t stream) const {
  settings.Validate();
  const auto start = std::chrono::steady_clock::now();
  Result result;
  const dvec3 view = glm::normalize(query.view), sun = glm::normalize(query.sun);
  RaySegment segment(medium_, query.camera, view, query.distance_m, RaySegment::Table::kExact);
  result.transmittance = segment.Transmittance(&result.transmittance_error);

  dvec3 normal(0.0);
  if (query.has_normal) {
    result.has_irradiance = true;
    normal = glm::normalize(query.normal);
    Spectrum error;
    Spectrum transmittance = SunTransmittance(query.camera, sun, &error);
    double cosine = std::max(glm::dot(normal, sun), 0.0);
    result.sun_irradiance = medium_.atmosphere().solar_irradiance * transmittance * cosine;
    result.sun_irradiance_error = medium_.atmosphere().solar_irradiance * error * cosine;
  }

  const int64_t blocks = settings.Blocks();
  std::vector<Spectrum> radiance_sums(blocks, Spectrum(0.0)), irradiance_sums(blocks, Spectrum(0.0));
  std::vector<Tally> tallies(blocks);
  IrradianceSampler hemisphere(medium_, normal, sun);
  // Per wavelength, the density of the paths' first vertices along the view
  // ray, guided by the sunlight on its pieces.
  std::vector<RaySegment::Mixture> view_densities;
  // In twilight the direction guides (single scattering alone continues no
  // path: no use for them).
  const dvec3 view_start = segment.length() > 0.0 ? segment.origin() : query.camera;
  const bool twilight = glm::dot(glm::normalize(view_start), sun) < kGuideSunCosine && settings.max_order != 1;
  const std::vector<DirectionGuideField>* guides = twilight ? &TwilightGuides() : nullptr;
  for (int w = 0; w < kWavelengthCount; ++w) {
    view_densities.push_back(segment.MakeMixture(
        w, Tracer(medium_, sunlight_, guides ? &(*guides)[w] : nullptr, settings, sun, w).SourcePieces(segment, view),
        kUnguidedShare));
  }
  const GuideFrame camera_frame(query.camera, sun);
  std::vector<GuideMixture> camera_guides(kWavelengthCount);
  for (int w = 0; w < kWavelengthCount && guides; ++w) {
    const double r = glm::length(query.camera);
    camera_guides[w] = (*guides)[w].At(r, glm::dot(query.camera, sun) / r);
  }
  auto run_block = [&](int64_t b) {
    Tally& tally = tallies[b];
    for (int w = 0; w < kWavelengthCount; ++w) {
      Tracer tracer(medium_, sunlight_, guides ? &(*guides)[w] : nullptr, settings, sun, w);
      for (int j = 0; j < kPathsPerBlock; ++j) {
        const uint64_t path = static_cast<uint64_t>(b) * kPathsPerBlock + j;
        Pcg32 rng = PathGenerator(settings.seed, stream, kRadianceEstimator, w, path);
        double u = (j + rng.Uniform()) / kPathsPerBlock;  // stratified along the view ray
        radiance_sums[b][w] += tracer.Radiance(segment, view, view_densities[w], u, rng, tally);
        if (!query.has_normal) continue;
        Pcg32 irradiance_rng = PathGenerator(settings.seed, stream, kIrradianceEstimator, w, path);
        constexpr int kSide = 8;  // kPathsPerBlock = kSide^2 strata of the hemisphere
        static_assert(kSide * kSide == kPathsPerBlock, "2D strata must tile the block");
        double technique = irradiance_rng.Uniform();
        double u1 = (j % kSide + irradiance_rng.Uniform()) / kSide;
        double u2 = (j / kSide + irradiance_rng.Uniform()) / kSide;
        double weight;
        dvec3 direction =
            hemisphere.Sample(technique, u1, u2, camera_guides[w], camera_frame, irradiance_rng, &weight);
        if (weight > 0.0) {
          irradiance_sums[b][w] += tracer.Incoming(query.camera, direction, weight, irradiance_rng, tally);
        }
      }
    }
  };
  tbb::task_arena arena(settings.threads > 0 ? settings.threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int64_t>(0, blocks, 1), [&](const tbb::blocked_range<int64_t>& range) {
      for (int64_t b = range.begin(); b != range.end(); ++b) run_block(b);
    });
  });

  result.radiance = FromBlocks(radiance_sums);
  if (query.has_normal) result.sky_irradiance = FromBlocks(irradiance_sums);
  Statistics& stats = result.statistics;
  stats.paths = blocks * kPathsPerBlock * kWavelengthCount * (query.has_normal ? 2 : 1);
  for (const Tally& t : tallies) {
    stats.vertices += t.vertices;
    stats.truncated += t.truncated;
  }
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace skybake::reference
