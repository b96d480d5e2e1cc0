#pragma once

#include <deal.II/base/table_handler.h>

#include <suspension/mesh/mesh_adaptor.h>

#include <iosfwd>

namespace Suspension::Postprocess
{
  using namespace dealii;

  /**
   * What the adaptive mesh did: its columns of statistics.txt (levels,
   * cells on the finest level, interface cells below it, whether the step
   * changed the mesh and what that cost) and the end-of-run line (how
   * many adaptations, the worst lag of the refinement behind the
   * interface). MeshAdaptor::levels() reduces over MPI.
   */
  class MeshReport
  {
  public:
    explicit MeshReport(bool with_solid);

    /// the mesh a step ran on; adapted: it was changed for the next one,
    /// which took 'seconds'
    /// counts the adaptation; with `row`, adds the step's columns to statistics
    void record(TableHandler &statistics, bool row, const MeshLevels &levels, bool adapted,
                double seconds);
    void report(std::ostream &out, types::global_cell_index n_cells) const;

    void save(std::ostream &out) const;
    void load(std::istream &in);

  private:
    const bool               with_solid;
    unsigned int             n_adaptations          = 0;
    types::global_cell_index worst_coarse_interface = 0; // over all steps
  };
} // namespace Suspension::Postprocess
