#pragma once

#include <suspension/core/parameters.h>

#include <mpi.h>

namespace Suspension
{
  /**
   * Runs a scene once, or, when 'Verification' asks for refinement or
   * time-step cycles, several times (one global refinement more, or half
   * the time step, each time) and prints the errors with their rates; or
   * once per value of a swept entry, printing the particle's deformation.
   */
  template <int dim>
  void run_study(const Parameters::All &parameters, MPI_Comm communicator);
} // namespace Suspension
