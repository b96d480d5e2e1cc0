#pragma once

#include <iosfwd>
#include <string>
#include <vector>

namespace Suspension::Postprocess
{
  /// The standard error of the mean of a series whose samples are
  /// correlated in time, by blocking (Flyvbjerg & Petersen, J. Chem. Phys.
  /// 91, 461, 1989): neighbouring samples are averaged in pairs, again and
  /// again; the naive error of the block means, s_B = sd_B / sqrt(n / B),
  /// grows with the block length B until blocks outlast the correlation
  /// time and then levels off. The level taken is the shortest block with
  /// B^3 > 2 n (s_B / s_1)^4 (Lee, Drummond & Needs, Phys. Rev. E 83,
  /// 066706, 2011): long enough for the correlation, short enough to keep
  /// many blocks. If no level with at least `min_blocks` blocks satisfies
  /// it, the longest such level is taken and `converged` is false (the
  /// series is too short for its correlation time: the error is a lower
  /// bound).
  struct BlockedError
  {
    double       error        = 0.;   // correlated samples
    double       naive        = 0.;   // as if independent
    unsigned int block_length = 1;    // samples per block where `error` was found
    bool         converged    = true; // the criterion was met
  };

  BlockedError blocked_error(const std::vector<double> &series, unsigned int min_blocks = 4);

  /**
   * Decides when monitored quantities (for a channel: the effective
   * viscosity and the solid's mean distance from the walls) stop drifting:
   * at every sample, the means over the last two windows of length
   * `window`, (t - 2w, t - w] and (t - w, t], are compared; the series is
   * steady at the first sample at which every mean changes by less than
   * `tolerance` relative to the newer one, or by less than the windows'
   * own scatter explains (two standard errors of the difference of the
   * two means, each by blocking): a change within the noise is not a
   * drift. With window = 0 the detector is off and steady() is true from
   * the first sample.
   */
  class SteadyStateDetector
  {
  public:
    SteadyStateDetector(double window, double tolerance);

    /// One sample; true if this sample is the one that makes it steady.
    bool add(double time, const std::vector<double> &values);

    bool   measured() const { return window > 0; }
    bool   steady() const { return !measured() || is_steady; }
    double steady_time() const { return t_steady; }
    /// relative change of each monitored mean at the last comparison
    /// (empty before the first: less than two windows of samples)
    const std::vector<double> &changes() const { return last_changes; }

    /// "steady from t = 3.2: over two windows of 1, mu_eff changed 0.1 %,
    /// wall distance 0.3 % (< 0.5 %)", or why not yet; `names` name the
    /// monitored values.
    std::string describe(const std::vector<std::string> &names, double last_time) const;

    void save(std::ostream &out) const;
    void load(std::istream &in);

  private:
    double                           window, tolerance;
    std::vector<double>              times;
    std::vector<std::vector<double>> values;
    bool                             is_steady = false;
    double                           t_steady  = 0.;
    std::vector<double>              last_changes;
    /// the change each could make and count as steady: max(tolerance, 2 sigma)
    std::vector<double>              last_allowed;
  };
} // namespace Suspension::Postprocess
