// The least-squares fit of one form to sampled relative optical paths. The
// only translation unit that includes Ceres (solver.cpp).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "fit/forms.h"

namespace skybake::fit {

// Samples to fit: residual_i = ln m_form(mu_i, t_i) - ln_target_i.
struct FitSamples {
  std::vector<double> mu, t, ln_target;
};

struct SolverResult {
  std::array<double, kCoefficientCount> coefficients{};
  double final_cost = 0.0;  // 1/2 Σ residual²
  int iterations = 0;
  std::string termination;  // Ceres' termination type, e.g. "CONVERGENCE"
  bool usable = false;      // Ceres produced finite coefficients and cost
};

// Levenberg-Marquardt with automatic derivatives from each initial guess;
// returns the lowest-cost usable result (usable = false if none is).
// `single_altitude`: all samples share t = 0, so only the t = 0 node of each
// parameter is fitted and the others are set equal to it.
SolverResult SolveForm(FormKind kind, const FitSamples& samples,
                       const std::vector<std::array<double, kCoefficientCount>>& initial_guesses,
                       bool single_altitude);

}  // namespace skybake::fit
