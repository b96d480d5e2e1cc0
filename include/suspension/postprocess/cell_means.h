#pragma once

#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/la_parallel_vector.h>

#include <string>

namespace Suspension::Postprocess
{
  using namespace dealii;

  /**
   * Writes one line per active cell: its bounding box (lower corner, upper
   * corner), level and the cell mean of one component of a field, gathered
   * on rank 0 into a text file. Small and plain: scripts/plot_cells.py
   * draws phi and the adaptive mesh from it without ParaView.
   */
  template <int dim>
  void write_cell_means(const DoFHandler<dim>                            &dof_handler,
                        const LinearAlgebra::distributed::Vector<double> &vector,
                        unsigned int                                      component,
                        const std::string                                &name,
                        double                                            time,
                        const std::string                                &filename);
} // namespace Suspension::Postprocess
