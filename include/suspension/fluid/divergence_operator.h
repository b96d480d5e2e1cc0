#pragma once

#include <deal.II/lac/la_parallel_vector.h>

#include <suspension/fluid/momentum_operator.h>

namespace Suspension::Fluid
{
  /**
   * The load of the projection, (div u, q_i) for every pressure test
   * function q_i, without the assembled matrix D (issue 14): one cell loop
   * on the momentum operator's MatrixFree data (velocity DoFs 0, pressure
   * DoFs 1). As with D, u is read with its boundary values as they are
   * stored (no constraint applied to the columns) and the pressure rows are
   * condensed with the hanging-node and periodic constraints; the result
   * equals D u to round-off. What it saves: D's sparsity pattern and
   * assembly at every mesh change, and its memory (in 3D a pressure row
   * couples with 3 x 125 velocity DoFs).
   */
  template <int dim>
  class DivergenceOperator
  {
  public:
    /// After every mesh change (the momentum operator reinitialized).
    void reinit(const MomentumOperator<dim> &op);

    /// load = D u (u: locally owned entries suffice; load: owned). u is
    /// read through the momentum operator's work vector 0 (not in a solve).
    void apply(const MomentumOperator<dim> &op, const VectorType &u, VectorType &load);

    std::size_t memory_consumption() const { return result.memory_consumption(); }

  private:
    template <int degree, int n_q>
    void cell_loop(const MomentumOperator<dim> &op);

    LinearAlgebra::distributed::Vector<double> result; // u: the operator's work vector 0
  };
} // namespace Suspension::Fluid
