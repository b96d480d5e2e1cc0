#include <deal.II/base/conditional_ostream.h>
#include <deal.II/base/convergence_table.h>
#include <deal.II/base/function_parser.h>
#include <deal.II/base/mpi.h>

#include <suspension/core/checkpoint.h>
#include <suspension/core/run_record.h>
#include <suspension/core/simulation.h>
#include <suspension/core/study.h>

#include <cmath>
#include <memory>
#include <iomanip>
#include <sstream>

namespace Suspension
{
  namespace
  {
    /// Runs a simulation; a failure propagates only after the simulation
    /// (and its TimerOutput) ended normally, so the error stays one line.
    template <int dim>
    RunSummary run_one(const Parameters::All &p, MPI_Comm communicator)
    {
      RunSummary         r;
      std::exception_ptr failure;
      {
        Simulation<dim> simulation(p, communicator);
        try
          {
            r = simulation.run();
          }
        catch (...)
          {
            failure = std::current_exception();
          }
      }
      if (failure)
        std::rethrow_exception(failure);
      return r;
    }

    template <int dim>
    void run_sweep(const Parameters::All &parameters, MPI_Comm communicator)
    {
      ConditionalOStream pcout(std::cout, Utilities::MPI::this_mpi_process(communicator) == 0);
      const auto        &v = parameters.verification;
      std::vector<std::pair<std::string, RunSummary>> runs;
      for (const auto &value : v.sweep_values)
        {
          pcout << v.sweep_entry << " = " << value << ":" << std::endl;
          auto overrides = parameters.overrides;
          overrides.emplace_back(v.sweep_entry, value);
          Parameters::All p = Parameters::read(parameters.input_file, dim, overrides);
          runs.emplace_back(value, run_one<dim>(p, communicator));
        }
      std::unique_ptr<FunctionParser<1>> expected;
      if (!v.sweep_expected_deformation.empty())
        {
          expected = std::make_unique<FunctionParser<1>>(1);
          expected->initialize("x", v.sweep_expected_deformation, {});
        }
      pcout << std::endl << "sweep of " << v.sweep_entry << ":" << std::endl;
      bool   monotonic_D = true, monotonic_theta = true, steady = true;
      double deviation   = 0.;
      for (unsigned int i = 0; i < runs.size(); ++i)
        {
          const auto &[value, r] = runs[i];
          pcout << "  " << std::setw(10) << value << "  D = " << std::fixed << std::setprecision(4)
                << r.deformation << "  inclination = " << std::setprecision(2) << r.inclination
                << " deg  cells " << r.n_cells;
          double expected_D = 0.;
          if (expected)
            {
              // a value that is not a number (a switch) makes x = 0
              double x = 0.;
              try
                {
                  x = Utilities::string_to_double(value);
                }
              catch (...)
                {
                }
              const double e = expected->value(Point<1>(x));
              expected_D     = e;
              deviation      = ((v.sweep_material_deformation ? r.deformation_B : r.deformation) - e) / e;
              pcout << "  expected D = " << std::setprecision(4) << e << "  deviation "
                    << std::setprecision(1) << 100. * (r.deformation - e) / e << " %";
            }
          pcout << std::defaultfloat << std::endl;
          if (r.deformation_B > 0.)
            {
              // the stretch of the material (mean of B over the core):
              // its own steady measure, whatever the rest shape of phi
              pcout << "  " << std::setw(10) << "" << "  D_B = " << std::fixed << std::setprecision(4)
                    << r.deformation_B << "  inclination_B = " << std::setprecision(2)
                    << r.inclination_B << " deg";
              if (expected)
                pcout << "  deviation " << std::setprecision(1)
                      << 100. * (r.deformation_B - expected_D) / expected_D << " %";
              pcout << std::defaultfloat << std::endl;
            }
          // a run without a report time cannot show that it is steady
          if (v.steady_tolerance > 0. && r.deformation_history.empty())
            steady = false;
          if (v.steady_tolerance > 0. && !r.deformation_history.empty())
            {
              // from the first report time to the end, both measures; the
              // verdict on the chosen one
              const auto  &first = r.deformation_history.front();
              const double change_D   = r.deformation / first[1] - 1.;
              const double change_D_B = r.deformation_B / first[2] - 1.;
              const double change     = v.sweep_material_deformation ? change_D_B : change_D;
              steady = steady && std::abs(change) <= v.steady_tolerance;
              pcout << "  " << std::setw(10) << "" << "  from t = " << first[0] << " to the end: D "
                    << std::fixed << std::setprecision(4) << first[1] << " -> " << r.deformation
                    << " (" << std::showpos << std::setprecision(1) << 100. * change_D
                    << std::noshowpos << " %), D_B " << std::setprecision(4) << first[2] << " -> "
                    << r.deformation_B << " (" << std::showpos << std::setprecision(1)
                    << 100. * change_D_B << std::noshowpos << " %)" << std::defaultfloat << std::endl;
            }
          if (i > 0)
            {
              // on the judged measure: the shape's or the material's
              const RunSummary &before = runs[i - 1].second;
              const bool        B      = v.sweep_material_deformation;
              monotonic_D     = monotonic_D && (B ? r.deformation_B > before.deformation_B :
                                                    r.deformation > before.deformation);
              monotonic_theta = monotonic_theta && (B ? r.inclination_B < before.inclination_B :
                                                        r.inclination < before.inclination);
            }
        }
      // (a sweep of a numerical switch compares runs with each other instead)
      if (runs.size() > 1 && v.sweep_agreement == 0)
        pcout << "  " << (v.sweep_material_deformation ? "D_B" : "D")
              << " grows along the sweep: " << (monotonic_D ? "yes" : "no")
              << ", inclination falls along the sweep: " << (monotonic_theta ? "yes" : "no")
              << std::endl;
      const RunSummary &first = runs.front().second, &last = runs.back().second;
      if (v.sweep_agreement > 0)
        {
          const double difference = last.deformation / first.deformation - 1.;
          pcout << "  last against first: D differs by " << std::fixed << std::setprecision(2)
                << 100. * difference << " %, |difference| <= " << v.sweep_agreement << ": "
                << (std::abs(difference) <= v.sweep_agreement ? "yes" : "no") << std::endl;
        }
      if (v.sweep_cell_reduction > 0)
        {
          const double reduction = double(first.n_cells) / last.n_cells;
          pcout << "  cells first / last " << std::fixed << std::setprecision(2) << reduction
                << ", >= " << v.sweep_cell_reduction << ": "
                << (reduction >= v.sweep_cell_reduction ? "yes" : "no") << std::defaultfloat
                << std::endl;
        }
      if (v.steady_tolerance > 0.)
        pcout << "  " << (v.sweep_material_deformation ? "D_B" : "D")
              << " steady in every run (|change| <= " << std::defaultfloat
              << std::setprecision(6) << v.steady_tolerance
              << "): " << (steady ? "yes" : "no") << std::endl;
      if (expected && v.tolerance > 0)
        pcout << "  |deviation" << (v.sweep_material_deformation ? " of D_B" : "")
              << "| of the last run <= " << std::setprecision(6) << v.tolerance << ": "
              << (std::abs(deviation) <= v.tolerance ? "yes" : "no") << std::endl;
    }
  } // namespace

