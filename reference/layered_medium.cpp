#include "reference/layered_medium.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "reference/quadrature.h"
#include "shaders_runtime/runtime.h"

namespace skybake::reference {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// One layer of a layered profile restricted to the altitudes where
// DensityProfile::At uses it: [begin, end).
struct LayerSpan {
  const DensityLayer* layer;
  double begin, end;
};

std::vector<LayerSpan> LayerSpans(const DensityProfile& profile) {
  std::vector<LayerSpan> spans;
  double base = 0.0, begin = -kInfinity;
  for (size_t i = 0; i < profile.layers.size(); ++i) {
    bool last = i + 1 == profile.layers.size();
    double end = last ? kInfinity : std::max(begin, base + profile.layers[i].width_m);
    if (end > begin || last) spans.push_back({&profile.layers[i], begin, end});
    begin = std::max(begin, end);
    base += profile.layers[i].width_m;
  }
  return spans;
}

// The layer's formula before clamping.
double LayerValue(const DensityLayer& l, double h) {
  double value = l.linear_term_per_m * h + l.constant_term;
  if (l.exp_term != 0.0) value += l.exp_term * std::exp(l.exp_scale_per_m * h);
  return value;
}

// Where the layer's formula is stationary (at most one point: its derivative
// is exp_term * exp_scale * exp(exp_scale h) + linear_term, monotone in h);
// NaN if nowhere.
double LayerStationaryPoint(const DensityLayer& l) {
  double ea = l.exp_term * l.exp_scale_per_m;
  if (ea == 0.0 || l.linear_term_per_m == 0.0) return std::numeric_limits<double>::quiet_NaN();
  double x = -l.linear_term_per_m / ea;
  return x > 0.0 ? std::log(x) / l.exp_scale_per_m : std::numeric_limits<double>::quiet_NaN();
}

// Minimum and maximum of a profile over [lo, hi], exactly: within a layer the
// extremes of the formula lie at the ends or at its stationary point, and
// clamping to [0, 1] commutes with taking them; a tabulated profile is
// piecewise linear.
void DensityRange(const DensityProfile& profile, double lo, double hi, double& minimum, double& maximum) {
  minimum = kInfinity;
  maximum = -kInfinity;
  auto consider = [&](double value) {
    minimum = std::min(minimum, value);
    maximum = std::max(maximum, value);
  };
  if (profile.kind == DensityProfile::Kind::kTabulated) {
    consider(profile.At(lo));
    consider(profile.At(hi));
    for (double h : profile.altitudes_m) {
      if (h > lo && h < hi) consider(profile.At(h));
    }
  } else {
    for (const LayerSpan& span : LayerSpans(profile)) {
      double a = std::max(lo, span.begin), b = std::min(hi, span.end);
      if (a > b) continue;
      consider(std::clamp(LayerValue(*span.layer, a), 0.0, 1.0));
      consider(std::clamp(LayerValue(*span.layer, b), 0.0, 1.0));
      double h = LayerStationaryPoint(*span.layer);
      if (h > a && h < b) consider(std::clamp(LayerValue(*span.layer, h), 0.0, 1.0));
    }
  }
  if (maximum < minimum) minimum = maximum = 0.0;
}

// Altitudes in (lo, hi) where a layer's formula crosses `level` (0 or 1), so
// that the clamped profile has a kink: bisection on each monotone piece.
void LayerCrossings(const DensityLayer& layer, double lo, double hi, double level, std::vector<double>& out) {
  double stationary = LayerStationaryPoint(layer);
  std::vector<double> ends = {lo};
  if (stationary > lo && stationary < hi) ends.push_back(stationary);
  ends.push_back(hi);
  for (size_t i = 0; i + 1 < ends.size(); ++i) {
    double a = ends[i], b = ends[i + 1];
    double fa = LayerValue(layer, a) - level, fb = LayerValue(layer, b) - level;
    if (!(fa * fb < 0.0)) continue;
    for (int k = 0; k < 200 && b - a > 1e-9 * std::max(1.0, std::abs(a)); ++k) {
      double m = 0.5 * (a + b), fm = LayerValue(layer, m) - level;
      if ((fm < 0.0) == (fa < 0.0)) {
        a = m;
        fa = fm;
      } else {
        b = m;
      }
    }
    out.push_back(0.5 * (a + b));
  }
}

}  // namespace

