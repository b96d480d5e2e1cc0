// suspension: parse the command line, read the scene, pick the dimension,
// run, and turn any error into one line on stderr and a non-zero exit.

#include <deal.II/base/mpi.h>
#include <deal.II/base/parameter_handler.h>

#include <suspension/core/memory.h>
#include <suspension/core/parameters.h>
#include <suspension/core/study.h>
#include <suspension/core/study_cases.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <regex>
#include <string>
#include <utility>
#include <vector>

namespace
{
  const char *usage =
    "usage: suspension FILE.prm [--resume] [--set 'Section/Entry=value']...\n"
    "                                      run the scene described in FILE.prm;\n"
    "                                      --resume: continue from the checkpoint in\n"
    "                                      <Output directory>/checkpoint/ (same FILE.prm);\n"
    "                                      --set: change one entry of FILE.prm\n"
    "       suspension FILE.prm --list-cases [--set ...]\n"
    "                                      the cases of FILE.prm's 'Study' subsection\n"
    "                                      as JSON (read by scripts/study), nothing run\n"
    "       suspension --print-parameters [2|3] [--json]\n"
    "                                      every entry, its default and documentation\n"
    "       suspension --help              this text\n";

  /// deal.II's exception texts span several lines; a user wants one.
  std::string one_line(std::string text)
  {
    text = std::regex_replace(text, std::regex("[\\s]+"), " ");
    return std::regex_replace(text, std::regex("^ | $"), "");
  }

  int fail(const std::string &message)
  {
    std::cerr << "suspension: error: " << one_line(message) << std::endl;
    return 1;
  }
} // namespace

int main(int argc, char *argv[])
{
  using namespace Suspension;
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  const std::vector<std::string> args(argv + 1, argv + argc);

  if (args.empty())
    return fail("no parameter file given (suspension --help for usage)");
  if (args[0] == "--help" || args[0] == "-h")
    {
      std::cout << usage;
      return 0;
    }
  if (args[0] == "--print-parameters")
    {
      unsigned int dim  = 2;
      bool         json = false;
      for (unsigned int i = 1; i < args.size(); ++i)
        if (args[i] == "3")
          dim = 3;
        else if (args[i] == "--json")
          json = true;
      dealii::ParameterHandler prm;
      Parameters::All::declare(prm, dim);
      prm.print_parameters(std::cout, json ? dealii::ParameterHandler::JSON :
                                             dealii::ParameterHandler::Text);
      return 0;
    }
  if (args[0].rfind("--", 0) == 0)
    return fail("unknown option '" + args[0] + "' (suspension --help for usage)");

  const std::string filename = args[0];
  bool              resume   = false;
  bool              list_cases = false;
  std::vector<std::pair<std::string, std::string>> overrides;
  for (unsigned int i = 1; i < args.size(); ++i)
    if (args[i] == "--resume")
      resume = true;
    else if (args[i] == "--list-cases")
      list_cases = true;
    else if (args[i] == "--set" && i + 1 < args.size() &&
             args[i + 1].find('=') == std::string::npos)
      return fail("--set '" + args[i + 1] + "': expected --set 'Section/Entry=value'");
    else if (args[i] == "--set" && i + 1 < args.size())
      {
        const std::string &entry = args[++i];
        overrides.emplace_back(entry.substr(0, entry.find('=')), entry.substr(entry.find('=') + 1));
      }
    else
      return fail("unknown or incomplete option '" + args[i] + "' (suspension --help for usage)");

  Parameters::All parameters;
  try
    {
      if (!std::ifstream(filename))
        return fail("cannot read parameter file '" + filename + "'");
      if (std::filesystem::is_directory(filename)) // an ifstream opens it
        return fail("cannot read parameter file '" + filename + "': it is a directory");
      unsigned int dim = Parameters::read_dimension(filename);
      // --set Dimension=3 declares the entries of that dimension (another
      // value is refused by read())
      for (const auto &[entry, value] : overrides)
        if (entry == "Dimension" && (value == "2" || value == "3"))
          dim = std::stoi(value);
      parameters             = Parameters::read(filename, dim, overrides);
      parameters.checkpoint.resume = resume;
      if (list_cases)
        {
          const auto cases = study_cases(parameters);
          if (dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0)
            write_study_cases(std::cout, parameters, cases);
          return 0;
        }
      // a mesh that cannot fit stops here, before anything is written
      check_memory(parameters, MPI_COMM_WORLD);
    }
  catch (const Parameters::InputError &e)
    {
      return fail("in '" + filename + "': " + e.what());
    }
  catch (const dealii::ExceptionBase &e)
    {
      std::ostringstream info;
      e.print_info(info);
      return fail("in '" + filename + "': " + info.str());
    }
  catch (const std::exception &e)
    {
      return fail("in '" + filename + "': " + e.what());
    }

  try
    {
      if (parameters.dimension == 2)
        run_study<2>(parameters, MPI_COMM_WORLD);
      else
        run_study<3>(parameters, MPI_COMM_WORLD);
    }
  catch (const Parameters::InputError &e)
    {
      return fail("in '" + filename + "': " + e.what()); // found only when run (a directory)
    }
  catch (const dealii::ExceptionBase &e)
    {
      std::ostringstream info;
      e.print_info(info);
      return fail(info.str());
    }
  catch (const std::exception &e)
    {
      return fail(e.what());
    }
  return 0;
}
