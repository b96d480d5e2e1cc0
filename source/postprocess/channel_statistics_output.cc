// ChannelStatistics: profiles.txt, rheology.txt, stationarity.txt,
// samples.txt, the screen summary, and the sums for checkpoints.
#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/base/table_handler.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/lac/full_matrix.h>

#include <suspension/postprocess/channel_statistics.h>
#include <suspension/postprocess/channel_statistics_layout.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <istream>
#include <memory>
#include <ostream>
#include <sstream>

namespace Suspension::Postprocess
{
  using namespace ChannelLayout;

  namespace
  {
    /// Rounded for the screen, without a negative zero.
    double rounded(const double x, const int digits)
    {
      const double scale = std::pow(10., digits);
      const double r     = std::round(x * scale) / scale;
      return r == 0. ? 0. : r;
    }
  } // namespace

  template <int dim>
  void ChannelStatistics<dim>::write(const std::string &directory) const
  {
    if (n_sampled == 0 || Utilities::MPI::this_mpi_process(communicator) != 0)
      return;
    const auto   p      = profiles();
    TableHandler table;
    const auto   column = [&](const std::string &name, const double value) {
      table.add_value(name, value);
      table.set_scientific(name, true);
      table.set_precision(name, 10);
    };
    for (unsigned int k = 0; k < p.y.size(); ++k)
      {
        column("y_over_h", p.y[k] / h);
        column("wall_distance", p.y[k] + h);
        column("u", p.u[k]);
        column("phi", p.phi[k]);
        column("u_rms", p.u_rms[k]);
        column("v_rms", p.v_rms[k]);
        if (dim == 3)
          column("w_rms", p.w_rms[k]);
        column("v", p.v[k]);
        column("tau_viscous", p.stress[b_viscous][k]);
        column("tau_reynolds", p.stress[b_reynolds][k]);
        column("tau_elastic", p.stress[b_elastic][k]);
        column("tau_collision", p.stress[b_collision][k]);
        column("tau_total", p.stress[b_total][k]);
        column("tau_linear", p.linear[k]);
      }
    {
      std::ofstream out(directory + "/profiles.txt");
      table.write_text(out, TableHandler::table_with_separate_column_description);
    }

    TableHandler bulk;
    const auto   with_error = [&](const std::string &name, const RunningMean &x,
                                const unsigned int quantity) {
      for (const auto &[n, value] :
           {std::pair{name, x.mean}, std::pair{name + "_error", error(quantity)}})
        {
          bulk.add_value(n, value);
          bulk.set_scientific(n, true);
          bulk.set_precision(n, 10);
        }
    };
    bulk.add_value("n_samples", n_sampled);
    bulk.add_value("time_first", first_time);
    bulk.add_value("time_last", last_time);
    // 1 if the samples cover a statistically steady state by the measured
    // criterion (or by assumption, with 'Steady state window' = 0)
    bulk.add_value("steady", steadiness.steady() ? 1 : 0);
    bulk.add_value("steady_measured", steadiness.measured() ? 1 : 0);
    // 0: fewer samples than blocking needs for their correlation (the
    // errors are lower bounds)
    bulk.add_value("errors_converged", blocked_error(series[1]).converged ? 1 : 0);
    with_error("driving_force", driving, 0);
    with_error("viscosity_ratio", viscosity_ratio, 1);
    with_error("N1", n1, 2);
    with_error("N2", n2, 3);
    for (unsigned int b = 0; b < n_budget; ++b)
      with_error(std::string("budget_") + budget_names[b], budget[b], 4 + b);
    for (unsigned int b = 0; b < n_budget; ++b)
      {
        const std::string name = std::string("fraction_") + budget_names[b];
        bulk.add_value(name, budget[b].mean / budget[b_total].mean);
        bulk.set_scientific(name, true);
        bulk.set_precision(name, 10);
      }
    bulk.add_value("straddling_cells", straddling_cells);
    bulk.add_value("linear_deviation", linear_deviation(p));
    bulk.set_scientific("linear_deviation", true);
    {
      std::ofstream out(directory + "/rheology.txt");
      bulk.write_text(out, TableHandler::table_with_separate_column_description);
    }
    std::ofstream(directory + "/stationarity.txt") << stationarity() << "\n";

    // the series behind the errors, for a look at their correlation
    TableHandler samples;
    const char  *names[] = {"driving_force", "viscosity_ratio", "N1", "N2"};
    for (std::size_t i = 0; i < sample_times.size(); ++i)
      {
        samples.add_value("time", sample_times[i]);
        for (unsigned int q = 0; q < 4 + n_budget; ++q)
          {
            const std::string name =
              q < 4 ? std::string(names[q]) : std::string("budget_") + budget_names[q - 4];
            samples.add_value(name, series[q][i]);
            samples.set_scientific(name, true);
            samples.set_precision(name, 10);
          }
      }
    samples.set_precision("time", 10);
    std::ofstream out(directory + "/samples.txt");
    samples.write_text(out, TableHandler::table_with_separate_column_description);
  }

