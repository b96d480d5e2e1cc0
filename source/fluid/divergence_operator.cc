#include <deal.II/matrix_free/fe_evaluation.h>

#include <suspension/fluid/divergence_operator.h>

namespace Suspension::Fluid
{
  template <int dim>
  void DivergenceOperator<dim>::reinit(const MomentumOperator<dim> &op)
  {
    op.get_matrix_free().initialize_dof_vector(result, op.pressure_index);
  }

  template <int dim>
  void DivergenceOperator<dim>::apply(const MomentumOperator<dim> &op, const VectorType &u,
                                      VectorType &load)
  {
    auto &velocity = op.work_vector(0);
    copy_locally_owned(u, velocity);
    velocity.update_ghost_values();
    if (op.velocity_degree() == 2)
      cell_loop<2, 3>(op);
    else
      cell_loop<-1, 0>(op);
    velocity.zero_out_ghost_values();
    copy_locally_owned(result, load);
  }

  template <int dim>
  template <int degree, int n_q>
  void DivergenceOperator<dim>::cell_loop(const MomentumOperator<dim> &op)
  {
    using Vector                   = LinearAlgebra::distributed::Vector<double>;
    constexpr int pressure_degree = degree < 0 ? -1 : degree - 1;
    const auto   &mf               = op.get_matrix_free();
    mf.template cell_loop<Vector, Vector>(
      [&op](const MatrixFree<dim, double> &data, Vector &dst, const Vector &src,
            const std::pair<unsigned int, unsigned int> &range) {
        FEEvaluation<dim, degree, n_q, dim, double>          u(data, op.velocity_index);
        FEEvaluation<dim, pressure_degree, n_q, 1, double> q(data, op.pressure_index);
        for (unsigned int cell = range.first; cell < range.second; ++cell)
          {
            u.reinit(cell);
            q.reinit(cell);
            // plain: the boundary values of u count, as in D's columns
            u.read_dof_values_plain(src);
            u.evaluate(EvaluationFlags::gradients);
            for (const unsigned int point : q.quadrature_point_indices())
              q.submit_value(u.get_divergence(point), point);
            q.integrate_scatter(EvaluationFlags::values, dst);
          }
      },
      result, op.work_vector(0), true);
  }

  template class DivergenceOperator<2>;
  template class DivergenceOperator<3>;
} // namespace Suspension::Fluid