double RadiusAlongRay(double r, double mu, double t) {
  double along = t + r * mu;
  double perpendicular_squared = r * r * (1.0 - mu) * (1.0 + mu);
  return std::sqrt(std::max(0.0, along * along + perpendicular_squared));
}

LayeredMedium::LayeredMedium(const Atmosphere& atmosphere) : atmosphere_(atmosphere) {
  geometry_.bottom_radius = atmosphere.bottom_radius_m;
  geometry_.top_radius = atmosphere.top_radius_m;
  geometry_.sun_angular_radius = atmosphere.sun_angular_radius_rad;
  geometry_.solar_irradiance = atmosphere.solar_irradiance;
  geometry_.mu_s_min = atmosphere.mu_s_min;
  for (const Constituent& c : atmosphere.constituents) {
    if (c.Extinction() == Spectrum(0.0)) continue;
    constituents_.push_back({c.density, c.Extinction(), c.scattering_per_m, c.phase});
  }

  const double height = atmosphere.top_radius_m - atmosphere.bottom_radius_m;
  std::vector<double> splits;
  for (const Coefficients& c : constituents_) {
    for (double h : c.density.Breakpoints()) splits.push_back(h);
    if (c.density.kind == DensityProfile::Kind::kLayers) {
      for (const LayerSpan& span : LayerSpans(c.density)) {
        double a = std::max(0.0, span.begin), b = std::min(height, span.end);
        if (a >= b) continue;
        LayerCrossings(*span.layer, a, b, 0.0, splits);
        LayerCrossings(*span.layer, a, b, 1.0, splits);
      }
    }
  }
  std::sort(splits.begin(), splits.end());
  for (double h : splits) {
    if (h <= 0.0 || h >= height) continue;
    double radius = atmosphere.bottom_radius_m + h;
    if (split_radii_.empty() || radius > split_radii_.back()) split_radii_.push_back(radius);
  }
  BuildShells();
}

void LayeredMedium::BuildShells() {
  const double bottom = geometry_.bottom_radius, height = geometry_.top_radius - bottom;
  // Extinction range over an altitude interval, per wavelength.
  auto range = [&](double lo, double hi, Spectrum& minimum, Spectrum& maximum) {
    minimum = maximum = Spectrum(0.0);
    for (const Coefficients& c : constituents_) {
      double dmin, dmax;
      DensityRange(c.density, lo, hi, dmin, dmax);
      minimum += c.extinction * dmin;
      maximum += c.extinction * dmax;
    }
  };
  // A shell is split until its majorant is within 20% of the extinction
  // everywhere in it (few wasted null collisions), or the waste across it is
  // negligible (1e-4 of an optical depth radially), or it is 1 m thick.
  std::vector<double> levels = {0.0};
  for (double radius : split_radii_) levels.push_back(radius - bottom);
  levels.push_back(height);
  std::vector<double> altitudes = {0.0};
  constexpr int kMaxShells = 4096;
  for (size_t i = 0; i + 1 < levels.size(); ++i) {
    std::vector<std::pair<double, double>> work = {{levels[i + 1], levels[i]}};  // stack of (hi, lo)
    while (!work.empty()) {
      auto [hi, lo] = work.back();
      work.pop_back();
      Spectrum minimum, maximum;
      range(lo, hi, minimum, maximum);
      bool tight = true;
      for (int w = 0; w < kWavelengthCount; ++w) {
        double waste = maximum[w] - minimum[w];
        if (waste > 0.2 * maximum[w] && waste * (hi - lo) > 1e-4) tight = false;
      }
      if (tight || hi - lo <= 1.0 || static_cast<int>(altitudes.size()) >= kMaxShells) {
        altitudes.push_back(hi);
      } else {
        double mid = 0.5 * (lo + hi);
        work.push_back({hi, mid});
        work.push_back({mid, lo});
      }
    }
  }
  shell_radii_.clear();
  for (double h : altitudes) shell_radii_.push_back(bottom + h);
  shell_radii_.front() = geometry_.bottom_radius;
  shell_radii_.back() = geometry_.top_radius;
  shell_geometry_.clear();
  majorants_.clear();
  for (int s = 0; s < shell_count(); ++s) {
    glsl::AtmosphereParameters shell = geometry_;
    shell.bottom_radius = shell_radii_[s];
    shell.top_radius = shell_radii_[s + 1];
    shell_geometry_.push_back(shell);
    Spectrum minimum, maximum;
    range(shell_radii_[s] - bottom, shell_radii_[s + 1] - bottom, minimum, maximum);
    // A relative margin keeps the bound safe against rounding in the profile.
    for (int w = 0; w < kWavelengthCount; ++w) majorants_.push_back(maximum[w] * (1.0 + 1e-9));
  }
}

