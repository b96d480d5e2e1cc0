#pragma once

#include <suspension/core/parameters.h>

#include <mpi.h>

#include <string>

namespace Suspension
{
  /// What a mesh will cost in memory, from the number of cells (issue 14,
  /// item 4).
  struct MemoryEstimate
  {
    double cells          = 0.; // of the mesh the estimate is for
    bool   refined        = false; // an adaptively refined mesh (costs more per cell)
    double bytes_per_cell = 0.; // measured, see memory.cc
    double bytes_per_rank = 0.; // the mesh's share of one rank, plus the base
    double available_per_rank = 0.; // MemAvailable of the node / its ranks
    unsigned int ranks_on_node = 1;
  };

  /// The estimate for the scene's initial mesh (base cells times
  /// 2^(dim global refinements), the refinement region not counted) on the
  /// ranks of `communicator`.
  MemoryEstimate estimate_memory(const Parameters::All &parameters, MPI_Comm communicator);

  /// The estimate for a mesh of `cells` active cells, refined towards the
  /// interfaces when the scene's mesh is adaptive.
  MemoryEstimate estimate_memory(const Parameters::All &parameters, double cells,
                                 MPI_Comm communicator);

  /// The same with the cost per cell of a uniform (`refined` false) or a
  /// refined mesh chosen by the caller.
  MemoryEstimate estimate_memory(const Parameters::All &parameters, double cells, bool refined,
                                 MPI_Comm communicator);

  /// Throws an InputError of 'Mesh/Global refinements' when the estimate
  /// does not fit in the memory available to the ranks of a node: a run
  /// that would be killed by the system after its set-up stops at once,
  /// before anything is written.
  void check_memory(const Parameters::All &parameters, MPI_Comm communicator);

  /// The same for the mesh of the initial refinement towards the
  /// particles, checked before its fields are built: throws an InputError
  /// of 'Mesh refinement/Maximum level' (collective).
  void check_memory_of_refined_mesh(const Parameters::All &parameters, double cells,
                                    MPI_Comm communicator);

  /// Gives the heap's free pages back to the system (glibc's malloc_trim;
  /// elsewhere nothing). In these runs even the largest vectors live on the
  /// heap (glibc's mallinfo2 counts no mapped blocks), so the memory that a
  /// set-up or a mesh change frees stays resident, in holes that the next
  /// large vector may not fit, unless it is released: called after each
  /// (the level-4 box: 1.1 GB of 4.0 GB free but resident after its set-up).
  void release_free_memory();

  /// Peak resident memory (VmHWM) of this process, in bytes.
  double peak_resident_memory();

  /// "Memory: peak resident 767 MB per rank (largest of 2 ranks), 2.4 kB
  /// per velocity DoF; estimated 690 MB" (collective).
  std::string memory_line(double velocity_dofs, double estimated_bytes_per_rank,
                          MPI_Comm communicator);
} // namespace Suspension
