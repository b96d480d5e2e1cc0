#pragma once

#include <deal.II/base/point.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/vector.h>

#include <suspension/fluid/fluid_operators.h>

#include <vector>

namespace Suspension::Postprocess
{
  using namespace dealii;

  /**
   * Values of a finite element field at arbitrary points of a distributed
   * mesh: each rank evaluates the points that lie in its own cells, and
   * the results are summed over ranks (averaged where a point lies on a
   * boundary between ranks). Points outside the domain give NaN.
   */
  template <int dim, typename VectorType>
  std::vector<Vector<double>>
  point_values(const DoFHandler<dim>         &dof_handler,
               const VectorType              &vector,
               const std::vector<Point<dim>> &points);
} // namespace Suspension::Postprocess
