// Colorimetry (bake/colour.h) against published constants: the tables
// against values printed in CIE 015:2018, an equal-energy spectrum to the
// equal-energy white point, D65 to its published chromaticity, the sRGB
// matrices to those IEC 61966-2-1 prints, and D65 to sRGB white.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "bake/colour.h"
#include "report/error_stats.h"
#include "shaders_runtime/runtime.h"

namespace skybake {
namespace {

// The observer's and the illuminant's samples as (wavelengths, values).
std::vector<double> Wavelengths(const SpectralTable& t) {
  std::vector<double> nm;
  for (std::size_t i = 0; i < t.values.size(); ++i) nm.push_back(t.WavelengthNm(i));
  return nm;
}

// The XYZ of illuminant D65's tabulated spectrum.
glm::dvec3 D65Xyz() {
  std::vector<double> power;
  for (const glm::dvec3& p : CieD65().values) power.push_back(p.x);
  return SpectrumToXyz(Wavelengths(CieD65()), power);
}

TEST(Colour, TablesHoldThePublishedValues) {
  const SpectralTable& cmf = Cie1931Observer();
  ASSERT_EQ(cmf.values.size(), 95u);  // 360 to 830 nm
  EXPECT_EQ(cmf.first_nm, 360.0);
  EXPECT_EQ(cmf.step_nm, 5.0);
  auto at = [](const SpectralTable& t, double nm) { return t.values[std::size_t((nm - t.first_nm) / t.step_nm)]; };
  EXPECT_DOUBLE_EQ(at(cmf, 555).y, 1.0);       // y_bar peaks at 1 at 555 nm
  EXPECT_DOUBLE_EQ(at(cmf, 600).x, 1.0622);    // x_bar(600)
  EXPECT_DOUBLE_EQ(at(cmf, 445).z, 1.7826);    // z_bar(445)
  EXPECT_DOUBLE_EQ(at(cmf, 360).x, 0.0001299);
  const SpectralTable& d65 = CieD65();
  ASSERT_EQ(d65.values.size(), 107u);  // 300 to 830 nm
  EXPECT_DOUBLE_EQ(at(d65, 560).x, 1.0);       // 100.000 in the CIE's table
  EXPECT_DOUBLE_EQ(at(d65, 460).x, 1.17812);   // 117.812
  EXPECT_DOUBLE_EQ(at(d65, 300).x, 0.000341);  // 0.0341
  // The integral of y_bar: 106.857 nm (CIE 015, from the 1 nm table; the
  // trapezoid rule on 5 nm agrees to 1e-4).
  std::vector<double> one(cmf.values.size(), 1.0);
  EXPECT_NEAR(SpectrumToXyz(Wavelengths(cmf), one).y, 106.857, 0.02);
}

// The functions are normalised to equal integrals, so the equal-energy
// spectrum is white at (1/3, 1/3); the published 5 nm table keeps that to
// about 1e-4 (its integrals are 106.865, 106.857 and 106.892 nm, 3e-4 apart
// at most), hence the tolerance.
TEST(Colour, EqualEnergySpectrumIsTheEqualEnergyWhite) {
  const glm::dvec2 xy = Chromaticity(SpectrumToXyz({360.0, 830.0}, {1.0, 1.0}));
  EXPECT_NEAR(xy.x, 1.0 / 3.0, 1e-4);
  EXPECT_NEAR(xy.y, 1.0 / 3.0, 1e-4);
}

TEST(Colour, D65HasItsPublishedChromaticity) {
  // CIE 015:2018 table 3 (2 degree observer): x = 0.31272, y = 0.32903.
  const glm::dvec2 xy = Chromaticity(D65Xyz());
  EXPECT_NEAR(xy.x, 0.31272, 5e-5);
  EXPECT_NEAR(xy.y, 0.32903, 5e-5);
}

TEST(Colour, D65HasItsPublishedUcsChromaticity) {
  // CIE 015:2018 table 3 (2 degree observer), to the four decimals printed:
  // u' = 0.1978, v' = 0.4683.
  const glm::dvec2 uv = UcsChromaticity(D65Xyz());
  EXPECT_NEAR(uv.x, 0.1978, 1e-4);
  EXPECT_NEAR(uv.y, 0.4683, 1e-4);
}

TEST(Colour, SrgbMatricesAreThoseOfIec61966) {
  // IEC 61966-2-1 prints the matrix to XYZ to four decimals, and the inverse
  // of that rounded matrix, again to four decimals, which therefore differs
  // from the exact inverse by up to 4e-4 (3.2406 against 3.24097).
  const double to_xyz[3][3] = {{0.4124, 0.3576, 0.1805}, {0.2126, 0.7152, 0.0722}, {0.0193, 0.1192, 0.9505}};
  const double to_rgb[3][3] = {{3.2406, -1.5372, -0.4986}, {-0.9689, 1.8758, 0.0415}, {0.0557, -0.2040, 1.0570}};
  const glm::dmat3 identity = XyzToLinearSrgbMatrix() * LinearSrgbToXyzMatrix();
  for (int row = 0; row < 3; ++row) {
    for (int column = 0; column < 3; ++column) {
      // glm matrices are indexed [column][row].
      EXPECT_NEAR(LinearSrgbToXyzMatrix()[column][row], to_xyz[row][column], 6e-5) << row << "," << column;
      EXPECT_NEAR(XyzToLinearSrgbMatrix()[column][row], to_rgb[row][column], 5e-4) << row << "," << column;
      EXPECT_NEAR(identity[column][row], row == column ? 1.0 : 0.0, 1e-12);
    }
  }
  // Y's row is Rec. 709's luminance, the report's weights.
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(LinearSrgbToXyzMatrix()[c][1], report::kLuminanceWeights[c], 6e-5);
}

// The runtime's XyzToLinearSrgb (its matrix written out in
// aerial_perspective.glsl) is the matrix derived here from the primaries,
// to the 7 decimals it is written with, and turns the sRGB white (x, y) =
// (0.3127, 0.3290) at Y = 1 into (1, 1, 1).
TEST(Colour, RuntimeConvertsXyzToLinearSrgb) {
  for (int k = 0; k < 3; ++k) {
    glm::dvec3 unit(0.0);
    unit[k] = 1.0;
    const glm::dvec3 runtime = glsl::XyzToLinearSrgb(unit), derived = XyzToLinearSrgbMatrix() * unit;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(runtime[c], derived[c], 1e-6) << k << " " << c;
  }
  const glm::dvec3 white(0.3127 / 0.3290, 1.0, (1.0 - 0.3127 - 0.3290) / 0.3290);
  const glm::dvec3 rgb = glsl::XyzToLinearSrgb(white);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(rgb[c], 1.0, 1e-6) << c;
}

TEST(Colour, D65IsSrgbWhite) {
  const glm::dvec3 xyz = D65Xyz();
  const glm::dvec3 rgb = XyzToLinearSrgbMatrix() * (xyz / xyz.y);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(rgb[c], 1.0, 5e-4) << c;
}

// SpectrumToXyz is linear (XyzWeights reproduces it) and takes the spectrum
// as linear between samples: a straight line given by 15 samples integrates
// as the same line given on the observer's whole grid.
TEST(Colour, WeightsAndInterpolationAreConsistent) {
  std::vector<double> nm;
  for (int i = 0; i < 15; ++i) nm.push_back(360.0 + i * (830.0 - 360.0) / 14.0);
  std::mt19937 random(3);
  std::uniform_real_distribution<double> uniform(0.0, 2.0);
  std::vector<double> v;
  for (std::size_t i = 0; i < nm.size(); ++i) v.push_back(uniform(random));
  const std::vector<glm::dvec3> w = XyzWeights(nm);
  glm::dvec3 sum(0.0);
  for (std::size_t i = 0; i < nm.size(); ++i) sum += w[i] * v[i];
  const glm::dvec3 direct = SpectrumToXyz(nm, v);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(sum[c], direct[c], 1e-12 * std::abs(direct[c]));

  auto line = [](double lambda) { return 0.5 + 0.002 * (lambda - 360.0); };
  std::vector<double> sparse, dense_nm = Wavelengths(Cie1931Observer()), dense;
  for (double lambda : nm) sparse.push_back(line(lambda));
  for (double lambda : dense_nm) dense.push_back(line(lambda));
  const glm::dvec3 a = SpectrumToXyz(nm, sparse), b = SpectrumToXyz(dense_nm, dense);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], 1e-12 * b[c]);
}

}  // namespace
}  // namespace skybake
