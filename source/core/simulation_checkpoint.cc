// Simulation: writing a checkpoint and resuming from one (the mesh, the
// fields and every scalar the rest of the run depends on).
#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>
#include <deal.II/lac/solver_control.h>

#include <boost/archive/text_iarchive.hpp>
#include <boost/archive/text_oarchive.hpp>
#include <boost/serialization/string.hpp>
#include <boost/serialization/utility.hpp>
#include <boost/serialization/vector.hpp>

#include <suspension/core/memory.h>
#include <suspension/core/simulation.h>
#include <suspension/fluid/body_force.h>
#include <suspension/mesh/resolution_check.h>
#include <suspension/postprocess/cell_means.h>
#include <suspension/postprocess/point_values.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <optional>
#include <sstream>

namespace Suspension
{
  template <int dim>
  double Simulation<dim>::resume()
  {
    TimerOutput::Scope scope(timer, "setup (mesh, DoFs, matrices)");
    const std::string path  = checkpoint.find();
    const std::string state = checkpoint.read_state();
    scene.create_coarse_mesh(triangulation);
    // Before p4est reads a mesh it cannot hold, and before fields are read
    // into elements of another size: the header (checkpoint_header()) must
    // match but for the rank count.
    const auto without_ranks = [](const std::string &header) {
      std::istringstream in(header);
      std::string        word, result;
      for (unsigned int i = 0; in >> word; ++i)
        if (i == 2 || i > 3) // not the tag, the format or the rank count
          result += (result.empty() ? "" : " ") + word;
      return result;
    };
    const std::string saved = state.substr(0, state.find('\n'));
    // format 2 (session 14): the reports (mesh, probes, verification)
    // save their own parts
    if (saved.rfind("suspension-checkpoint 2 ", 0) != 0)
      throw std::runtime_error("--resume: '" + path + "/state.txt' is not a checkpoint of "
                               "this version of suspension (format 2; '" +
                               saved.substr(0, saved.find(' ', saved.find(' ') + 1)) +
                               "' was written by an older one): rerun the case from its start");
    if (without_ranks(saved) != without_ranks(checkpoint_header()))
      throw std::runtime_error("--resume: the checkpoint in '" + path + "' was written for '" +
                               without_ranks(saved) + "', the parameter file gives '" +
                               without_ranks(checkpoint_header()) +
                               "' (dimension, coarse cells, elements): resume with the file "
                               "the checkpoint was written with");
    checkpoint.load_mesh(triangulation);
    // for the run summary: the checkpoint's mesh on the ranks of this run
    initial_memory_estimate =
      estimate_memory(parameters, triangulation.n_global_active_cells(), communicator).bytes_per_rank;
    space.setup(scene);
    if (!prescribed_velocity)
      operators.reinit(space);
    // in the order of write_checkpoint()
    fluid.resume_from_checkpoint();
    if (solid)
      solid->resume_from_checkpoint(space);
    smallest_cell_size = smallest_cell();
    return load_state(state, path);
  }

  template <int dim>
  void Simulation<dim>::write_checkpoint(const double dt, const double wall_time)
  {
    TimerOutput::Scope scope(timer, "checkpoint");
    // the order of deserialization in resume()
    fluid.prepare_for_checkpoint();
    if (solid)
      solid->prepare_for_checkpoint();
    const auto report = checkpoint.write(triangulation, save_state(dt, wall_time));
    fluid.checkpoint_written();
    if (solid)
      solid->checkpoint_written();
    // formatted apart, so that the screen's stream keeps its precision
    std::ostringstream line;
    line << "  checkpoint at step " << fluid.step_number() << ", t = " << fluid.time() << ": "
         << std::fixed << std::setprecision(2) << report.bytes / 1e6 << " MB in "
         << report.seconds << " s";
    pcout << line.str() << std::endl;
  }

  namespace
  {
    /// Sizes a checkpoint must match: same mesh, same discretisation.
    template <int dim>
    std::vector<unsigned long long> sizes(const Triangulation<dim>      &tria,
                                          const Fluid::FluidSpace<dim>  &space,
                                          const Solid::SolidPhase<dim>  *solid)
    {
      return {tria.n_global_active_cells(), space.dof_velocity.n_dofs(),
              space.dof_pressure.n_dofs(), solid ? solid->get_dof_handler().n_dofs() : 0};
    }
  } // namespace

