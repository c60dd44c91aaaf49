#include "fit/solver.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include <ceres/ceres.h>
#include <tbb/parallel_for.h>

namespace skybake::fit {

namespace {

struct LogResidual {
  FormKind kind;
  double mu, t, ln_target;
  template <typename T>
  bool operator()(const T* coefficients, T* residual) const {
    using std::log;
    residual[0] = log(EvaluateForm(kind, coefficients, mu, t)) - T(ln_target);
    return true;
  }
};

bool AllFinite(const std::array<double, kCoefficientCount>& c) {
  return std::all_of(c.begin(), c.end(), [](double v) { return std::isfinite(v); });
}

SolverResult SolveFrom(FormKind kind, const FitSamples& samples,
                       std::array<double, kCoefficientCount> coefficients, bool single_altitude) {
  ceres::Problem problem;
  double* x = coefficients.data();
  for (size_t i = 0; i < samples.mu.size(); ++i) {
    // No robust loss: the samples are exact to 1e-8 and noise-free, so there
    // are no outliers to discount; a robust loss would only trade the largest
    // errors (near the horizon) for smaller ones elsewhere (see the README).
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<LogResidual, 1, kCoefficientCount>(
            new LogResidual{kind, samples.mu[i], samples.t[i], samples.ln_target[i]}),
        nullptr, x);
  }
  if (single_altitude) {
    // One altitude: only the t = 0 nodes are determined; τ does not matter.
    std::vector<int> constant{kLayerTopCoefficient};
    for (int k = 0; k < kShapeParameters; ++k) {
      constant.push_back(3 * k + 1);
      constant.push_back(3 * k + 2);
    }
    problem.SetManifold(x, new ceres::SubsetManifold(kCoefficientCount, constant));
  }
  for (int index = 0; index < kCoefficientCount; ++index) {
    ParameterBounds bounds = Bounds(kind, std::min(index / 3, kShapeParameters));
    x[index] = std::clamp(x[index], bounds.lower, bounds.upper);
    problem.SetParameterLowerBound(x, index, bounds.lower);
    problem.SetParameterUpperBound(x, index, bounds.upper);
  }

  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 200;
  options.function_tolerance = 1e-12;
  options.gradient_tolerance = 1e-14;
  options.parameter_tolerance = 1e-10;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);

  if (single_altitude) {
    for (int k = 0; k < kShapeParameters; ++k) x[3 * k + 1] = x[3 * k + 2] = x[3 * k];
  }
  SolverResult result;
  result.coefficients = coefficients;
  result.final_cost = summary.final_cost;
  result.iterations = static_cast<int>(summary.iterations.size());
  result.termination = ceres::TerminationTypeToString(summary.termination_type);
  result.usable = summary.termination_type != ceres::FAILURE &&
                  summary.termination_type != ceres::USER_FAILURE &&
                  std::isfinite(summary.final_cost) && AllFinite(coefficients);
  return result;
}

}  // namespace

SolverResult SolveForm(FormKind kind, const FitSamples& samples,
                       const std::vector<std::array<double, kCoefficientCount>>& initial_guesses,
                       bool single_altitude) {
  // The starts are independent solves; run them side by side.
  std::vector<SolverResult> results(initial_guesses.size());
  tbb::parallel_for(size_t{0}, initial_guesses.size(), [&](size_t i) {
    if (AllFinite(initial_guesses[i])) results[i] = SolveFrom(kind, samples, initial_guesses[i], single_altitude);
  });
  SolverResult best;
  for (const SolverResult& result : results)  // in order, so ties resolve the same way every run
    if (result.usable && (!best.usable || result.final_cost < best.final_cost)) best = result;
  return best;
}

}  // namespace skybake::fit
