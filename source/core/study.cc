#include <deal.II/base/conditional_ostream.h>
#include <deal.II/base/convergence_table.h>
#include <deal.II/base/mpi.h>

#include <suspension/core/simulation.h>
#include <suspension/core/study.h>

#include <cmath>
#include <iomanip>

namespace Suspension
{
  template <int dim>
  void run_study(const Parameters::All &parameters, MPI_Comm communicator)
  {
    ConditionalOStream pcout(std::cout, Utilities::MPI::this_mpi_process(communicator) == 0);
    const auto        &v = parameters.verification;
    const unsigned int cycles = std::max(v.refinement_cycles, v.time_step_cycles);
    const bool         in_space = v.refinement_cycles > 1;

    ConvergenceTable table;
    std::vector<RunSummary> runs;
    for (unsigned int cycle = 0; cycle < cycles; ++cycle)
      {
        Parameters::All p = parameters;
        if (in_space)
          p.mesh.global_refinements += cycle;
        else
          p.time_stepping.time_step /= std::pow(2., cycle);
        if (cycles > 1)
          pcout << "cycle " << cycle << ":" << std::endl;
        Simulation<dim> simulation(p, communicator);
        const RunSummary r = simulation.run();
        runs.push_back(r);
        if (cycles > 1)
          {
            table.add_value(in_space ? "h" : "dt", in_space ? r.smallest_cell : r.time_step);
            table.add_value("u L2", r.final_errors.velocity_l2);
            table.add_value("p L2", r.final_errors.pressure_l2);
          }
      }
    if (cycles == 1)
      return;

    const std::string key = in_space ? "h" : "dt";
    table.set_scientific(key, true);
    table.set_precision(key, 3);
    for (const auto &c : {"u L2", "p L2"})
      {
        table.set_scientific(c, true);
        table.set_precision(c, 3);
        table.evaluate_convergence_rates(c, ConvergenceTable::reduction_rate_log2);
      }
    pcout << std::endl << (in_space ? "mesh" : "time-step") << " convergence:" << std::endl;
    if (Utilities::MPI::this_mpi_process(communicator) == 0)
      table.write_text(std::cout);

    // Rate between the last two cycles, the asymptotic one.
    const auto rate = [&](const auto error) {
      const auto &a = runs[runs.size() - 2], &b = runs.back();
      return std::log2(error(a) / error(b));
    };
    pcout << std::fixed << std::setprecision(2)
          << "final velocity rate: " << rate([](const RunSummary &r) { return r.final_errors.velocity_l2; })
          << ", final pressure rate: " << rate([](const RunSummary &r) { return r.final_errors.pressure_l2; })
          << std::defaultfloat << std::endl;
  }

  template void run_study<2>(const Parameters::All &, MPI_Comm);
  template void run_study<3>(const Parameters::All &, MPI_Comm);
} // namespace Suspension
