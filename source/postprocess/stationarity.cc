#include <suspension/postprocess/stationarity.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <istream>
#include <ostream>
#include <sstream>
#include <stdexcept>

namespace Suspension::Postprocess
{
  namespace
  {
    double naive_error(const std::vector<double> &x)
    {
      const std::size_t n = x.size();
      if (n < 2)
        return 0.;
      double mean = 0.;
      for (const double v : x)
        mean += v;
      mean /= n;
      double m2 = 0.;
      for (const double v : x)
        m2 += (v - mean) * (v - mean);
      return std::sqrt(m2 / (n - 1) / n);
    }
  } // namespace

  BlockedError blocked_error(const std::vector<double> &series, const unsigned int min_blocks)
  {
    BlockedError        result;
    std::vector<double> blocks = series;
    const double        n      = series.size();
    result.naive               = naive_error(blocks);
    result.error               = result.naive;
    if (series.size() < 2 * std::max(min_blocks, 1u) || !(result.naive > 0.))
      return result;
    result.converged = false;
    for (unsigned int length = 1; blocks.size() >= min_blocks; length *= 2)
      {
        const double e = naive_error(blocks);
        result.error        = e;
        result.block_length = length;
        const double ratio  = e / result.naive;
        if (std::pow(double(length), 3) > 2. * n * std::pow(ratio, 4))
          {
            result.converged = true;
            break;
          }
        std::vector<double> halved(blocks.size() / 2);
        for (std::size_t i = 0; i < halved.size(); ++i)
          halved[i] = 0.5 * (blocks[2 * i] + blocks[2 * i + 1]);
        blocks.swap(halved);
      }
    return result;
  }

  SteadyStateDetector::SteadyStateDetector(const double window, const double tolerance)
    : window(window)
    , tolerance(tolerance)
  {}

  bool SteadyStateDetector::add(const double time, const std::vector<double> &sample)
  {
    if (!measured() || is_steady)
      return false;
    times.push_back(time);
    values.push_back(sample);
    if (time - times.front() < 2. * window * (1. - 1e-9))
      return false;
    // the samples of (t - 2w, t - w] and (t - w, t], per monitored value
    const std::size_t                n = sample.size();
    std::vector<std::vector<double>> older(n), newer(n);
    for (std::size_t s = times.size(); s-- > 0;)
      {
        const double age = time - times[s];
        if (age >= 2. * window * (1. - 1e-9))
          break;
        auto &side = age < window * (1. - 1e-9) ? newer : older;
        for (std::size_t c = 0; c < n; ++c)
          side[c].push_back(values[s][c]);
      }
    if (older[0].empty() || newer[0].empty())
      return false;
    const auto mean = [](const std::vector<double> &x) {
      double sum = 0.;
      for (const double v : x)
        sum += v;
      return sum / x.size();
    };
    last_changes.assign(n, 0.);
    last_allowed.assign(n, tolerance);
    bool within = true;
    for (std::size_t c = 0; c < n; ++c)
      {
        // the samples are stored newest first: their order does not
        // matter for the mean, and blocking sees the same neighbours
        const double a = mean(older[c]), b = mean(newer[c]);
        const double scale = std::max(std::abs(b), 1e-300);
        last_changes[c]    = std::abs(b - a) / scale;
        // a change the windows' own scatter explains is not a drift: two
        // standard errors of the difference of two blocked means
        const double ea = blocked_error(older[c]).error, eb = blocked_error(newer[c]).error;
        last_allowed[c] = std::max(tolerance, 2. * std::sqrt(ea * ea + eb * eb) / scale);
        within          = within && last_changes[c] < last_allowed[c];
      }
    if (!within)
      return false;
    is_steady = true;
    t_steady  = time;
    times.clear();
    values.clear();
    return true;
  }

  std::string SteadyStateDetector::describe(const std::vector<std::string> &names,
                                            const double                    last_time) const
  {
    std::ostringstream s;
    const auto         percent = [](const double x) {
      std::ostringstream p;
      p << std::fixed << std::setprecision(2) << 100. * x << " %";
      return p.str();
    };
    const auto changes_text = [&]() {
      std::string text;
      for (std::size_t c = 0; c < last_changes.size() && c < names.size(); ++c)
        {
          text += (c > 0 ? ", " : "") + names[c] + " " + percent(last_changes[c]);
          if (c < last_allowed.size() && last_allowed[c] > tolerance)
            text += std::string(last_changes[c] < last_allowed[c] ? " (within" : " (above") +
                    " its noise, 2 sigma = " + percent(last_allowed[c]) + ")";
        }
      return text;
    };
    if (!measured())
      return "assumed steady from 'Statistics/Start time' on (not measured: 'Steady state "
             "window' is 0)";
    if (is_steady)
      s << "steady from t = " << t_steady << ": the means over the last two windows of "
        << window << " changed by " << changes_text() << " (tolerance " << percent(tolerance)
        << "); sampled over " << last_time - t_steady << " time units since then";
    else if (last_changes.empty())
      s << "NOT STEADY: fewer than two windows of " << window
        << " time units of samples by t = " << last_time << "; the numbers are provisional";
    else
      s << "NOT STEADY by t = " << last_time << ": the means over the last two windows of "
        << window << " changed by " << changes_text() << " (tolerance " << percent(tolerance)
        << "); the numbers are provisional";
    return s.str();
  }

  void SteadyStateDetector::save(std::ostream &out) const
  {
    out << "SteadyStateDetector " << std::setprecision(17) << is_steady << " " << t_steady << " "
        << times.size() << " " << (values.empty() ? 0 : values[0].size()) << " "
        << last_changes.size() << "\n";
    for (std::size_t s = 0; s < times.size(); ++s)
      {
        out << times[s];
        for (const double v : values[s])
          out << " " << v;
        out << "\n";
      }
    for (const double c : last_changes)
      out << c << " ";
    for (const double c : last_allowed)
      out << c << " ";
    out << "\n";
  }

  void SteadyStateDetector::load(std::istream &in)
  {
    std::string tag;
    std::size_t n_times = 0, n_values = 0, n_changes = 0;
    in >> tag >> is_steady >> t_steady >> n_times >> n_values >> n_changes;
    if (tag != "SteadyStateDetector")
      throw std::runtime_error("channel statistics: the saved steady-state record is missing");
    times.assign(n_times, 0.);
    values.assign(n_times, std::vector<double>(n_values, 0.));
    for (std::size_t s = 0; s < n_times; ++s)
      {
        in >> times[s];
        for (double &v : values[s])
          in >> v;
      }
    last_changes.assign(n_changes, 0.);
    for (double &c : last_changes)
      in >> c;
    last_allowed.assign(n_changes, 0.);
    for (double &c : last_allowed)
      in >> c;
    if (in.fail())
      throw std::runtime_error("channel statistics: cannot read the saved steady-state record");
  }
} // namespace Suspension::Postprocess