int LayeredMedium::ShellIndex(double radius) const {
  auto upper = std::upper_bound(shell_radii_.begin(), shell_radii_.end(), radius);
  int index = static_cast<int>(upper - shell_radii_.begin()) - 1;
  return std::clamp(index, 0, shell_count() - 1);
}

Spectrum LayeredMedium::Extinction(double radius) const {
  double h = radius - geometry_.bottom_radius;
  Spectrum sum(0.0);
  for (const Coefficients& c : constituents_) sum += c.extinction * c.density.At(h);
  return sum;
}

double LayeredMedium::Extinction(double radius, int wavelength) const {
  double h = radius - geometry_.bottom_radius;
  double sum = 0.0;
  for (const Coefficients& c : constituents_) sum += c.extinction[wavelength] * c.density.At(h);
  return sum;
}

double LayeredMedium::Scattering(double radius, int wavelength, double* per_constituent) const {
  double h = radius - geometry_.bottom_radius;
  double sum = 0.0;
  for (size_t i = 0; i < constituents_.size(); ++i) {
    const Coefficients& c = constituents_[i];
    per_constituent[i] = c.scattering[wavelength] == 0.0 ? 0.0 : c.scattering[wavelength] * c.density.At(h);
    sum += per_constituent[i];
  }
  return sum;
}

OpticalDepthEstimate LayeredMedium::OpticalDepth(double r, double mu, double t0, double t1,
                                                 double relative_tolerance) const {
  OpticalDepthEstimate result;
  if (!(t1 > t0)) return result;
  std::vector<double> cuts = {t0, t1};
  double tangent = -r * mu;
  if (tangent > t0 && tangent < t1) cuts.push_back(tangent);
  const double r_mu = r * mu;
  for (double radius : split_radii_) {
    // Both roots of t^2 + 2 r mu t + (r^2 - R^2) = 0, without cancellation.
    double c = (r - radius) * (r + radius);
    double disc = r_mu * r_mu - c;
    if (disc < 0.0) continue;
    double q = -(r_mu + std::copysign(std::sqrt(disc), r_mu));
    for (double t : {q, q != 0.0 ? c / q : 0.0}) {
      if (t > t0 && t < t1) cuts.push_back(t);
    }
  }
  std::sort(cuts.begin(), cuts.end());

  auto integrand = [&](double t) { return Extinction(RadiusAlongRay(r, mu, t)); };
  struct Piece {
    double a, b;
    GaussKronrodResult estimate;
    int depth;
  };
  std::vector<Piece> pieces;
  Spectrum total(0.0);
  for (size_t i = 0; i + 1 < cuts.size(); ++i) {
    if (!(cuts[i + 1] > cuts[i])) continue;
    Piece piece{cuts[i], cuts[i + 1], GaussKronrod15(integrand, cuts[i], cuts[i + 1]), 0};
    result.evaluations += 15;
    total += piece.estimate.kronrod;
    pieces.push_back(piece);
  }
  // Each piece may use the share of the tolerance proportional to its length.
  const Spectrum tolerance = relative_tolerance * total + Spectrum(1e-15);
  const double length = t1 - t0;
  std::reverse(pieces.begin(), pieces.end());  // processed front to back from the stack's end
  while (!pieces.empty()) {
    Piece piece = pieces.back();
    pieces.pop_back();
    Spectrum error = glm::abs(piece.estimate.kronrod - piece.estimate.gauss);
    Spectrum allowed = tolerance * ((piece.b - piece.a) / length);
    // Millimetre pieces or 40 halvings mean a discontinuity the splits
    // missed; accept them with their (reported) error rather than loop.
    bool accept = piece.depth >= 40 || piece.b - piece.a <= 1e-3;
    if (!accept) {
      accept = true;
      for (int w = 0; w < kWavelengthCount; ++w) accept = accept && error[w] <= allowed[w];
    }
    if (accept) {
      result.value += piece.estimate.kronrod;
      result.error += error;
      continue;
    }
    double mid = 0.5 * (piece.a + piece.b);
    Piece right{mid, piece.b, GaussKronrod15(integrand, mid, piece.b), piece.depth + 1};
    Piece left{piece.a, mid, GaussKronrod15(integrand, piece.a, mid), piece.depth + 1};
    result.evaluations += 30;
    pieces.push_back(right);
    pieces.push_back(left);
  }
  return result;
}

