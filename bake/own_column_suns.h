// The suns of a scattering grid's own columns below its split
// (shadow_edge.glsl, "The sun axis after sunset"), solved once per grid for
// the bake's passes over its texels.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <memory>
#include <vector>

#include <tbb/parallel_for.h>

#include "bake/bake.h"
#include "bake/detail.h"
#include "core/constants.h"
#include "shaders_runtime/runtime.h"

namespace skybake::detail {

// Per ray of a scattering grid with a split, the sun cosines of its own
// columns below it (shadow_edge.glsl, "The sun axis after sunset") per nu
// slice, as GetScatteringTexel gives them, solved once for the grid:
// GetScatteringOwnColumnSunZenith's fixed point, each column's from the
// edge of the column above it (which lies close to its own), with each lit
// column's distance to the edge (ShadowEdgeLitDistance, a Newton solve)
// read from a table over the edge (LitDistances), which
// TwilightSunAxis.OwnColumnsLieWhereTheLookupReadsThem holds within 1e-7
// radians of the exact solve.
class OwnColumnSuns {
 public:
  explicit OwnColumnSuns(const AtmosphereParameters& grid)
      : grid_(grid),
        distances_(grid),
        mu_s_(std::size_t(grid.scattering_r_size) * grid.scattering_mu_size * grid.scattering_nu_size *
              grid.scattering_mu_s_split) {
    const int mu_size = grid.scattering_mu_size;
    tbb::parallel_for(0, grid.scattering_r_size * mu_size, [&](int ray) {
      const int y = ray % mu_size, z = ray / mu_size;
      for (int slice = 0; slice < grid.scattering_nu_size; ++slice) {
        const ScatteringTexel slice_ray = GetScatteringSliceTexel(grid, slice, y, z);
        const double r = slice_ray.r, mu = slice_ray.mu, nu = slice_ray.grid_nu;
        const bool ground = slice_ray.ray_intersects_ground;
        double edge = glsl::GetScatteringSliceEdge(grid, r, mu, nu, ground, 0.0);
        for (int column = grid.scattering_mu_s_split - 1; column >= 0; --column) {
          double sun = distances_.SunZenith(grid, column, edge);
          for (int i = 0; i < 50; ++i) {
            edge = glsl::GetScatteringSliceEdge(grid, r, mu, nu, ground, std::cos(sun));
            const double next = distances_.SunZenith(grid, column, edge);
            const bool converged = std::abs(next - sun) < 1e-11;
            sun = next;
            if (converged) break;
          }
          mu_s_[Index(slice * grid.scattering_mu_s_size + column, y, z)] = std::cos(sun);
        }
      }
    });
  }
  // Of texel (x, y, z), x's column below the split.
  double MuS(int x, int y, int z) const { return mu_s_[Index(x, y, z)]; }
  // The same by an index of the texels below the split, in [0, size()).
  std::size_t Index(int x, int y, int z) const {
    const int slice = x / grid_.scattering_mu_s_size, column = x % grid_.scattering_mu_s_size;
    return ((std::size_t(z) * grid_.scattering_mu_size + y) * grid_.scattering_nu_size + slice) *
               grid_.scattering_mu_s_split +
           column;
  }
  std::size_t size() const { return mu_s_.size(); }
  double MuSAt(std::size_t index) const { return mu_s_[index]; }
  // Whether `grid` has the suns of this one: the same geometry and sizes
  // (the suns depend on nothing else, not on the wavelengths).
  bool HasTheSunsOf(const AtmosphereParameters& grid) const {
    const AtmosphereParameters& a = grid_;
    return a.bottom_radius == grid.bottom_radius && a.top_radius == grid.top_radius &&
           a.sun_angular_radius == grid.sun_angular_radius && a.scattering_r_size == grid.scattering_r_size &&
           a.scattering_mu_size == grid.scattering_mu_size && a.scattering_mu_s_size == grid.scattering_mu_s_size &&
           a.scattering_nu_size == grid.scattering_nu_size && a.scattering_r_min == grid.scattering_r_min &&
           a.scattering_r_max == grid.scattering_r_max && a.scattering_mu_s_min == grid.scattering_mu_s_min &&
           a.scattering_mu_s_max == grid.scattering_mu_s_max && a.scattering_mu_s_split == grid.scattering_mu_s_split;
  }

