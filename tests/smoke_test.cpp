#include <gtest/gtest.h>

#include "bake/atmosphere.h"

TEST(Atmosphere, RayleighPhaseIsSymmetric) {
  skybake::PhaseFunction phase{skybake::PhaseKind::kRayleigh, 0.0};
  EXPECT_DOUBLE_EQ(phase.Evaluate(0.5), phase.Evaluate(-0.5));
}
