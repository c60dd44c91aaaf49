#include "fit/optical_path.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/errors.h"

namespace skybake::fit {

namespace {

// The unclamped layer expression: density kinks where it crosses 0 or 1.
double LayerExpression(const DensityLayer& layer, double altitude_m) {
  return layer.exp_term * std::exp(layer.exp_scale_per_m * altitude_m) +
         layer.linear_term_per_m * altitude_m + layer.constant_term;
}

// Roots of g on [lo, hi], found by sampling and bisection. Layer expressions
// are exp + linear, with at most two roots per level, so 256 samples per
// layer cannot miss a crossing unless two roots lie closer than a sample
// spacing, where the clamped density differs from the unclamped one by less
// than the quadrature tolerance anyway.
template <typename G>
void AppendRoots(const G& g, double lo, double hi, std::vector<double>* roots) {
  constexpr int kSamples = 256;
  double x0 = lo, g0 = g(lo);
  for (int i = 1; i <= kSamples; ++i) {
    double x1 = lo + (hi - lo) * i / kSamples;
    double g1 = g(x1);
    if ((g0 < 0.0) != (g1 < 0.0)) {
      double a = x0, b = x1, ga = g0;
      for (int k = 0; k < 200 && b - a > 1e-12 * std::max(1.0, std::abs(b)); ++k) {
        double m = 0.5 * (a + b);
        double gm = g(m);
        if ((gm < 0.0) == (ga < 0.0)) {
          a = m;
          ga = gm;
        } else {
          b = m;
        }
      }
      roots->push_back(0.5 * (a + b));
    }
    x0 = x1;
    g0 = g1;
  }
}

std::vector<double> FindKinks(const DensityProfile& profile, double thickness_m) {
  std::vector<double> kinks = profile.Breakpoints();
  if (profile.kind == DensityProfile::Kind::kLayers) {
    double base = 0.0;
    for (size_t i = 0; i < profile.layers.size(); ++i) {
      const DensityLayer& layer = profile.layers[i];
      bool last = i + 1 == profile.layers.size();
      double top = last ? thickness_m : std::min(thickness_m, base + layer.width_m);
      if (top > base) {
        for (double level : {0.0, 1.0}) {
          AppendRoots([&](double z) { return LayerExpression(layer, z) - level; }, base, top, &kinks);
        }
      }
      base += layer.width_m;
      if (base >= thickness_m) break;
    }
  }
  std::vector<double> inside;
  for (double k : kinks)
    if (std::isfinite(k) && k > 0.0 && k < thickness_m) inside.push_back(k);
  std::sort(inside.begin(), inside.end());
  // A crossing found by bisection at a layer boundary (the tent's peak) is
  // the boundary itself: merge points closer than the bisection resolution.
  double resolution = 1e-9 * std::max(1.0, thickness_m);
  std::vector<double> merged;
  for (double k : inside)
    if (merged.empty() || k - merged.back() > resolution) merged.push_back(k);
  return merged;
}

}  // namespace

std::optional<double> ColumnSample::RelativeOpticalPath() const {
  if (!(vertical_column_m > 0.0)) return std::nullopt;
  return slant_column_m / vertical_column_m;
}

std::optional<double> ColumnSample::OpticalLength() const {
  if (!(density_at_observer > 0.0)) return std::nullopt;
  return slant_column_m / density_at_observer;
}

ColumnIntegrator::ColumnIntegrator(const DensityProfile& profile, double bottom_radius_m,
                                   double top_radius_m, const QuadratureOptions& options)
    : profile_(profile),
      bottom_radius_m_(bottom_radius_m),
      top_radius_m_(top_radius_m),
      options_(options) {
  if (!(std::isfinite(bottom_radius_m) && std::isfinite(top_radius_m) && bottom_radius_m > 0.0 &&
        top_radius_m > bottom_radius_m)) {
    throw InputError("atmosphere radii must satisfy 0 < bottom (" + std::to_string(bottom_radius_m) +
                     " m) < top (" + std::to_string(top_radius_m) + " m)");
  }
  kinks_ = FindKinks(profile, thickness_m());
}

double ColumnIntegrator::DistanceToAltitude(double altitude_m, double mu, double target_altitude_m) const {
  double r = bottom_radius_m_ + altitude_m;
  double dz = std::max(0.0, target_altitude_m - altitude_m);
  // (R+z)^2 - r^2 factored so that a target just above the observer keeps its digits.
  double radial = dz * (2.0 * bottom_radius_m_ + target_altitude_m + altitude_m);
  double rmu = r * mu;
  double denom = std::sqrt(rmu * rmu + radial) + rmu;
  return denom > 0.0 ? radial / denom : 0.0;
}

QuadratureResult ColumnIntegrator::VerticalColumn(double altitude_m) const {
  double h = std::clamp(altitude_m, 0.0, thickness_m());
  return Integrate([this](double z) { return profile_.At(z); }, h, thickness_m(), kinks_, options_);
}

QuadratureResult ColumnIntegrator::SlantColumn(double altitude_m, double mu) const {
  // Integrated in path length s rather than altitude: dz/ds = (s + rμ)/r(s)
  // vanishes at the tangent point of a horizontal ray, so ds/dz has an
  // inverse-square-root singularity there, while the integrand in s stays
  // smooth (a Gaussian-like fall-off exp(-s²/2rH) for an exponential profile).
  double h = std::clamp(altitude_m, 0.0, thickness_m());
  mu = std::clamp(mu, 0.0, 1.0);
  double r = bottom_radius_m_ + h;
  double length = DistanceToAltitude(h, mu, thickness_m());
  std::vector<double> s_kinks;
  for (double z : kinks_)
    if (z > h) s_kinks.push_back(DistanceToAltitude(h, mu, z));
  auto density = [&](double s) {
    double q = s * s + 2.0 * r * mu * s;  // r(s)^2 - r^2
    double z = h + q / (std::sqrt(r * r + q) + r);
    return profile_.At(std::min(z, thickness_m()));
  };
  return Integrate(density, 0.0, length, s_kinks, options_);
}

ColumnSample ColumnIntegrator::Sample(double altitude_m, double mu) const {
  QuadratureResult slant = SlantColumn(altitude_m, mu);
  QuadratureResult vertical = VerticalColumn(altitude_m);
  ColumnSample sample;
  sample.slant_column_m = slant.value;
  sample.vertical_column_m = vertical.value;
  sample.density_at_observer = profile_.At(std::clamp(altitude_m, 0.0, thickness_m()));
  sample.converged = slant.converged && vertical.converged;
  return sample;
}

}  // namespace skybake::fit
