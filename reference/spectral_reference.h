// The reference at N wavelengths, converted exactly to CIE XYZ: the path
// tracer answers each batch of three wavelengths (bake/spectral.h), and the
// batches' results are added with their matrices, so the colour of a spectral
// bake is measured against the same wavelengths converted without the
// tables' approximations.
#pragma once

#include <functional>
#include <vector>

#include "bake/config.h"
#include "bake/spectral.h"
#include "reference/path_tracer.h"
#include "shaders_runtime/query.h"

namespace skybake::reference {

// Called once per batch after its queries (batch index, batch count).
using SpectralProgress = std::function<void(std::size_t batch, std::size_t batches)>;
// Called after each query of a batch.
using QueryProgress = std::function<void()>;

// The results of `queries` in XYZ (luminance units, bake/spectral.h), one per
// query, each row evaluated with stream = its index as `skybake reference`
// does:
// - radiance, sun and sky irradiance: the sums of the batches' values times
//   their matrices; a standard error is the same sum of the batches' standard
//   errors with the matrices' absolute values, an upper bound (the batches
//   share random streams, so their errors are correlated);
// - transmittance: the sun's XYZ through the ray over the sun's XYZ, the
//   transmittance of sunlight's colour (as the spectral tables store it).
std::vector<Result> EvaluateSpectral(const AtmosphereSource& atmosphere, const SpectralBatches& batches,
                                     const std::vector<Query>& queries, const Settings& settings,
                                     const QueryProgress& progress = nullptr);

}  // namespace skybake::reference
