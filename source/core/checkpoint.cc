#include <deal.II/base/mpi.h>

#include <suspension/core/checkpoint.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace Suspension
{
  namespace fs = std::filesystem;

  template <int dim>
  Checkpoint<dim>::Checkpoint(const Parameters::All &parameters, MPI_Comm communicator)
    : settings(parameters.checkpoint)
    , communicator(communicator)
    , directory(parameters.output.directory + "/checkpoint")
    , last_written(std::chrono::steady_clock::now())
  {}

  template <int dim>
  bool Checkpoint<dim>::enabled() const
  {
    return settings.interval_steps > 0 || settings.interval_minutes > 0;
  }

  template <int dim>
  bool Checkpoint<dim>::due(const unsigned int step)
  {
    if (settings.interval_steps > 0 && step % settings.interval_steps == 0)
      return true;
    if (settings.interval_minutes <= 0)
      return false;
    // every rank must take the same decision: the slowest clock decides
    const double minutes =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - last_written).count() / 60.;
    return Utilities::MPI::max(minutes, communicator) >= settings.interval_minutes;
  }

  template <int dim>
  CheckpointReport
  Checkpoint<dim>::write(const parallel::distributed::Triangulation<dim> &triangulation,
                         const std::string                               &state)
  {
    const auto         start = std::chrono::steady_clock::now();
    const bool         root  = Utilities::MPI::this_mpi_process(communicator) == 0;
    const std::string  tmp = directory + ".tmp", old = directory + ".old";
    if (root)
      {
        fs::remove_all(tmp); // a write that crashed before
        fs::create_directories(tmp);
      }
    MPI_Barrier(communicator);
    triangulation.save(tmp + "/mesh");
    bool written = true;
    if (root)
      {
        // last, so that its presence means the rest is complete
        std::ofstream out(tmp + "/state.txt");
        out << state;
        out.close();
        written = !out.fail();
      }
    AssertThrow(Utilities::MPI::min(written ? 1 : 0, communicator) == 1,
                ExcMessage("cannot write the checkpoint file '" + tmp + "/state.txt'"));
    MPI_Barrier(communicator);

    CheckpointReport report;
    report.directory = directory;
    if (root)
      {
        if (fs::exists(directory))
          {
            fs::remove_all(old);
            fs::rename(directory, old);
          }
        fs::rename(tmp, directory);
        fs::remove_all(old);
        for (const auto &file : fs::directory_iterator(directory))
          report.bytes += file.file_size();
      }
    MPI_Barrier(communicator);
    last_written   = std::chrono::steady_clock::now();
    report.seconds = std::chrono::duration<double>(last_written - start).count();
    return report;
  }

  template <int dim>
  std::string Checkpoint<dim>::find() const
  {
    int which = -1;
    if (Utilities::MPI::this_mpi_process(communicator) == 0)
      {
        if (fs::exists(directory + "/state.txt"))
          which = 0;
        else if (fs::exists(directory + ".old/state.txt"))
          which = 1; // crashed between the two renames
      }
    which = Utilities::MPI::broadcast(communicator, which, 0);
    if (which < 0)
      throw std::runtime_error("--resume: no checkpoint in '" + directory +
                               "' (no state.txt there or in " + directory + ".old)");
    return which == 0 ? directory : directory + ".old";
  }

  template <int dim>
  std::string Checkpoint<dim>::read_state() const
  {
    const std::string path = find();
    std::string       state;
    if (Utilities::MPI::this_mpi_process(communicator) == 0)
      {
        std::ifstream      in(path + "/state.txt");
        std::ostringstream text;
        text << in.rdbuf();
        state = text.str();
      }
    return Utilities::MPI::broadcast(communicator, state, 0);
  }

  template <int dim>
  void Checkpoint<dim>::load_mesh(parallel::distributed::Triangulation<dim> &triangulation) const
  {
    triangulation.load(find() + "/mesh");
  }

  template class Checkpoint<2>;
  template class Checkpoint<3>;
} // namespace Suspension
