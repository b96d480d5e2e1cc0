#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include <suspension/core/memory.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>
#ifdef __GLIBC__
#  include <malloc.h>
#endif

namespace Suspension
{
  namespace
  {
    /// Peak resident memory per active cell, re-measured in session 22 on
    /// the matrix-free code (doc/performance.md, "Memory"): on uniform
    /// meshes of the channel scenes the slope of VmHWM over three steps
    /// (fluid only, and with the solid's DG fields); on meshes refined
    /// towards the particles the peak less the base over the cells of the
    /// initial mesh, including what the transfer at mesh changes holds
    /// (2D: 6.3 kB per cell over 3 steps, 10.0 over 80 steps with 6
    /// adaptations; 3D: 22 and 25 kB over 2-3 steps at levels 3 and 4,
    /// taken as 30 with the same allowance for adaptations).
    constexpr double BYTES_2D_FLUID = 3.3e3, BYTES_2D_SOLID = 5.1e3, BYTES_2D_REFINED = 10e3;
    constexpr double BYTES_3D_FLUID = 10.5e3, BYTES_3D_SOLID = 21.2e3, BYTES_3D_REFINED = 30e3;

    double bytes_per_cell(const Parameters::All &p, const bool refined)
    {
      const bool solid = p.solid.enabled();
      if (p.dimension == 2)
        return refined ? BYTES_2D_REFINED : (solid ? BYTES_2D_SOLID : BYTES_2D_FLUID);
      return refined ? BYTES_3D_REFINED : (solid ? BYTES_3D_SOLID : BYTES_3D_FLUID);
    }

    /// What a rank holds before its mesh: the code and the libraries (the
    /// intercept of the same measurements, 185-188 MB).
    constexpr double base_bytes = 185e6;

    std::string in_units(const double bytes)
    {
      std::ostringstream out;
      out << std::fixed;
      if (bytes >= 1e12)
        out << std::setprecision(1) << bytes / 1e12 << " TB";
      else if (bytes >= 1e9)
        out << std::setprecision(1) << bytes / 1e9 << " GB";
      else
        out << std::setprecision(0) << bytes / 1e6 << " MB";
      return out.str();
    }

    /// The memory limit of this process's control group (what a batch
    /// system such as Slurm grants a job, often less than the node has):
    /// cgroup v2's memory.max or v1's memory.limit_in_bytes, in bytes; 0 if
    /// there is none.
    double cgroup_limit()
    {
      for (const char *file : {"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"})
        {
          std::ifstream in(file);
          double        bytes = 0.;
          if (in >> bytes && bytes > 0. && bytes < 1e18) // "max" or 2^63: none
            return bytes;
        }
      return 0.;
    }

    /// MemAvailable of /proc/meminfo, or the control group's limit if that
    /// is smaller, in bytes; 0 if unknown.
    double available_memory()
    {
      std::ifstream meminfo("/proc/meminfo");
      std::string   key;
      double        kB;
      std::string   unit;
      double        available = 0.;
      while (meminfo >> key >> kB >> unit)
        if (key == "MemAvailable:")
          available = kB * 1024.;
      const double limit = cgroup_limit();
      return limit > 0. && (available <= 0. || limit < available) ? limit : available;
    }
  } // namespace

  MemoryEstimate estimate_memory(const Parameters::All &p, const double cells,
                                 MPI_Comm communicator)
  {
    return estimate_memory(p, cells, p.mesh_refinement.enabled, communicator);
  }

  MemoryEstimate estimate_memory(const Parameters::All &p, const double cells, const bool refined,
                                 MPI_Comm communicator)
  {
    MemoryEstimate e;
    e.cells          = cells;
    e.refined        = refined;
    e.bytes_per_cell = bytes_per_cell(p, e.refined);
    const unsigned int ranks = dealii::Utilities::MPI::n_mpi_processes(communicator);
    e.bytes_per_rank = base_bytes + e.cells / ranks * e.bytes_per_cell;
    MPI_Comm node;
    MPI_Comm_split_type(communicator, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node);
    e.ranks_on_node = dealii::Utilities::MPI::n_mpi_processes(node);
    MPI_Comm_free(&node);
    // the node with the least memory per rank decides
    e.available_per_rank =
      dealii::Utilities::MPI::min(available_memory() / e.ranks_on_node, communicator);
    return e;
  }

  MemoryEstimate estimate_memory(const Parameters::All &p, MPI_Comm communicator)
  {
    double cells = std::pow(2., double(p.dimension * p.mesh.global_refinements));
    for (const unsigned int n : p.geometry.subdivisions)
      cells *= n;
    // the coarse mesh is uniform: its cost per cell is that of a uniform mesh
    return estimate_memory(p, cells, false, communicator);
  }

  namespace
  {
    std::string does_not_fit(const MemoryEstimate &e, MPI_Comm communicator)
    {
      std::ostringstream message;
      message << "make " << std::setprecision(3) << e.cells << " cells, which need about "
              << in_units(e.bytes_per_rank) << " per rank on "
              << dealii::Utilities::MPI::n_mpi_processes(communicator) << " rank(s) ("
              << std::setprecision(2) << e.bytes_per_cell / 1e3 << " kB per "
              << (e.refined ? "cell of an adaptive mesh" : "cell") << ", measured); the "
              << e.ranks_on_node << " rank(s) on a node have " << in_units(e.available_per_rank)
              << " available each: lower it or run on more nodes (mpirun -np N)";
      return message.str();
    }
  } // namespace

  void check_memory(const Parameters::All &p, MPI_Comm communicator)
  {
    const MemoryEstimate e = estimate_memory(p, communicator);
    if (e.available_per_rank <= 0. || e.bytes_per_rank <= e.available_per_rank)
      return;
    throw Parameters::InputError("Mesh/Global refinements",
                                 std::to_string(p.mesh.global_refinements) + " refinements " +
                                   does_not_fit(e, communicator));
  }

  void check_memory_of_refined_mesh(const Parameters::All &p, const double cells,
                                    MPI_Comm communicator)
  {
    const MemoryEstimate e = estimate_memory(p, cells, communicator);
    if (e.available_per_rank <= 0. || e.bytes_per_rank <= e.available_per_rank)
      return;
    throw Parameters::InputError("Mesh refinement/Maximum level",
                                 "the initial refinement towards the particles to level " +
                                   std::to_string(p.mesh_refinement.maximum_level) + " would " +
                                   does_not_fit(e, communicator));
  }

  void release_free_memory()
  {
#ifdef __GLIBC__
    malloc_trim(0);
#endif
  }

  double peak_resident_memory()
  {
    dealii::Utilities::System::MemoryStats stats;
    dealii::Utilities::System::get_memory_stats(stats);
    return stats.VmHWM * 1024.;
  }

  std::string memory_line(const double velocity_dofs, const double estimated_bytes_per_rank,
                          MPI_Comm communicator)
  {
    const auto   peak  = dealii::Utilities::MPI::min_max_avg(peak_resident_memory(), communicator);
    const unsigned int ranks = dealii::Utilities::MPI::n_mpi_processes(communicator);
    std::ostringstream line;
    line << "Memory: peak resident " << in_units(peak.max) << " per rank";
    if (ranks > 1)
      line << " (largest of " << ranks << " ranks, mean " << in_units(peak.avg) << ")";
    line << ", " << std::fixed << std::setprecision(2) << peak.sum / velocity_dofs / 1e3
         << " kB per velocity DoF; estimated before the run " << in_units(estimated_bytes_per_rank)
         << " per rank";
    return line.str();
  }
} // namespace Suspension