  template <int dim>
  void run_study(const Parameters::All &parameters, MPI_Comm communicator)
  {
    if (parameters.checkpoint.resume &&
        (!parameters.verification.sweep_entry.empty() ||
         std::max(parameters.verification.refinement_cycles,
                  parameters.verification.time_step_cycles) > 1))
      throw std::runtime_error("--resume continues a single run; this file asks for a sweep "
                               "or refinement / time-step cycles");
    if (parameters.checkpoint.resume)
      Checkpoint<dim>(parameters, communicator).find(); // a missing one: one line, nothing run
    // every swept value read (and checked) before anything is written
    for (const auto &value : parameters.verification.sweep_values)
      if (!parameters.verification.sweep_entry.empty())
        {
          auto overrides = parameters.overrides;
          overrides.emplace_back(parameters.verification.sweep_entry, value);
          Parameters::read(parameters.input_file, dim, overrides);
        }
    write_run_record(parameters, communicator); // the first output, after every check
    if (!parameters.verification.sweep_entry.empty())
      return run_sweep<dim>(parameters, communicator);

    ConditionalOStream pcout(std::cout, Utilities::MPI::this_mpi_process(communicator) == 0);
    const auto        &v = parameters.verification;
    const unsigned int cycles = std::max(v.refinement_cycles, v.time_step_cycles);
    const bool         in_space = v.refinement_cycles > 1;

    std::vector<RunSummary> runs;
    for (unsigned int cycle = 0; cycle < cycles; ++cycle)
      {
        Parameters::All p = parameters;
        if (in_space && p.mesh_refinement.enabled)
          {
            // an adaptive mesh refines its finest level
            p.mesh_refinement.maximum_level += cycle;
            p.mesh_refinement.initial_cycles += cycle;
          }
        else if (in_space)
          p.mesh.global_refinements += cycle;
        else
          p.time_stepping.time_step /= std::pow(2., cycle);
        if (cycles > 1)
          pcout << "cycle " << cycle << ":" << std::endl;
        const RunSummary r = run_one<dim>(p, communicator);
        runs.push_back(r);
      }
    if (cycles == 1)
      return;

    // One velocity (and, where it is not zero, pressure) column per time
    // at which errors were reported.
    const std::string key = in_space ? "h" : "dt";
    const auto       &reported = runs.front().errors;
    double            largest_pressure_error = 0.;
    for (const auto &r : runs)
      for (const auto &[t, e] : r.errors)
        largest_pressure_error = std::max(largest_pressure_error, e.pressure_l2);
    // a pressure error within a hundred times the linear solvers' tolerance
    // is theirs (round-off of an exact discrete pressure, as in Couette
    // flow), not the discretization's: no column, no noise rates
    const bool with_pressure =
      largest_pressure_error > 100. * parameters.fluid_solver.solver_tolerance;
    const bool     with_phi      = runs.front().phi_l1_error >= 0.;
    ConvergenceTable         table;
    std::vector<std::string> columns; // error columns, in the order of the first run
    for (const auto &r : runs)
      {
        const auto add = [&](const std::string &name, const double value) {
          table.add_value(name, value);
          if (&r == &runs.front())
            columns.push_back(name);
        };
        table.add_value(key, in_space ? r.smallest_cell : r.time_step);
        if (with_phi)
          {
            add("phi L1", r.phi_l1_error);
            add("phi L1 means", r.phi_cell_l1_error);
          }
        for (unsigned int k = 0; k < r.errors.size() && k < reported.size(); ++k)
          {
            // the last entry is the end of the run (possibly a steady state
            // whose time may differ between platforms: not printed)
            std::ostringstream t;
            if (k + 1 == reported.size())
              t << "final";
            else
              t << std::setprecision(6) << "t=" << reported[k].first;
            add("u L2 " + t.str(), r.errors[k].second.velocity_l2);
            if (with_pressure)
              add("p L2 " + t.str(), r.errors[k].second.pressure_l2);
          }
      }
    table.set_scientific(key, true);
    table.set_precision(key, 3);
    for (const auto &c : columns)
      {
        table.set_scientific(c, true);
        table.set_precision(c, 3);
        table.evaluate_convergence_rates(c, ConvergenceTable::reduction_rate_log2);
      }
    pcout << std::endl << (in_space ? "mesh" : "time-step") << " convergence:" << std::endl;
    if (Utilities::MPI::this_mpi_process(communicator) == 0)
      table.write_text(std::cout);

    if (with_phi)
      pcout << std::fixed << std::setprecision(2) << "final phi L1 rate: "
            << std::log2(runs[runs.size() - 2].phi_l1_error / runs.back().phi_l1_error)
            << std::defaultfloat << std::endl;
    if (reported.empty())
      return;

    // Rate between the last two cycles (the asymptotic one), final time.
    const auto &a = runs[runs.size() - 2].final_errors, &b = runs.back().final_errors;
    const double velocity_rate = std::log2(a.velocity_l2 / b.velocity_l2);
    const double pressure_rate = std::log2(a.pressure_l2 / b.pressure_l2);
    pcout << std::fixed << std::setprecision(2) << "final velocity rate: " << velocity_rate;
    if (with_pressure)
      pcout << ", final pressure rate: " << pressure_rate;
    pcout << std::defaultfloat << std::endl;
    // The last rate alone is not a verdict: a run that blows up at every
    // cycle can still give a large "rate" between two overflowing errors.
    // Every cycle's final error must also be finite and below the previous.
    const auto falls = [&](const auto error_of) {
      for (unsigned int k = 0; k < runs.size(); ++k)
        if (!std::isfinite(error_of(runs[k].final_errors)) ||
            (k > 0 && !(error_of(runs[k].final_errors) < error_of(runs[k - 1].final_errors))))
          return false;
      return true;
    };
    const bool velocity_falls = falls([](const auto &e) { return e.velocity_l2; });
    const bool pressure_falls = falls([](const auto &e) { return e.pressure_l2; });
    if (v.minimum_velocity_rate > 0)
      pcout << "velocity rate >= " << v.minimum_velocity_rate << ": "
            << (velocity_falls && velocity_rate >= v.minimum_velocity_rate ? "yes" : "no")
            << std::endl;
    if (v.minimum_pressure_rate > 0)
      pcout << "pressure rate >= " << v.minimum_pressure_rate << ": "
            << (with_pressure && pressure_falls && pressure_rate >= v.minimum_pressure_rate ?
                  "yes" :
                  "no")
            << std::endl;
  }

  template void run_study<2>(const Parameters::All &, MPI_Comm);
  template void run_study<3>(const Parameters::All &, MPI_Comm);
} // namespace Suspension