template <typename Visit>
RayEvent LayeredMedium::Traverse(double r, double mu, double t_max, bool stop_at_ground, Visit&& visit) const {
  // The ray descends through the shells to the one holding its lowest point
  // (or to the ground), then ascends. Exit distances are measured from the
  // ray's origin with the GLSL primitives applied to each shell's spheres.
  const int shells = shell_count();
  int s = ShellIndex(r);
  bool descending = mu < 0.0;
  double t = 0.0;
  for (;;) {
    const glsl::AtmosphereParameters& shell = shell_geometry_[s];
    double t_exit;
    int next;
    if (descending && (s > 0 || stop_at_ground) && glsl::RayIntersectsGround(shell, r, mu)) {
      t_exit = glsl::DistanceToBottomAtmosphereBoundary(shell, r, mu);
      next = s - 1;
    } else {
      descending = false;
      t_exit = glsl::DistanceToTopAtmosphereBoundary(shell, r, mu);
      next = s + 1;
    }
    t_exit = std::max(t_exit, t);
    double hit = 0.0;
    double extinction = 0.0;
    if (visit(s, t, std::min(t_exit, t_max), hit, extinction)) return {RayEnd::kCollision, hit, extinction};
    if (t_exit >= t_max) return {RayEnd::kLimit, t_max, 0.0};
    t = t_exit;
    if (next < 0) return {RayEnd::kGround, t, 0.0};
    if (next >= shells) return {RayEnd::kSpace, t, 0.0};
    s = next;
  }
}

RayEvent LayeredMedium::SampleFreeFlight(double r, double mu, double t_max, int wavelength, Pcg32& rng) const {
  return Traverse(r, mu, t_max, true, [&](int shell, double begin, double end, double& hit, double& sigma) {
    double majorant = Majorant(shell, wavelength);
    if (majorant <= 0.0) return false;
    double t = begin;
    for (;;) {
      t -= std::log(1.0 - rng.Uniform()) / majorant;
      if (t >= end) return false;  // memoryless: restart in the next shell
      double extinction = Extinction(RadiusAlongRay(r, mu, t), wavelength);
      if (rng.Uniform() * majorant < extinction) {
        hit = t;
        sigma = extinction;
        return true;
      }
    }
  });
}

double LayeredMedium::RatioTrackingTransmittance(double r, double mu, double t_max, int wavelength,
                                                 Pcg32& rng) const {
  double transmittance = 1.0;
  Traverse(r, mu, t_max, false, [&](int shell, double begin, double end, double&, double&) {
    double majorant = Majorant(shell, wavelength);
    if (majorant <= 0.0) return false;
    double t = begin;
    for (;;) {
      t -= std::log(1.0 - rng.Uniform()) / majorant;
      if (t >= end) return false;
      double extinction = Extinction(RadiusAlongRay(r, mu, t), wavelength);
      transmittance *= std::max(0.0, 1.0 - extinction / majorant);
      if (transmittance < 1e-2) {
        if (rng.Uniform() < 0.5) {
          transmittance = 0.0;
          return true;
        }
        transmittance *= 2.0;
      }
    }
  });
  return transmittance;
}

std::vector<double> LayeredMedium::ShellCrossings(double r, double mu, double t_max) const {
  std::vector<double> crossings;
  RayEvent event = Traverse(r, mu, t_max, true, [&](int, double, double end, double&, double&) {
    crossings.push_back(end);
    return false;
  });
  if (crossings.empty() || crossings.back() < event.distance) crossings.push_back(event.distance);
  return crossings;
}

}  // namespace skybake::reference
