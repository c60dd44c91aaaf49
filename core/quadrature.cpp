#include "core/quadrature.h"

#include <cmath>

#include "core/constants.h"

namespace skybake {

void AppendGaussLegendre(int n, double a, double b, std::vector<double>& nodes, std::vector<double>& weights) {
  for (int i = 0; i < n; ++i) {
    double x = std::cos(kPi * (i + 0.75) / (n + 0.5));
    double derivative = 1.0;
    for (int iteration = 0; iteration < 100; ++iteration) {
      double p0 = 1.0, p1 = x;
      for (int k = 2; k <= n; ++k) {
        double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
        p0 = p1, p1 = p2;
      }
      derivative = n * (x * p1 - p0) / (x * x - 1.0);
      double step = p1 / derivative;
      x -= step;
      if (std::abs(step) < 1e-15) break;
    }
    nodes.push_back(0.5 * (a + b) + 0.5 * (b - a) * x);
    weights.push_back((b - a) / ((1.0 - x * x) * derivative * derivative));
  }
}

}  // namespace skybake
