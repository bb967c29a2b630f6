// Test-only helpers: a chi-square goodness-of-fit test of a direction sampler against the
// density it claims, in the style of Mitsuba 3's ChiSquareTest (mitsuba/python/chi2.py), and a
// running mean / standard-error accumulator for Monte Carlo assertions.
//
// The chi-square test:
//   * the sphere of directions is cut into n_cos x n_phi cells, uniform in cos(theta) in [-1, 1]
//     and in phi in [0, 2 pi), so all cells have the same solid angle (d omega = dcos dphi);
//   * n_samples directions are drawn and histogrammed; a sampler may fail (return nullopt), and
//     the failures form one more category, whose expected count is the probability mass the pdf
//     does not account for (a sampler that fails 10% of the time must have a pdf that integrates
//     to 0.9);
//   * the pdf is integrated over each cell with the midpoint rule on sub x sub points in
//     (cos theta, phi), which is exact in measure because the parameterisation has a constant
//     Jacobian; the same integral at half the resolution gives an estimate of its error;
//   * categories whose expected count is below min_expected are pooled (sorted by expected count,
//     merged until the pool reaches min_expected), as Mitsuba does, so the chi-square
//     approximation of the statistic's distribution holds;
//   * the p-value is the upper tail of the chi-square distribution with (categories - 1) degrees
//     of freedom, computed from the regularised upper incomplete gamma function Q(dof/2, x/2)
//     implemented below (series / continued fraction, Numerical Recipes 6.2);
//   * each test rejects at the Sidak-corrected level alpha_1 = 1 - (1 - alpha)^(1/n_tests), where
//     n_tests is the number of chi-square tests in the suite; then the chance that a correct
//     sampler fails any of them is alpha (0.01 by default). With fixed seeds the outcome is
//     deterministic, so this is the chance that the chosen seeds are unlucky.
// Besides the statistic, the fraction of samples that produced a direction ("sample mass") is
// compared with the integral of the pdf ("pdf mass"); a mismatch beyond binomial noise plus the
// integration error estimate is reported and fails the test.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "base/rng.h"
#include "base/vec.h"

