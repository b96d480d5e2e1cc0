#include <deal.II/base/mpi.h>
#include <deal.II/matrix_free/fe_evaluation.h>

#include <suspension/fluid/momentum_right_hand_side.h>

namespace Suspension::Fluid
{
  template <int dim>
  void MomentumRightHandSide<dim>::reinit(const MomentumOperator<dim> &op)
  {
    u_star.reinit(0);
    lifting.reinit(0);
    op.get_matrix_free().initialize_dof_vector(p_sharp, op.pressure_index);
  }

  template <int dim>
  void MomentumRightHandSide<dim>::assemble(const MomentumOperator<dim>     &op,
                                            const FluidSpace<dim>           &space,
                                            const AffineConstraints<double> &step_constraints,
                                            const MomentumLoad<dim>         &load,
                                            VectorType                      &rhs)
  {
    const auto &mf      = op.get_matrix_free();
    Vector     &history = op.work_vector(0);
    const auto  read    = [](const Combination &terms, Vector &to) {
      form_locally_owned(terms, to);
      to.update_ghost_values();
    };
    read(load.history, history);
    read(load.p_sharp, p_sharp);
    if (load.convection)
      {
        if (u_star.size() == 0)
          mf.initialize_dof_vector(u_star, op.velocity_index);
        read(load.u_star, u_star);
      }

    // the lifting g: the boundary data of the step at the constrained DoFs
    // (hanging nodes next to a moving wall inherit theirs), zero elsewhere
    bool lifted = false;
    for (const auto &line : step_constraints.get_lines())
      lifted = lifted || (line.inhomogeneity != 0. && history.in_local_range(line.index));
    lifted = Utilities::MPI::max(lifted ? 1 : 0, space.communicator()) > 0;
    if (lifted)
      {
        if (lifting.size() == 0)
          mf.initialize_dof_vector(lifting, op.velocity_index);
        lifting = 0.;
        for (const auto &line : step_constraints.get_lines())
          if (line.inhomogeneity != 0. && lifting.in_local_range(line.index))
            lifting(line.index) = line.inhomogeneity;
        lifting.update_ghost_values();
      }

    if (op.velocity_degree() == 2)
      cell_loop<2, 3>(op, space, load, lifted);
    else
      cell_loop<-1, 0>(op, space, load, lifted);
    copy_locally_owned(op.work_vector(1), rhs);
    for (auto *v : {&history, &u_star, &lifting, &p_sharp})
      v->zero_out_ghost_values();
  }

