#include "bake/medium.h"

#include <algorithm>
#include <cmath>

#include "core/quadrature.h"

namespace skybake {

namespace {

bool IsMiePhase(const PhaseFunction& phase) {
  return phase.kind == PhaseKind::kHenyeyGreenstein || phase.kind == PhaseKind::kCornetteShanks;
}

}  // namespace

Medium::Medium(const Atmosphere& atmosphere) : atmosphere_(atmosphere) {
  for (int i = 0; i < constituent_count(); ++i) {
    const Constituent& c = atmosphere_.constituents[i];
    if (c.scattering_per_m == Spectrum(0.0)) continue;  // absorbs only
    auto group = std::find_if(groups_.begin(), groups_.end(),
                              [&](const PhaseGroup& g) { return g.phase == c.phase; });
    if (group == groups_.end()) {
      groups_.push_back(PhaseGroup{c.phase, {}});
      group = groups_.end() - 1;
      if (mie_group_ < 0 && IsMiePhase(c.phase)) mie_group_ = static_cast<int>(groups_.size()) - 1;
    }
    group->constituents.push_back(i);
  }
  for (const Constituent& c : atmosphere_.constituents) {
    for (double altitude : c.density.Breakpoints()) {
      double radius = atmosphere_.bottom_radius_m + altitude;
      if (radius > atmosphere_.bottom_radius_m && radius < atmosphere_.top_radius_m) {
        breakpoint_radii_.push_back(radius);
      }
    }
  }
  std::sort(breakpoint_radii_.begin(), breakpoint_radii_.end());
  breakpoint_radii_.erase(std::unique(breakpoint_radii_.begin(), breakpoint_radii_.end()), breakpoint_radii_.end());
}

void Medium::Densities(double altitude_m, double* densities) const {
  for (int i = 0; i < constituent_count(); ++i) densities[i] = atmosphere_.constituents[i].density.At(altitude_m);
}

Spectrum Medium::Extinction(const double* densities) const {
  Spectrum sum(0.0);
  for (int i = 0; i < constituent_count(); ++i) sum += atmosphere_.constituents[i].Extinction() * densities[i];
  return sum;
}

Spectrum Medium::GroupScattering(int group, const double* densities) const {
  Spectrum sum(0.0);
  for (int i : groups_[group].constituents) sum += atmosphere_.constituents[i].scattering_per_m * densities[i];
  return sum;
}

Spectrum Medium::OpticalDepth(double r, double mu, double d, int nodes) const {
  if (!(d > 0.0) || constituent_count() == 0) return Spectrum(0.0);
  // Split points: where the altitude along the ray is extremal (the tangent
  // point) and where it crosses a breakpoint radius R, the roots of
  // t^2 + 2 r mu t + r^2 - R^2 = 0.
  std::vector<double> splits = {0.0, d};
  double tangent = -r * mu;
  if (tangent > 0.0 && tangent < d) splits.push_back(tangent);
  for (double R : breakpoint_radii_) {
    double disc = r * r * mu * mu - (r - R) * (r + R);
    if (disc < 0.0) continue;
    double s = std::sqrt(disc);
    for (double t : {-r * mu - s, -r * mu + s}) {
      if (t > 0.0 && t < d) splits.push_back(t);
    }
  }
  std::sort(splits.begin(), splits.end());

  const int intervals_total = std::max(1, nodes / 8);
  std::vector<double> densities(constituent_count());
  Spectrum sum(0.0);
  for (size_t p = 0; p + 1 < splits.size(); ++p) {
    double a = splits[p], b = splits[p + 1];
    if (b <= a) continue;
    int intervals = std::max(1, static_cast<int>(std::ceil(intervals_total * (b - a) / d)));
    double h = (b - a) / intervals;
    for (int k = 0; k < intervals; ++k) {
      double mid = a + (k + 0.5) * h;
      for (int n = 0; n < 8; ++n) {
        double t = mid + 0.5 * h * GaussLegendre8Rule::kNodes[n];
        double radius = std::sqrt(t * t + 2.0 * r * mu * t + r * r);
        Densities(radius - atmosphere_.bottom_radius_m, densities.data());
        sum += Extinction(densities.data()) * (0.5 * h * GaussLegendre8Rule::kWeights[n]);
      }
    }
  }
  return sum;
}

}  // namespace skybake
