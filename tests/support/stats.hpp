// Statistics for tests: chi-square goodness of fit with pooling, normal tail bounds.
#pragma once

#include <vector>

namespace candela::test {

struct ChiSquare {
  double statistic = 0.0;
  int dof = 0;
  double p_value = 1.0;
};

// Pearson's test of observed counts against expected counts. Cells whose expected count
// is below min_expected are pooled into one cell (merged with the smallest cell when
// the pool stays too small).
ChiSquare chi_square_test(const std::vector<double>& observed, const std::vector<double>& expected,
                          double min_expected = 5.0);

// Regularized upper incomplete gamma function Q(a, x)
double gamma_q(double a, double x);

// Per-test significance that keeps the family-wise error at alpha over m tests (Sidak)
double sidak_alpha(double alpha, int m);

}  // namespace candela::test