  template <int dim>
  void ChannelStatistics<dim>::print_summary(std::ostream &out, const double tolerance,
                                             const bool unladen) const
  {
    if (n_sampled == 0)
      {
        out << "  channel statistics: no samples" << std::endl;
        return;
      }
    const auto   p       = profiles();
    const double total   = budget[b_total].mean;
    const auto   fixed   = [](const double x, const int digits) {
      std::ostringstream s;
      s << std::fixed << std::setprecision(digits) << rounded(x, digits);
      return s.str();
    };
    const auto   plus_minus = [&](const RunningMean &x, const unsigned int quantity) {
      return fixed(x.mean, 6) + " +- " + fixed(error(quantity), 6);
    };
    out << "  channel statistics: " << n_sampled << " samples, t = " << rounded(first_time, 6)
        << " to " << rounded(last_time, 6) << std::endl;
    out << "  stationarity: " << stationarity() << std::endl;
    const bool converged = blocked_error(series[1]).converged;
    out << "  mu_eff/mu = " << plus_minus(viscosity_ratio, 1) << ", N1 = " << plus_minus(n1, 2)
        << ", N2 = " << plus_minus(n2, 3) << " (errors: blocked batch means"
        << (converged ? "" : "; lower bounds, the samples are too few for their correlation")
        << ")" << std::endl;
    out << "  shear-stress budget (half-channel mean):";
    for (unsigned int b = 0; b < b_total; ++b)
      out << (b > 0 ? ", " : " ") << budget_names[b] << " "
          << fixed(total != 0. ? 100. * budget[b].mean / total : 0., 2) << " %";
    out << std::endl;
    const double deviation = linear_deviation(p);
    if (straddling_cells > 0)
      out << "  note: bin boundaries cut up to " << straddling_cells
          << " cells; profiles are sharper with 'Statistics/Number of bins' a divisor of the "
             "cells across"
          << std::endl;
    out << "  total shear stress linear to " << std::scientific << std::setprecision(1)
        << deviation << " of the wall value" << std::defaultfloat << std::endl;

    if (tolerance > 0 && unladen)
      {
        // laminar unladen flow: mu_eff = mu, no normal stress differences,
        // all shear stress viscous
        const std::pair<const char *, double> checks[] = {
          {"|mu_eff/mu - 1|", std::abs(viscosity_ratio.mean - 1.)},
          {"|N1|", std::abs(n1.mean)},
          {"|N2|", std::abs(n2.mean)},
          {"|viscous fraction - 1|", std::abs(budget[b_viscous].mean / total - 1.)},
          {"total shear stress deviation from linear", deviation}};
        for (const auto &[name, value] : checks)
          out << "  " << name << " = " << std::scientific << std::setprecision(1) << value
              << " <= " << std::defaultfloat << tolerance << ": "
              << (value <= tolerance ? "yes" : "no") << std::endl;
      }
  }

  template <int dim>
  void ChannelStatistics<dim>::save(std::ostream &out) const
  {
    out << "ChannelStatistics " << dim << " " << n_bins << " " << n_stored << " " << n_sampled
        << std::setprecision(17) << " " << first_time << " " << last_time << " "
        << straddling_cells << "\n";
    for (const auto &bin : sums)
      {
        for (const double x : bin)
          out << " " << x;
        out << "\n";
      }
    for (const RunningMean *r : {&driving, &viscosity_ratio, &n1, &n2})
      out << r->n << " " << r->mean << " " << r->m2 << "\n";
    for (const auto &r : budget)
      out << r.n << " " << r.mean << " " << r.m2 << "\n";
    for (unsigned int i = 0; i <= series.size(); ++i)
      {
        const auto &q = i < series.size() ? series[i] : sample_times;
        out << q.size();
        for (const double x : q)
          out << " " << x;
        out << "\n";
      }
    steadiness.save(out);
  }

  template <int dim>
  void ChannelStatistics<dim>::load(std::istream &in)
  {
    std::string  tag;
    unsigned int d = 0, bins = 0, stored = 0;
    in >> tag >> d >> bins >> stored >> n_sampled >> first_time >> last_time >> straddling_cells;
    AssertThrow(tag == "ChannelStatistics" && d == dim && bins == n_bins && stored == n_stored,
                ExcMessage("channel statistics: the saved sums do not match this run "
                           "(dimension, 'Number of bins' or format)"));
    for (auto &bin : sums)
      for (double &x : bin)
        in >> x;
    for (RunningMean *r : {&driving, &viscosity_ratio, &n1, &n2})
      in >> r->n >> r->mean >> r->m2;
    for (auto &r : budget)
      in >> r.n >> r.mean >> r.m2;
    for (unsigned int i = 0; i <= series.size(); ++i)
      {
        auto       &q = i < series.size() ? series[i] : sample_times;
        std::size_t n = 0;
        in >> n;
        q.assign(n, 0.);
        for (double &x : q)
          in >> x;
      }
    AssertThrow(!in.fail(), ExcMessage("channel statistics: cannot read the saved sums"));
    steadiness.load(in);
  }

  template class ChannelStatistics<2>;
  template class ChannelStatistics<3>;
} // namespace Suspension::Postprocess