namespace bpm {

// ---------------------------------------------------------------------------------------------
// Mean and standard error of i.i.d. samples (Welford's algorithm, in double).
struct MeanAccumulator {
  long long n = 0;
  double mean = 0, m2 = 0;
  double min = std::numeric_limits<double>::infinity(),
         max = -std::numeric_limits<double>::infinity();
  void add(double x) {
    ++n;
    double d = x - mean;
    mean += d / double(n);
    m2 += d * (x - mean);
    min = std::min(min, x);
    max = std::max(max, x);
  }
  double variance() const { return n > 1 ? m2 / double(n - 1) : 0.0; }
  double standard_error() const { return n > 0 ? std::sqrt(variance() / double(n)) : 0.0; }
};

// Number of standard errors allowed when a Monte Carlo mean is compared with its exact value.
// Two-sided, a correct estimator lands outside +-4 standard errors with probability 6.3e-5, so
// that even over the few dozen such checks in the suite a false alarm has probability < 0.5%
// (the same family-wise reasoning as the Sidak correction of the chi-square tests; +-3 would
// give 0.27% per check and several percent over the suite).
constexpr double kMeanTestSigmas = 4.0;

namespace chi2 {

// Regularised lower incomplete gamma P(a, x) by its power series (converges fast for x < a + 1).
inline double gamma_p_series(double a, double x) {
  double ap = a, term = 1.0 / a, sum = term;
  for (int n = 0; n < 100000; ++n) {
    ap += 1;
    term *= x / ap;
    sum += term;
    if (std::fabs(term) < std::fabs(sum) * 1e-16) break;
  }
  return sum * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

// Regularised upper incomplete gamma Q(a, x) by its continued fraction (modified Lentz), for
// x >= a + 1.
inline double gamma_q_continued_fraction(double a, double x) {
  const double tiny = 1e-300;
  double b = x + 1 - a, c = 1 / tiny, d = 1 / b, h = d;
  for (int i = 1; i < 100000; ++i) {
    double an = -i * (i - a);
    b += 2;
    d = an * d + b;
    if (std::fabs(d) < tiny) d = tiny;
    c = b + an / c;
    if (std::fabs(c) < tiny) c = tiny;
    d = 1 / d;
    double del = d * c;
    h *= del;
    if (std::fabs(del - 1) < 1e-16) break;
  }
  return std::exp(-x + a * std::log(x) - std::lgamma(a)) * h;
}

// Q(a, x) = Gamma(a, x) / Gamma(a).
inline double regularized_gamma_q(double a, double x) {
  if (!(x > 0)) return 1;
  if (std::isinf(x)) return 0;
  if (x < a + 1) return std::clamp(1 - gamma_p_series(a, x), 0.0, 1.0);
  return std::clamp(gamma_q_continued_fraction(a, x), 0.0, 1.0);
}

// P(X >= statistic) for X chi-square distributed with dof degrees of freedom.
inline double chi2_survival(double statistic, double dof) {
  if (std::isnan(statistic)) return 0;
  return regularized_gamma_q(0.5 * dof, 0.5 * statistic);
}

// Per-test level such that n_tests independent tests at that level reject anything with
// probability family_alpha (Sidak).
inline double sidak_alpha(double family_alpha, int n_tests) {
  return 1 - std::pow(1 - family_alpha, 1.0 / std::max(1, n_tests));
}

struct Options {
  int n_cos = 10;  // cells in cos(theta), over [-1, 1]
  int n_phi = 20;  // cells in phi, over [0, 2 pi)
  long long n_samples = 200000;
  // pdf evaluations per cell side (even). The midpoint rule errs by O(h^2) where the pdf is
  // smooth but by O(h) across a discontinuity inside a cell (a rough dielectric's transmission
  // pdf drops to zero where the generalized half vector reaches the horizon, while GGX's D there
  // is not zero); 64 keeps the resulting systematic part of the statistic below ~1 for the BSDFs
  // tested here (about 5 with 32).
  int sub = 64;
  double min_expected = 5;  // pooling threshold
  double alpha = 0.01;      // family-wise significance level
  int n_tests = 1;          // chi-square tests in the suite, for the Sidak correction
};

struct Result {
  double statistic = 0;
  int dof = 0;
  double p_value = 0;
  double alpha_per_test = 0;
  int pooled_in = 0, pooled_out = 0;  // categories merged, and pools formed
  long long n_valid = 0;              // samples that returned a direction
  long long n_not_unit = 0;           // returned directions that were not unit length
  long long n_in_zero_cells = 0;      // samples in cells where the pdf integrated to zero
  double sample_mass = 0;             // n_valid / n_samples
  double pdf_mass = 0;                // integral of the pdf over the sphere
  double mass_tolerance = 0;
  bool mass_mismatch = false;
  std::string report;
  bool passed() const {
    return dof >= 1 && std::isfinite(statistic) && p_value > alpha_per_test && n_not_unit == 0 &&
           !mass_mismatch;
  }
};

inline int cos_cell(const Options& o, float z) {
  double t = (std::clamp(double(z), -1.0, 1.0) + 1) / 2;
  return std::clamp(int(t * o.n_cos), 0, o.n_cos - 1);
}
inline int phi_cell(const Options& o, Vec3 w) {
  double phi = std::atan2(double(w.y), double(w.x));
  if (phi < 0) phi += 2 * M_PI;
  return std::clamp(int(phi / (2 * M_PI) * o.n_phi), 0, o.n_phi - 1);
}

// Integral of pdf over cell (i, j) by the midpoint rule with s x s points.
template <class Pdf>
double integrate_cell(const Options& o, Pdf& pdf, int i, int j, int s) {
  double dz = 2.0 / o.n_cos / s, dphi = 2 * M_PI / o.n_phi / s;
  double z0 = -1 + 2.0 * i / o.n_cos, phi0 = 2 * M_PI * j / o.n_phi;
  double sum = 0;
  for (int a = 0; a < s; ++a) {
    double z = z0 + (a + 0.5) * dz;
    double r = std::sqrt(std::max(0.0, 1 - z * z));
    for (int b = 0; b < s; ++b) {
      double phi = phi0 + (b + 0.5) * dphi;
      Vec3 w(float(r * std::cos(phi)), float(r * std::sin(phi)), float(z));
      double p = pdf(w);
      if (std::isfinite(p) && p > 0) sum += p;
    }
  }
  return sum * dz * dphi;
}

// Histogram of n_samples directions drawn by sample(Rng&) from one stream of `seed`; counts the
// valid and the non-unit directions in r.
template <class Sampler>
std::vector<double> histogram(Sampler& sample, uint64_t seed, const Options& o, Result& r) {
  std::vector<double> observed(o.n_cos * o.n_phi, 0.0);
  Rng rng(seed);
  for (long long k = 0; k < o.n_samples; ++k) {
    std::optional<Vec3> w = sample(rng);
    if (!w) continue;
    if (!is_finite(*w) || std::fabs(length(*w) - 1) > 1e-3f) {
      ++r.n_not_unit;
      continue;
    }
    ++r.n_valid;
    observed[cos_cell(o, w->z) * o.n_phi + phi_cell(o, *w)] += 1;
  }
  return observed;
}

// Expected counts per cell of n samples, and the pdf's integral over the sphere in r.pdf_mass;
// *mass_half: that integral at half the resolution.
template <class Pdf>
std::vector<double> expected_counts(Pdf& pdf, double n, const Options& o, Result& r,
                                    double* mass_half) {
  std::vector<double> expected(o.n_cos * o.n_phi);
  for (int i = 0; i < o.n_cos; ++i)
    for (int j = 0; j < o.n_phi; ++j) {
      double m = integrate_cell(o, pdf, i, j, o.sub);
      expected[i * o.n_phi + j] = m * n;
      r.pdf_mass += m;
      *mass_half += integrate_cell(o, pdf, i, j, std::max(1, o.sub / 2));
    }
  return expected;
}

// Mass check: n_valid is binomial(n, pdf_mass) when the pdf is right; allow 5 standard
// deviations of that, twice the integration error estimate (the difference between the two
// resolutions, doubled because across discontinuities the error does not shrink monotonically)
// and 1e-5 for the float rounding of pdf values.
inline void check_mass(double n, double mass_half, Result& r) {
  r.sample_mass = double(r.n_valid) / n;
  double pm = std::clamp(r.pdf_mass, 0.0, 1.0);
  r.mass_tolerance =
      5 * std::sqrt(pm * (1 - pm) / n) + 2 * std::fabs(r.pdf_mass - mass_half) + 1e-5;
  r.mass_mismatch = std::fabs(r.sample_mass - r.pdf_mass) > r.mass_tolerance;
}

// The statistic over the categories (cells plus "sampler failed"), those with small expected
// counts pooled, and its p-value, in r. Returns each unpooled category's contribution with its
// cell (-1: the failures), for the report.
inline std::vector<std::pair<double, int>> pooled_statistic(const std::vector<double>& expected,
                                                            const std::vector<double>& observed,
                                                            double n, const Options& o, Result& r) {
  struct Cat {
    double e, o;
    int cell;
  };
  const int n_cells = int(expected.size());
  std::vector<Cat> cats;
  cats.reserve(n_cells + 1);
  for (int c = 0; c < n_cells; ++c) cats.push_back({expected[c], observed[c], c});
  cats.push_back({std::max(0.0, n - n * r.pdf_mass), n - double(r.n_valid), -1});
  std::stable_sort(cats.begin(), cats.end(), [](const Cat& a, const Cat& b) { return a.e < b.e; });

  double stat = 0, pool_e = 0, pool_o = 0;
  int k = 0;
  std::vector<std::pair<double, int>> contributions;  // (contribution, cell) for the report
  for (const Cat& c : cats) {
    if (c.e == 0 && c.o == 0) continue;
    if (c.e < o.min_expected) {
      pool_e += c.e;
      pool_o += c.o;
      ++r.pooled_in;
      if (pool_e >= o.min_expected) {
        stat += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
        ++k;
        ++r.pooled_out;
        pool_e = pool_o = 0;
      }
      continue;
    }
    double e = c.e + pool_e, ob = c.o + pool_o;  // a remaining small pool joins the next cell
    pool_e = pool_o = 0;
    double contrib = (ob - e) * (ob - e) / e;
    stat += contrib;
    contributions.push_back({contrib, c.cell});
    ++k;
  }
  if (pool_e > 0 || pool_o > 0) {
    stat += pool_e > 0 ? (pool_o - pool_e) * (pool_o - pool_e) / pool_e
                       : std::numeric_limits<double>::infinity();
    ++k;
  }
  r.statistic = stat;
  r.dof = k - 1;
  r.p_value = r.dof >= 1 ? chi2_survival(stat, r.dof) : 0.0;
  return contributions;
}

// The report: the outcome, then the six categories that contribute most.
inline std::string report(const Result& r, std::vector<std::pair<double, int>> contributions,
                          const std::vector<double>& expected, const std::vector<double>& observed,
                          double n, const Options& o) {
  std::ostringstream os;
  os << "chi2 = " << r.statistic << ", dof = " << r.dof << ", p = " << r.p_value
     << " (reject below " << r.alpha_per_test << "), pooled " << r.pooled_in << " categories into "
     << r.pooled_out << "; sample mass " << r.sample_mass << " vs pdf mass " << r.pdf_mass
     << " (tolerance " << r.mass_tolerance << (r.mass_mismatch ? ", MISMATCH" : "") << "); "
     << r.n_not_unit << " non-unit directions; " << r.n_in_zero_cells
     << " samples in cells of zero pdf\n";
  std::sort(contributions.begin(), contributions.end(),
            [](auto& a, auto& b) { return a.first > b.first; });
  for (size_t q = 0; q < std::min<size_t>(6, contributions.size()); ++q) {
    int c = contributions[q].second;
    if (c < 0) {
      os << "  failures: observed " << (n - double(r.n_valid)) << ", expected "
         << (n - n * r.pdf_mass) << "\n";
      continue;
    }
    int i = c / o.n_phi, j = c % o.n_phi;
    os << "  cell cos[" << (-1 + 2.0 * i / o.n_cos) << ", " << (-1 + 2.0 * (i + 1) / o.n_cos)
       << ") phi[" << (2 * M_PI * j / o.n_phi) << ", " << (2 * M_PI * (j + 1) / o.n_phi)
       << "): observed " << observed[c] << ", expected " << expected[c] << ", contribution "
       << contributions[q].first << "\n";
  }
  return os.str();
}

// sample(Rng&) -> std::optional<Vec3>; pdf(Vec3) -> double (solid-angle density).
template <class Sampler, class Pdf>
Result run(Sampler&& sample, Pdf&& pdf, uint64_t seed, const Options& o = {}) {
  Result r;
  const double n = double(o.n_samples);
  r.alpha_per_test = sidak_alpha(o.alpha, o.n_tests);
  const std::vector<double> observed = histogram(sample, seed, o, r);
  double mass_half = 0;
  const std::vector<double> expected = expected_counts(pdf, n, o, r, &mass_half);
  for (size_t c = 0; c < expected.size(); ++c)
    if (expected[c] == 0) r.n_in_zero_cells += (long long)observed[c];
  check_mass(n, mass_half, r);
  const std::vector<std::pair<double, int>> contributions =
      pooled_statistic(expected, observed, n, o, r);
  r.report = report(r, contributions, expected, observed, n, o);
  return r;
}

}  // namespace chi2
}  // namespace bpm
