#pragma once

#include <deal.II/distributed/tria.h>

#include <suspension/core/parameters.h>

#include <mpi.h>

#include <chrono>
#include <string>

namespace Suspension
{
  using namespace dealii;

  /// What writing one checkpoint cost.
  struct CheckpointReport
  {
    std::string   directory;
    std::uintmax_t bytes   = 0;
    double        seconds = 0.;
  };

  /**
   * When to write a checkpoint, and where: the mesh with the fields the
   * parts attached to it (Triangulation::save()) plus `state`, a text the
   * caller composes from the scalars of the time loop, into
   * <Output directory>/checkpoint/.
   *
   * Writing never touches the last good checkpoint until the new one is
   * complete: everything goes to checkpoint.tmp/ first; then, after a
   * barrier, rank 0 renames checkpoint/ to checkpoint.old/, checkpoint.tmp/
   * to checkpoint/, and removes checkpoint.old/. A crash at any moment
   * leaves checkpoint/ or (between the two renames) checkpoint.old/
   * complete; read() takes the first of the two that exists.
   *
   * The files are state.txt and mesh, mesh.info, mesh_fixed.data (and
   * mesh_variable.data) of Triangulation::save(); state.txt is written last.
   */
  template <int dim>
  class Checkpoint
  {
  public:
    Checkpoint(const Parameters::All &parameters, MPI_Comm communicator);

    bool enabled() const;

    /// Collective: every 'Interval steps' steps, or once 'Interval
    /// minutes' of wall time (on the slowest rank) have passed since the
    /// start of the run or the last checkpoint.
    bool due(unsigned int step);

    /// Collective. The fields must have been attached already
    /// (SolutionTransfer::prepare_for_serialization); `state` matters on
    /// rank 0 only.
    CheckpointReport write(const parallel::distributed::Triangulation<dim> &triangulation,
                           const std::string                               &state);

    /// Collective: the directory read() would take; throws (naming the
    /// path) if there is no complete checkpoint.
    std::string find() const;

    /// Collective: the state text of the checkpoint find() names.
    std::string read_state() const;

    /// Collective. `triangulation` must hold the coarse mesh only (with its
    /// periodicity); afterwards it is the saved mesh with the fields
    /// attached, to be deserialized in the order they were saved.
    void load_mesh(parallel::distributed::Triangulation<dim> &triangulation) const;

  private:
    const Parameters::Checkpoint &settings;
    MPI_Comm                      communicator;
    const std::string             directory; // <output>/checkpoint
    std::chrono::steady_clock::time_point last_written;
  };
} // namespace Suspension
