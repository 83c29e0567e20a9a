#include "support/stats.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace candela::test {
namespace {

// P(a, x) by its power series, for x < a + 1
double gamma_p_series(double a, double x) {
  double term = 1.0 / a, sum = term;
  for (int n = 1; n < 10000; ++n) {
    term *= x / (a + n);
    sum += term;
    if (std::fabs(term) < std::fabs(sum) * 1e-15) break;
  }
  return sum * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

// Q(a, x) by its continued fraction (modified Lentz), for x >= a + 1
double gamma_q_fraction(double a, double x) {
  const double tiny = 1e-300;
  double b = x + 1.0 - a, c = 1.0 / tiny, d = 1.0 / b, h = d;
  for (int i = 1; i < 10000; ++i) {
    double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::fabs(d) < tiny) d = tiny;
    c = b + an / c;
    if (std::fabs(c) < tiny) c = tiny;
    d = 1.0 / d;
    double delta = d * c;
    h *= delta;
    if (std::fabs(delta - 1.0) < 1e-15) break;
  }
  return std::exp(-x + a * std::log(x) - std::lgamma(a)) * h;
}

}  // namespace

double gamma_q(double a, double x) {
  if (x <= 0.0) return 1.0;
  return x < a + 1.0 ? 1.0 - gamma_p_series(a, x) : gamma_q_fraction(a, x);
}

double sidak_alpha(double alpha, int m) { return 1.0 - std::pow(1.0 - alpha, 1.0 / m); }

ChiSquare chi_square_test(const std::vector<double>& observed, const std::vector<double>& expected,
                          double min_expected) {
  std::vector<std::pair<double, double>> cells;  // (expected, observed)
  double pool_e = 0.0, pool_o = 0.0;
  for (size_t i = 0; i < observed.size(); ++i) {
    if (expected[i] < min_expected) {
      pool_e += expected[i];
      pool_o += observed[i];
    } else {
      cells.emplace_back(expected[i], observed[i]);
    }
  }
  if (pool_e > 0.0 || pool_o > 0.0) {
    if (pool_e < min_expected && !cells.empty()) {
      auto smallest = std::min_element(cells.begin(), cells.end());
      smallest->first += pool_e;
      smallest->second += pool_o;
    } else {
      cells.emplace_back(pool_e, pool_o);
    }
  }
  ChiSquare r;
  for (const auto& [e, o] : cells) {
    if (e <= 0.0) {
      // Samples where the pdf says none can land: certain rejection
      if (o > 0.0) r.statistic = INFINITY;
      continue;
    }
    r.statistic += (o - e) * (o - e) / e;
  }
  r.dof = int(cells.size()) - 1;
  r.p_value = std::isfinite(r.statistic) ? gamma_q(0.5 * r.dof, 0.5 * r.statistic) : 0.0;
  return r;
}

}  // namespace candela::test