  template <int dim>
  template <int degree, int n_q>
  void MomentumRightHandSide<dim>::cell_loop(const MomentumOperator<dim> &op,
                                             const FluidSpace<dim>       &space,
                                             const MomentumLoad<dim>     &load,
                                             const bool                   lifted)
  {
    using VA = VectorizedArray<double>;
    constexpr int pressure_degree = degree < 0 ? -1 : degree - 1;
    const auto   &mf = op.get_matrix_free();
    const Vector &history = op.work_vector(0);
    const auto   &unit_points = space.quadrature.get_points();
    const double  inv_rho = load.inverse_density;

    FEEvaluation<dim, degree, n_q, dim, double> test(mf, op.velocity_index),
      old(mf, op.velocity_index), star(mf, op.velocity_index), lift(mf, op.velocity_index);
    FEEvaluation<dim, pressure_degree, n_q, 1, double> pressure(mf, op.pressure_index);
    const unsigned int n_points = test.n_q_points;
    AssertDimension(n_points, unit_points.size());
    // per lane of a cell batch: the sources' force and stress at the points
    std::vector<Point<dim>>                           points(n_points);
    std::vector<std::vector<Tensor<1, dim>>>          force(VA::size(),
                                                   std::vector<Tensor<1, dim>>(n_points));
    std::vector<std::vector<SymmetricTensor<2, dim>>> stress(
      VA::size(), std::vector<SymmetricTensor<2, dim>>(n_points));

    const auto worker = [&](const MatrixFree<dim, double> &, Vector &dst, const Vector &,
                            const std::pair<unsigned int, unsigned int> &range) {
      for (unsigned int cell = range.first; cell < range.second; ++cell)
        {
          test.reinit(cell);
          old.reinit(cell);
          old.read_dof_values_plain(history);
          old.evaluate(EvaluationFlags::values);
          pressure.reinit(cell);
          pressure.read_dof_values_plain(p_sharp);
          pressure.evaluate(EvaluationFlags::gradients);
          if (load.convection)
            {
              star.reinit(cell);
              star.read_dof_values_plain(u_star);
              star.evaluate(EvaluationFlags::values | EvaluationFlags::gradients);
            }
          // only cells that touch a moving wall carry a lifting
          bool lift_cell = false;
          if (lifted)
            {
              lift.reinit(cell);
              lift.read_dof_values_plain(lifting);
              for (unsigned int i = 0; i < lift.dofs_per_cell && !lift_cell; ++i)
                for (unsigned int v = 0; v < VA::size(); ++v)
                  lift_cell = lift_cell || lift.begin_dof_values()[i][v] != 0.;
              if (lift_cell)
                lift.evaluate(EvaluationFlags::values | EvaluationFlags::gradients);
            }

          // the sources, cell by cell (a batch holds VA::size() cells)
          const unsigned int n_lanes = mf.n_active_entries_per_cell_batch(cell);
          bool               cell_stress = false;
          for (unsigned int v = 0; v < n_lanes; ++v)
            {
              for (unsigned int q = 0; q < n_points; ++q)
                for (unsigned int d = 0; d < dim; ++d)
                  points[q][d] = test.quadrature_point(q)[d][v];
              std::fill(force[v].begin(), force[v].end(), Tensor<1, dim>());
              std::fill(stress[v].begin(), stress[v].end(), SymmetricTensor<2, dim>());
              const auto tria_cell = mf.get_cell_iterator(cell, v, op.velocity_index);
              for (const auto *s : *load.sources)
                s->add(tria_cell, points, unit_points, load.time, force[v], stress[v]);
              if (load.stress)
                for (const auto &s : stress[v])
                  cell_stress = cell_stress || s.norm() != 0.;
            }

          const bool with_gradient = lift_cell || cell_stress;
          for (unsigned int q = 0; q < n_points; ++q)
            {
              Tensor<1, dim, VA> value = old.get_value(q) - pressure.get_gradient(q);
              for (unsigned int v = 0; v < n_lanes; ++v)
                for (unsigned int d = 0; d < dim; ++d)
                  value[d][v] += inv_rho * force[v][q][d];
              if (load.convection)
                {
                  const Tensor<1, dim, VA> w    = star.get_value(q);
                  const Tensor<2, dim, VA> grad = star.get_gradient(q);
                  value -= grad * w + (0.5 * trace(grad)) * w;
                }
              Tensor<2, dim, VA> gradient;
              if (lift_cell)
                {
                  value -= load.alpha_over_dt * lift.get_value(q);
                  gradient -= load.viscosity * lift.get_gradient(q);
                  // semi-implicit convection: the operator's C(u*) g too
                  if (op.advecting())
                    value -= lift.get_gradient(q) * op.advection_value(cell, q) +
                             op.advection_half_div(cell, q) * lift.get_value(q);
                }
              if (cell_stress)
                for (unsigned int v = 0; v < n_lanes; ++v)
                  for (unsigned int c = 0; c < dim; ++c)
                    for (unsigned int d = 0; d < dim; ++d)
                      gradient[c][d][v] -= inv_rho * stress[v][q][c][d];
              test.submit_value(value, q);
              if (with_gradient)
                test.submit_gradient(gradient, q);
            }
          test.integrate_scatter(with_gradient ?
                                   EvaluationFlags::values | EvaluationFlags::gradients :
                                   EvaluationFlags::values,
                                 dst);
        }
    };
    mf.template cell_loop<Vector, Vector>(worker, op.work_vector(1), history, true);
  }

  template class MomentumRightHandSide<2>;
  template class MomentumRightHandSide<3>;
} // namespace Suspension::Fluid
