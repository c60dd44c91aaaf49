#include "fit/quadrature.h"

#include <algorithm>
#include <cmath>
#include <queue>

#include "core/quadrature.h"

namespace skybake::fit {

namespace {

struct Panel {
  double a, b, value, error;
  bool operator<(const Panel& o) const { return error < o.error; }  // max-heap on error
};

Panel Rule(const std::function<double(double)>& f, double a, double b) {
  double centre = 0.5 * (a + b);
  double half = 0.5 * (b - a);
  double fc = f(centre);
  double kronrod = fc * GaussKronrod15Rule::kKronrodWeights[7];
  double gauss = fc * GaussKronrod15Rule::kGaussWeights[3];
  for (int i = 0; i < 7; ++i) {
    double dx = half * GaussKronrod15Rule::kNodes[i];
    double pair = f(centre - dx) + f(centre + dx);
    kronrod += GaussKronrod15Rule::kKronrodWeights[i] * pair;
    if (i % 2 == 1) gauss += GaussKronrod15Rule::kGaussWeights[i / 2] * pair;
  }
  return {a, b, kronrod * half, std::abs((kronrod - gauss) * half)};
}

}  // namespace

QuadratureResult Integrate(const std::function<double(double)>& f, double a, double b,
                           const std::vector<double>& breakpoints,
                           const QuadratureOptions& options) {
  QuadratureResult result;
  if (!(b > a)) return result;

  std::vector<double> edges{a, b};
  for (double p : breakpoints)
    if (p > a && p < b) edges.push_back(p);
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());

  std::priority_queue<Panel> panels;
  std::vector<Panel> finished;  // panels too narrow to split further
  double value = 0.0, error = 0.0;
  for (size_t i = 0; i + 1 < edges.size(); ++i) {
    Panel p = Rule(f, edges[i], edges[i + 1]);
    result.evaluations += 15;
    value += p.value;
    error += p.error;
    panels.push(p);
  }

  auto tolerance = [&] {
    return std::max(options.absolute_tolerance, options.relative_tolerance * std::abs(value));
  };
  while (!panels.empty() && error > tolerance()) {
    if (static_cast<int>(panels.size() + finished.size()) >= options.max_panels) {
      result.converged = false;
      break;
    }
    Panel worst = panels.top();
    panels.pop();
    double mid = 0.5 * (worst.a + worst.b);
    if (!(mid > worst.a && mid < worst.b)) {  // no representable split left
      finished.push_back(worst);
      result.converged = false;
      continue;
    }
    Panel left = Rule(f, worst.a, mid);
    Panel right = Rule(f, mid, worst.b);
    result.evaluations += 30;
    value += left.value + right.value - worst.value;
    error += left.error + right.error - worst.error;
    panels.push(left);
    panels.push(right);
  }

  // Re-sum from the panels: the running total accumulates cancellation error.
  result.value = 0.0;
  result.error_estimate = 0.0;
  result.panels = static_cast<int>(panels.size() + finished.size());
  for (; !panels.empty(); panels.pop()) finished.push_back(panels.top());
  std::sort(finished.begin(), finished.end(),
            [](const Panel& x, const Panel& y) { return std::abs(x.value) < std::abs(y.value); });
  for (const Panel& p : finished) {
    result.value += p.value;
    result.error_estimate += p.error;
  }
  if (result.error_estimate > tolerance()) result.converged = false;
  return result;
}

}  // namespace skybake::fit
