// Query files for `skybake reference`: the CSV columns of `skybake eval`
// (altitude_m, view_zenith_deg, sun_zenith_deg, view_sun_azimuth_deg, and
// optionally distance_m and normal_zenith_deg), and the result table: the
// input columns, then per channel (a wavelength, or X, Y and Z of a spectral
// reference) radiance, radiance_stderr,
// transmittance, with normals sun_irradiance, sky_irradiance,
// sky_irradiance_stderr, and last transmittance_error (the quadrature's
// estimated error bound).
#pragma once

#include <string>
#include <vector>

#include "bake/atmosphere.h"
#include "reference/path_tracer.h"
#include "formats/query_csv.h"
#include "shaders_runtime/query.h"

namespace skybake::reference {

// Column names of the result table.
std::vector<std::string> ResultColumns(const QueryTable& table, const ChannelNames& channels);

// The whole result table, one row per query (results in the same order).
std::string FormatResultCsv(const QueryTable& table, const std::vector<Result>& results,
                            const ChannelNames& channels);

}  // namespace skybake::reference
