// Postprocess::blocked_error and SteadyStateDetector against exact values:
// 1. independent samples (n = 2^16, unit variance): the standard error of
//    the mean is 1/sqrt(n); naive and blocked estimates agree with it;
// 2. an AR(1) series x_{i+1} = rho x_i + sqrt(1 - rho^2) e_i, rho = 0.9:
//    the exact standard error of the mean is, for n >> 1,
//    sqrt((1 + rho) / (1 - rho) / n), 4.36 times the naive one; blocking
//    must find it (within 10 %: the level chosen keeps about 100 blocks,
//    whose estimate scatters by about 7 %);
// 3. y(t) = 1 + exp(-t / tau), tau = 0.5, sampled every 0.01 and watched
//    over windows of w = 1 with tolerance 0.5 %: steady at the first
//    sample where the two windows' means (sums over their samples) differ
//    by less than 0.5 %, computed here directly (t* = 4.157 for the
//    continuous means);
// 4. a linear drift y = 1 + 0.1 t never counts as steady by t = 20;
// 5. too short a series for its correlation: 64 samples of the AR(1)
//    series are flagged as not converged;
// 6. noise is not drift: y = 1 + 0.01 e (e independent, unit variance),
//    sampled every 0.01 over windows of 1, tolerance 0.1 %: the two
//    windows' means differ by about 0.01 sqrt(2/100) = 0.14 %, more than
//    the tolerance, but within two standard errors (0.28 %): steady at the
//    first comparison, t = 2; the same noise on a drift of 5 % per time
//    unit is not steady by t = 20.

#include <suspension/postprocess/stationarity.h>

#include <cmath>
#include <fstream>
#include <iomanip>
#include <random>
#include <string>
#include <vector>

using namespace Suspension::Postprocess;

int main()
{
  std::ofstream out("output");
  out << std::setprecision(4);
  const std::size_t                n = 1 << 16;
  std::mt19937_64                  random(12345);
  std::normal_distribution<double> normal(0., 1.);

  std::vector<double> independent(n);
  for (auto &x : independent)
    x = normal(random);
  const auto   a     = blocked_error(independent);
  const double exact = 1. / std::sqrt(double(n));
  out << "independent: naive / exact = " << a.naive / exact << ", blocked / exact = " << a.error / exact
      << "; naive within 2 %: " << (std::abs(a.naive / exact - 1) < 0.02 ? "yes" : "no")
      << ", blocked within 5 %: " << (std::abs(a.error / exact - 1) < 0.05 ? "yes" : "no")
      << ", converged: " << (a.converged ? "yes" : "no") << std::endl;

  const double        rho = 0.9;
  std::vector<double> ar(n);
  double              x = normal(random);
  for (auto &v : ar)
    {
      v = x;
      x = rho * x + std::sqrt(1. - rho * rho) * normal(random);
    }
  const auto   b         = blocked_error(ar);
  const double exact_ar  = std::sqrt((1. + rho) / (1. - rho) / double(n));
  out << "AR(1), rho = 0.9: exact / naive = " << exact_ar / b.naive
      << " (theory sqrt(19) = " << std::sqrt(19.) << "), blocked / exact = " << b.error / exact_ar
      << ", within 10 %: " << (std::abs(b.error / exact_ar - 1) < 0.1 ? "yes" : "no")
      << ", converged: " << (b.converged ? "yes" : "no")
      << ", block length >= 2 tau_int = 19 samples: " << (b.block_length >= 19 ? "yes" : "no")
      << std::endl;

  // 3: the detector against the same comparison done by hand
  const double        tau = 0.5, w = 1., tolerance = 0.005, dt = 0.01;
  SteadyStateDetector detector(w, tolerance);
  std::vector<double> t, y;
  double              found = -1., expected = -1.;
  for (unsigned int i = 0; i <= 1000; ++i)
    {
      t.push_back(i * dt);
      y.push_back(1. + std::exp(-t.back() / tau));
      if (detector.add(t.back(), {y.back()}) && found < 0)
        found = t.back();
      // by hand: samples with age in [0, w) and [w, 2w)
      if (expected < 0 && t.back() >= 2. * w - 1e-12)
        {
          double older = 0., newer = 0.;
          int    n_older = 0, n_newer = 0;
          for (std::size_t s = 0; s < t.size(); ++s)
            {
              const double age = t.back() - t[s];
              if (age < w - 1e-9)
                newer += y[s], ++n_newer;
              else if (age < 2. * w - 1e-9)
                older += y[s], ++n_older;
            }
          const double mo = older / n_older, mn = newer / n_newer;
          if (std::abs(mn - mo) / mn < tolerance)
            expected = t.back();
        }
    }
  // the continuous means' crossing, for comparison
  const auto change = [&](const double s) {
    const double mo = 1. + tau / w * (std::exp(-(s - 2 * w) / tau) - std::exp(-(s - w) / tau));
    const double mn = 1. + tau / w * (std::exp(-(s - w) / tau) - std::exp(-s / tau));
    return (mo - mn) / mn - tolerance;
  };
  double lo = 2. * w, hi = 10.;
  for (int i = 0; i < 60; ++i)
    (change(0.5 * (lo + hi)) > 0 ? lo : hi) = 0.5 * (lo + hi);
  out << "exponential approach: steady at t = " << found << " (by hand " << expected
      << ", continuous means " << 0.5 * (lo + hi) << "); same as by hand: "
      << (std::abs(found - expected) < 1e-9 ? "yes" : "no")
      << ", within 2 samples of the continuous crossing: "
      << (std::abs(found - 0.5 * (lo + hi)) <= 2 * dt ? "yes" : "no") << std::endl;

  const auto short_series = blocked_error(std::vector<double>(ar.begin(), ar.begin() + 64));
  out << "64 samples of the AR(1) series: converged: " << (short_series.converged ? "yes" : "no")
      << std::endl;

  SteadyStateDetector noisy(w, 0.001), noisy_drift(w, 0.001);
  double              noisy_at = -1.;
  for (unsigned int i = 0; i <= 2000; ++i)
    {
      const double e = normal(random);
      if (noisy.add(i * dt, {1. + 0.01 * e}) && noisy_at < 0)
        noisy_at = i * dt;
      noisy_drift.add(i * dt, {1. + 0.05 * i * dt + 0.01 * e});
    }
  out << "noise alone: steady at t = " << noisy_at << " (the first comparison, t = 2: "
      << (std::abs(noisy_at - 2.) < 1e-9 ? "yes" : "no") << "); noise on a drift: steady by t = 20: "
      << (noisy_drift.steady() ? "yes" : "no") << std::endl;
  // the verdict names a change beyond the noise allowance as such
  const std::string drift_text = noisy_drift.describe({"y"}, 20.);
  out << "noise on a drift, verdict says above its noise: "
      << (drift_text.find("above its noise") != std::string::npos ? "yes" : "no")
      << ", within its noise: "
      << (drift_text.find("within its noise") != std::string::npos ? "yes" : "no") << std::endl;

  SteadyStateDetector drifting(w, tolerance);
  for (unsigned int i = 0; i <= 2000; ++i)
    drifting.add(i * dt, {1. + 0.1 * i * dt});
  out << "linear drift: steady by t = 20: " << (drifting.steady() ? "yes" : "no")
      << ", last change " << 100. * drifting.changes()[0] << " % (exact 0.1 / 2.95 = "
      << 100. * 0.1 / 2.95 << " %)" << std::endl;
}
