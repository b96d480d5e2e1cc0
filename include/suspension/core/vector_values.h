#pragma once

#include <deal.II/base/tensor.h>
#include <deal.II/fe/fe.h>
#include <deal.II/lac/vector.h>

#include <vector>

namespace Suspension
{
  using namespace dealii;

  /// The value at point q of a vector-valued FESystem of dim equal scalar
  /// bases, from one cell's DoF values and the scalar base element's shape
  /// values at the points (shape(base_index, q)). FEValues on the system
  /// would copy every shape value of every component on every reinit;
  /// summing here reads the scalar base's values only (same order of
  /// summation as FEValues, so the same round-off), and only at the points
  /// that are asked for.
  template <int dim, typename ScalarShape>
  Tensor<1, dim> vector_value_from_scalar_base(const FiniteElement<dim> &system,
                                               const Vector<double>     &local,
                                               const ScalarShape &shape, const unsigned int q)
  {
    Tensor<1, dim> value;
    for (unsigned int i = 0; i < local.size(); ++i)
      {
        const auto [c, base_i] = system.system_to_component_index(i);
        value[c] += local[i] * shape(base_i, q);
      }
    return value;
  }

  /// The same at every point of `values`.
  template <int dim, typename ScalarShape>
  void vector_values_from_scalar_base(const FiniteElement<dim> &system, const Vector<double> &local,
                                      const ScalarShape &shape, std::vector<Tensor<1, dim>> &values)
  {
    for (unsigned int q = 0; q < values.size(); ++q)
      values[q] = vector_value_from_scalar_base(system, local, shape, q);
  }
} // namespace Suspension
