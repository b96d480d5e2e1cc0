#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include <suspension/core/memory.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>

namespace Suspension
{
  namespace
  {
    /// Peak resident memory per active cell, measured on uniform meshes of
    /// the channel scenes over three steps (the slope of VmHWM between 768
    /// and 49 152 cells in 2D, 4 096 and 32 768 in 3D; doc/performance.md,
    /// "Memory"): the fluid's matrices and vectors (Q2-Q1) and, with a
    /// solid, its DG fields. Adaptive runs need more (hanging-node
    /// constraints, the transfer at mesh changes): this is a lower bound.
    double bytes_per_cell(const Parameters::All &p)
    {
      const bool solid = p.solid.enabled();
      if (p.dimension == 2)
        return solid ? 10.4e3 : 8.5e3;
      return solid ? 85.e3 : 71.e3;
    }

    /// What a rank holds before its mesh: the code and the libraries (the
    /// intercept of the same measurements).
    constexpr double base_bytes = 190e6;

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

    /// MemAvailable of /proc/meminfo in bytes; 0 if unknown.
    double available_memory()
    {
      std::ifstream meminfo("/proc/meminfo");
      std::string   key;
      double        kB;
      std::string   unit;
      while (meminfo >> key >> kB >> unit)
        if (key == "MemAvailable:")
          return kB * 1024.;
      return 0.;
    }
  } // namespace

  MemoryEstimate estimate_memory(const Parameters::All &p, MPI_Comm communicator)
  {
    MemoryEstimate e;
    e.cells = std::pow(2., double(p.dimension * p.mesh.global_refinements));
    for (const unsigned int n : p.geometry.subdivisions)
      e.cells *= n;
    e.bytes_per_cell = bytes_per_cell(p);
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

  void check_memory(const Parameters::All &p, MPI_Comm communicator)
  {
    const MemoryEstimate e = estimate_memory(p, communicator);
    if (e.available_per_rank <= 0. || e.bytes_per_rank <= e.available_per_rank)
      return;
    std::ostringstream message;
    message << p.mesh.global_refinements << " refinements make " << std::setprecision(3)
            << e.cells << " cells, which need about " << in_units(e.bytes_per_rank)
            << " per rank on " << dealii::Utilities::MPI::n_mpi_processes(communicator)
            << " rank(s) (" << std::setprecision(2) << e.bytes_per_cell / 1e3
            << " kB per cell, measured); the " << e.ranks_on_node
            << " rank(s) on a node have " << in_units(e.available_per_rank)
            << " available each: lower it or run on more nodes (mpirun -np N)";
    throw Parameters::InputError("Mesh/Global refinements", message.str());
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
