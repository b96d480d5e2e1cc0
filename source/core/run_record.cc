#include <deal.II/base/mpi.h>
#include <deal.II/base/config.h>
#include <deal.II/base/utilities.h>

#include <suspension/code_version.h> // generated at build time
#include <suspension/core/run_record.h>

#include <chrono>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

namespace Suspension
{
  std::string code_version()
  {
    return SUSPENSION_CODE_VERSION;
  }

  namespace
  {
    /// The command line that reproduces the run, quoted as a shell wants it.
    std::string command_line(const Parameters::All &p)
    {
      std::string line = "suspension '" + p.input_file + "'";
      if (p.checkpoint.resume)
        line += " --resume";
      for (const auto &[entry, value] : p.overrides)
        line += " --set '" + entry + "=" + value + "'";
      return line;
    }

    /// Empty on success, else why the record could not be written.
    std::string write_file(const Parameters::All &p, const unsigned int n_ranks)
    {
      namespace fs = std::filesystem;
      const fs::path   directory = p.output.directory;
      std::error_code  error;
      fs::create_directories(directory, error);
      if (error)
        return "cannot create the output directory '" + directory.string() +
               "': " + error.message();
      if (!fs::is_directory(directory))
        return "'" + directory.string() + "' exists and is not a directory";

      const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
      char              date[32];
      std::strftime(date, sizeof(date), "%Y-%m-%d %H:%M:%S UTC", std::gmtime(&now));
      std::ofstream out(directory / "parameters_used.prm");
      out << "# suspension " << code_version() << ", deal.II " << DEAL_II_PACKAGE_VERSION
          << ", " << n_ranks << " MPI rank" << (n_ranks > 1 ? "s" : "") << ", started " << date
          << "\n# " << command_line(p)
          << "\n# Every entry as used (the file's values with the --set ones applied):"
          << "\n# 'suspension parameters_used.prm' runs the same scene.\n\n"
          << p.parameters_used;
      out.close();
      if (!out)
        return "cannot write '" + (directory / "parameters_used.prm").string() + "'";
      return "";
    }
  } // namespace

  void write_run_record(const Parameters::All &p, MPI_Comm communicator)
  {
    const unsigned int n_ranks = dealii::Utilities::MPI::n_mpi_processes(communicator);
    std::string        failure;
    if (dealii::Utilities::MPI::this_mpi_process(communicator) == 0)
      failure = write_file(p, n_ranks);
    // every rank stops, with rank 0's reason
    failure = dealii::Utilities::MPI::broadcast(communicator, failure, 0);
    if (!failure.empty())
      throw Parameters::InputError("Output/Directory", failure);

    if (p.output.run_header && dealii::Utilities::MPI::this_mpi_process(communicator) == 0)
      std::cout << "suspension " << code_version() << " (deal.II " << DEAL_II_PACKAGE_VERSION
                << ", " << n_ranks << " MPI rank" << (n_ranks > 1 ? "s" : "")
                << "): " << command_line(p) << "\n"
                << "  every parameter as used: "
                << (std::filesystem::path(p.output.directory) / "parameters_used.prm").string()
                << std::endl;
  }
} // namespace Suspension
