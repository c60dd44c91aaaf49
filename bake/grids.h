// The bake's grids and whole-table operations on them: the coarser grid of
// the higher orders, a texture per scattering grid, and parallel loops over
// a table's rows.
#pragma once

#include <algorithm>
#include <cstddef>

#include <tbb/parallel_for.h>

#include "bake/detail.h"
#include "core/spectrum.h"

namespace skybake::detail {

// The grid of each higher order's radiance: the r and mu sizes of the grid
// of the scattering densities divided by `divisor` (mu kept even). mu_s and
// nu keep their sizes, as the light of low suns changes fastest with mu_s
// (docs/benchmark.md measures the divisor's error).
inline AtmosphereParameters HigherOrderGrid(AtmosphereParameters grid, int divisor) {
  grid.scattering_r_size = std::max(2, grid.scattering_r_size / divisor);
  grid.scattering_mu_size = std::max(4, grid.scattering_mu_size / divisor / 2 * 2);
  return grid;
}

// target += source * factor, per channel, over the rgb of every texel.
// f(row, first, end) over the rows of a texture (y and z) in parallel:
// first and end are the row's texel offsets into texels.
template <typename F>
inline void ForEachRow(const Texture& texture, F&& f) {
  const std::size_t row_size = std::size_t(4) * texture.width;
  tbb::parallel_for(0, texture.height * texture.depth, [&](int row) {
    f(row, row * row_size, (row + 1) * row_size);
  });
}

inline void AddScaled(const Texture& source, const Spectrum& factor, Texture& target) {
  ForEachRow(target, [&](int, std::size_t first, std::size_t end) {
    for (std::size_t i = first; i < end; i += 4) {
      for (int c = 0; c < 3; ++c) target.texels[i + c] += float(source.texels[i + c] * factor[c]);
    }
  });
}

// Gives `texture` the size of the grid's scattering textures, in the memory
// it has where that is large enough; texels it did not have are zero.
inline void SizeForScatteringGrid(const AtmosphereParameters& grid, Texture* texture) {
  texture->width = grid.scattering_nu_size * grid.scattering_mu_s_size;
  texture->height = grid.scattering_mu_size;
  texture->depth = grid.scattering_r_size;
  texture->texels.resize(std::size_t(4) * texture->width * texture->height * texture->depth, 0.0f);
}

// Copies the texels of the mu_s columns from `first_column` up of a
// texture on `grid` into `to`, a texture of the same size.
inline void CopyColumnsFrom(const Texture& from, const AtmosphereParameters& grid, int first_column, Texture* to) {
  const int mu_s_size = grid.scattering_mu_s_size;
  ForEachRow(*to, [&](int, std::size_t first, std::size_t end) {
    for (std::size_t i = first; i < end; i += 4) {
      if (int((i - first) / 4) % mu_s_size < first_column) continue;
      for (int c = 0; c < 4; ++c) to->texels[i + c] = from.texels[i + c];
    }
  });
}

inline Texture ScatteringGridTexture(const AtmosphereParameters& grid) {
  Texture texture;
  SizeForScatteringGrid(grid, &texture);
  return texture;
}
}  // namespace skybake::detail
