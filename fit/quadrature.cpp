#include "fit/quadrature.h"

#include <algorithm>
#include <cmath>
#include <queue>

namespace skybake::fit {

namespace {

// QUADPACK qk15 abscissae (positive half, last = centre) and weights.
constexpr double kNodes[8] = {
    0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
    0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
    0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
    0.207784955007898467600689403773245, 0.000000000000000000000000000000000};
constexpr double kKronrodWeights[8] = {
    0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
    0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
    0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
    0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
// Gauss weights for the odd-indexed nodes 1, 3, 5 and the centre 7.
constexpr double kGaussWeights[4] = {
    0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
    0.381830050505118944950369775488975, 0.417959183673469387755102040816327};

struct Panel {
  double a, b, value, error;
  bool operator<(const Panel& o) const { return error < o.error; }  // max-heap on error
};

Panel Rule(const std::function<double(double)>& f, double a, double b) {
  double centre = 0.5 * (a + b);
  double half = 0.5 * (b - a);
  double fc = f(centre);
  double kronrod = fc * kKronrodWeights[7];
  double gauss = fc * kGaussWeights[3];
  for (int i = 0; i < 7; ++i) {
    double dx = half * kNodes[i];
    double pair = f(centre - dx) + f(centre + dx);
    kronrod += kKronrodWeights[i] * pair;
    if (i % 2 == 1) gauss += kGaussWeights[i / 2] * pair;
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