  template <int dim>
  std::string Simulation<dim>::checkpoint_header() const
  {
    std::ostringstream line;
    line << "suspension-checkpoint 2 " << dim << "D " << Utilities::MPI::n_mpi_processes(communicator)
         << " " << triangulation.n_cells(0) << "_coarse_cells " << space.fe_velocity.get_name()
         << " " << space.fe_pressure.get_name() << " "
         << (solid ? solid->get_fe().get_name() : std::string("no_solid"));
    return line.str();
  }

  template <int dim>
  std::string Simulation<dim>::save_state(const double dt, const double wall_time) const
  {
    const auto part = [](const auto &object) {
      std::ostringstream out;
      object.save(out);
      return out.str();
    };
    // a line resume() reads before the mesh, then a boost archive
    std::ostringstream out;
    out << checkpoint_header() << "\n";
    {
      boost::archive::text_oarchive archive(out);
      archive << sizes(triangulation, space, solid.get());
      archive << part(fluid) << (solid ? part(*solid) : std::string()) << part(adaptor)
              << part(field_output)
              << (channel_statistics ? part(*channel_statistics) : std::string());
      archive << dt << wall_time << last_output_time << last_driving_force << n_outputs
              << (mesh_report ? part(*mesh_report) : std::string())
              << (contact_report ? part(*contact_report) : std::string())
              << (probe_report ? part(*probe_report) : std::string())
              << part(verification_report);
      archive << statistics;
    }
    return out.str();
  }

  template <int dim>
  double Simulation<dim>::load_state(const std::string &state, const std::string &path)
  {
    const auto part = [](auto &object, const std::string &text) {
      std::istringstream in(text);
      object.load(in);
    };
    std::istringstream in(state);
    std::string        header;
    std::getline(in, header);
    const std::string ranks = Utilities::split_string_list(header, ' ')[3];
    boost::archive::text_iarchive   archive(in);
    std::vector<unsigned long long> saved;
    archive >> saved;
    if (saved != sizes(triangulation, space, solid.get()))
      throw std::runtime_error(
        "--resume: the checkpoint in '" + path + "' has " + std::to_string(saved[0]) +
        " cells and " + std::to_string(saved[1]) + " + " + std::to_string(saved[2]) + " + " +
        std::to_string(saved[3]) +
        " DoFs, the parameter file gives another mesh or discretisation: resume with the file "
        "the checkpoint was written with");

    std::string fluid_state, solid_state, adaptor_state, output_state, statistics_state;
    archive >> fluid_state >> solid_state >> adaptor_state >> output_state >> statistics_state;
    part(fluid, fluid_state);
    if (solid)
      part(*solid, solid_state);
    part(adaptor, adaptor_state);
    part(field_output, output_state);
    if (channel_statistics)
      {
        if (statistics_state.empty())
          throw std::runtime_error("--resume: the checkpoint in '" + path +
                                   "' has no channel statistics ('Statistics/Enabled' was false)");
        part(*channel_statistics, statistics_state);
      }

    double      dt = 0.;
    std::string mesh_state, contact_state, probe_state, verification_state;
    archive >> dt >> wall_time_before >> last_output_time >> last_driving_force >> n_outputs >>
      mesh_state >> contact_state >> probe_state >> verification_state;
    if (mesh_report)
      part(*mesh_report, mesh_state);
    if (contact_report)
      part(*contact_report, contact_state);
    if (probe_report)
      part(*probe_report, probe_state);
    part(verification_report, verification_state);
    archive >> statistics;

    std::ostringstream line;
    line << "  resumed from '" << path << "' (written on " << ranks << " rank"
         << (ranks != "1" ? "s" : "") << ") at step " << fluid.step_number() << ", t = "
         << fluid.time();
    pcout << line.str() << std::endl;
    return dt;
  }

  template class Simulation<2>;
  template class Simulation<3>;
} // namespace Suspension