 private:
  // Each lit column's D(E) = ShadowEdgeLitDistance at its position, as a
  // cubic in E between nodes kStep apart (Hermite, with the slopes of exact
  // solves kSlopeStep either side of each node), over the edges of every
  // ray: from the start's at the ground (90 degrees and the disc's radius)
  // to pi and the disc's radius. D(E) is smooth (ShadowEdgeUnitSun goes on
  // smoothly past the tables' lowest sun), so the cubic's error is of order
  // kStep^4 times D's fourth derivative.
  class LitDistances {
   public:
    explicit LitDistances(const AtmosphereParameters& grid)
        : past_(glsl::SHADOW_EDGE_PAST_COLUMNS),
          lit_(grid.scattering_mu_s_split - past_),
          lowest_edge_(0.5 * kPi + grid.sun_angular_radius),
          nodes_(int(std::ceil(0.5 * kPi / kStep)) + 1),
          distance_(std::size_t(lit_) * nodes_),
          slope_(distance_.size()) {
      tbb::parallel_for(0, lit_ * nodes_, [&](int i) {
        const int k = i / nodes_;
        const double edge = lowest_edge_ + (i % nodes_) * kStep, x = double(k) / lit_;
        auto distance = [&](double e) {
          return glsl::ShadowEdgeLitDistance(grid, glsl::GetScatteringSunAxis(grid), x, glsl::ShadowEdgeDirection(e));
        };
        distance_[i] = distance(edge);
        slope_[i] = (distance(edge + kSlopeStep) - distance(edge - kSlopeStep)) / (2.0 * kSlopeStep);
      });
    }
    // The sun zenith angle of a column, E - GetScatteringShadowEdgeDistance,
    // with the table's D.
    double SunZenith(const AtmosphereParameters& grid, int column, double edge) const {
      if (column < past_ || edge < lowest_edge_) {
        return edge - glsl::GetScatteringShadowEdgeDistance(grid, glsl::GetScatteringSunAxis(grid), column,
                                                            glsl::ShadowEdgeDirection(edge));
      }
      const double position = std::min((edge - lowest_edge_) / kStep, nodes_ - 1.0 - 1e-9);
      const int node = int(position);
      const double t = position - node, t2 = t * t, t3 = t2 * t;
      const std::size_t i = std::size_t(column - past_) * nodes_ + node;
      return edge - ((2.0 * t3 - 3.0 * t2 + 1.0) * distance_[i] + (t3 - 2.0 * t2 + t) * kStep * slope_[i] +
                     (3.0 * t2 - 2.0 * t3) * distance_[i + 1] + (t3 - t2) * kStep * slope_[i + 1]);
    }

   private:
    static constexpr double kStep = 0.05 * kPi / 180.0, kSlopeStep = 1e-5;
    int past_, lit_;
    double lowest_edge_;
    int nodes_;
    std::vector<double> distance_, slope_;  // per lit column, then node
  };

  AtmosphereParameters grid_;  // the grid whose suns these are
  LitDistances distances_;
  std::vector<double> mu_s_;
};

// Bake, with the suns of the table's own columns (OwnColumnSuns) shared
// between bakes of the same geometry: *own_suns, where not null and of the
// same geometry, is used instead of solving them again, and receives the
// ones the bake used (null where the table has no split). Bake passes null.
LutSet BakeSharingOwnSuns(const Atmosphere& atmosphere, const BakeSettings& settings, BakeReport* report,
                          const BakeProgress& progress, const BakeOrderSnapshot& order_snapshot,
                          std::shared_ptr<const OwnColumnSuns>* own_suns);

}  // namespace skybake::detail
