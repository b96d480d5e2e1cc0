#pragma once

#include <suspension/core/parameters.h>

#include <mpi.h>

#include <string>

namespace Suspension
{
  /// The code's version: 'git describe --always --dirty' of the source tree
  /// at build time (cmake/code_version.cmake), or "unknown (...)" when it
  /// was not built from a git checkout.
  std::string code_version();

  /**
   * What makes a run reproducible from its output alone: creates the output
   * directory and writes parameters_used.prm into it, the code version, the
   * command line and every entry as used (the file's values with the --set
   * ones applied; 'suspension parameters_used.prm' runs the same scene).
   * With 'Output/Run header' it prints two lines that name both.
   *
   * Called once, after every check of the input and before anything else
   * is written, so that a refused input leaves no directory behind. A
   * directory that cannot be created is an InputError of 'Output/Directory'
   * on every rank.
   */
  void write_run_record(const Parameters::All &parameters, MPI_Comm communicator);
} // namespace Suspension
