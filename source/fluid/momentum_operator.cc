#include <deal.II/base/mpi.h>
#include <deal.II/fe/mapping_q1.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/solver_gmres.h>
#include <deal.II/matrix_free/fe_evaluation.h>
#include <deal.II/matrix_free/tools.h>

#include <suspension/fluid/momentum_operator.h>

#include <petscvec.h>

#include <algorithm>

namespace Suspension::Fluid
{
  void copy_locally_owned(const VectorType &from, LinearAlgebra::distributed::Vector<double> &to)
  {
    AssertDimension(from.locally_owned_size(), to.locally_owned_size());
    const PetscScalar *values;
    AssertThrow(VecGetArrayRead(from, &values) == 0, ExcMessage("VecGetArrayRead"));
    std::copy(values, values + to.locally_owned_size(), to.begin());
    AssertThrow(VecRestoreArrayRead(from, &values) == 0, ExcMessage("VecRestoreArrayRead"));
  }

  void copy_locally_owned(const LinearAlgebra::distributed::Vector<double> &from, VectorType &to)
  {
    AssertDimension(from.locally_owned_size(), to.locally_owned_size());
    PetscScalar *values;
    AssertThrow(VecGetArray(to, &values) == 0, ExcMessage("VecGetArray"));
    std::copy(from.begin(), from.begin() + from.locally_owned_size(), values);
    AssertThrow(VecRestoreArray(to, &values) == 0, ExcMessage("VecRestoreArray"));
  }

  void form_locally_owned(const Combination &terms, VectorType &to)
  {
    Assert(!terms.empty(), ExcInternalError());
    AssertThrow(VecCopy(*terms[0].second, to) == 0, ExcMessage("VecCopy"));
    AssertThrow(VecScale(to, terms[0].first) == 0, ExcMessage("VecScale"));
    for (unsigned int k = 1; k < terms.size(); ++k)
      AssertThrow(VecAXPY(to, terms[k].first, *terms[k].second) == 0, ExcMessage("VecAXPY"));
  }

  void form_locally_owned(const Combination &terms, LinearAlgebra::distributed::Vector<double> &to)
  {
    Assert(!terms.empty(), ExcInternalError());
    Vec view;
    AssertThrow(VecCreateMPIWithArray(to.get_mpi_communicator(), 1, to.locally_owned_size(),
                                      PETSC_DETERMINE, to.begin(), &view) == 0,
                ExcMessage("VecCreateMPIWithArray"));
    AssertThrow(VecCopy(*terms[0].second, view) == 0, ExcMessage("VecCopy"));
    AssertThrow(VecScale(view, terms[0].first) == 0, ExcMessage("VecScale"));
    for (unsigned int k = 1; k < terms.size(); ++k)
      AssertThrow(VecAXPY(view, terms[k].first, *terms[k].second) == 0, ExcMessage("VecAXPY"));
    AssertThrow(VecDestroy(&view) == 0, ExcMessage("VecDestroy"));
  }

  template <int dim>
  void MomentumOperator<dim>::reinit(const FluidSpace<dim> &space)
  {
    degree = space.fe_velocity.degree;
    typename MatrixFree<dim, double>::AdditionalData data;
    data.tasks_parallel_scheme = MatrixFree<dim, double>::AdditionalData::none;
    // quadrature points: the right-hand side evaluates its sources there
    data.mapping_update_flags =
      update_values | update_gradients | update_JxW_values | update_quadrature_points;
    const std::vector<const DoFHandler<dim> *> dofs = {&space.dof_velocity, &space.dof_pressure};
    const std::vector<const AffineConstraints<double> *> constraints = {
      &space.velocity_constraints, &space.pressure_constraints};
    matrix_free.reinit(MappingQ1<dim>(), dofs, constraints, QGauss<1>(degree + 1), data);
    matrix_free.initialize_dof_vector(x_local);
    matrix_free.initialize_dof_vector(b_local);
    // every constrained DoF (Dirichlet, hanging, periodic) is left out of
    // the system and filled in by the caller's distribute()
    constrained.clear();
    const auto &owned = x_local.get_partitioner()->locally_owned_range();
    for (unsigned int i = 0; i < owned.n_elements(); ++i)
      if (space.velocity_constraints.is_constrained(owned.nth_index_in_set(i)))
        constrained.push_back(i);
    mass = viscosity = -1.;
    clear_advection();
    advection_values.clear(); // sized for the old mesh
    advection_half_divergence.clear();
    if (degree == 2)
      {
        compute_diagonal<2, 3>(mass_diagonal, 1., 0.);
        compute_diagonal<2, 3>(viscous_diagonal, 0., 1.);
      }
    else
      {
        compute_diagonal<-1, 0>(mass_diagonal, 1., 0.);
        compute_diagonal<-1, 0>(viscous_diagonal, 0., 1.);
      }
    for (const unsigned int i : constrained)
      mass_diagonal.local_element(i) = viscous_diagonal.local_element(i) = 0.;
  }

  template <int dim>
  template <int fe_degree, int n_q>
  void MomentumOperator<dim>::apply_cells(Vector &dst, const Vector &src) const
  {
    matrix_free.template cell_loop<Vector, Vector>(
      [this](const MatrixFree<dim, double> &mf, Vector &out, const Vector &in,
             const std::pair<unsigned int, unsigned int> &range) {
        FEEvaluation<dim, fe_degree, n_q, dim, double> u(mf);
        for (unsigned int cell = range.first; cell < range.second; ++cell)
          {
            u.reinit(cell);
            u.gather_evaluate(in, EvaluationFlags::values | EvaluationFlags::gradients);
            if (!advection_active)
              for (const unsigned int q : u.quadrature_point_indices())
                {
                  u.submit_value(mass * u.get_value(q), q);
                  u.submit_gradient(viscosity * u.get_gradient(q), q);
                }
            else
              for (const unsigned int q : u.quadrature_point_indices())
                {
                  const unsigned int k     = cell * u.n_q_points + q;
                  const auto         value = u.get_value(q);
                  const auto         grad  = u.get_gradient(q);
                  u.submit_value((mass + advection_half_divergence[k]) * value +
                                   grad * advection_values[k],
                                 q);
                  u.submit_gradient(viscosity * grad, q);
                }
            u.integrate_scatter(EvaluationFlags::values | EvaluationFlags::gradients, out);
          }
      },
      dst, src, true);
  }

  template <int dim>
  template <int fe_degree, int n_q>
  void MomentumOperator<dim>::evaluate_advection(const Vector &u_star)
  {
    FEEvaluation<dim, fe_degree, n_q, dim, double> w(matrix_free);
    const unsigned int n_batches = matrix_free.n_cell_batches();
    n_advection_points = w.n_q_points;
    advection_values.resize(std::size_t(n_batches) * w.n_q_points);
    advection_half_divergence.resize(std::size_t(n_batches) * w.n_q_points);
    for (unsigned int cell = 0; cell < n_batches; ++cell)
      {
        w.reinit(cell);
        // as stored, boundary values included (as the explicit right-hand
        // side reads it)
        w.read_dof_values_plain(u_star);
        w.evaluate(EvaluationFlags::values | EvaluationFlags::gradients);
        for (const unsigned int q : w.quadrature_point_indices())
          {
            const unsigned int k         = cell * w.n_q_points + q;
            advection_values[k]          = w.get_value(q);
            advection_half_divergence[k] = 0.5 * w.get_divergence(q);
          }
      }
  }

  template <int dim>
  void MomentumOperator<dim>::set_advection(const Combination &terms)
  {
    // x_local is free between solves; the caller's solve overwrites it
    form_locally_owned(terms, x_local);
    x_local.update_ghost_values();
    if (degree == 2)
      evaluate_advection<2, 3>(x_local);
    else
      evaluate_advection<-1, 0>(x_local);
    x_local.zero_out_ghost_values();
    advection_active = true;
  }

  template <int dim>
  void MomentumOperator<dim>::clear_advection()
  {
    advection_active = false;
  }

  template <int dim>
  void MomentumOperator<dim>::vmult(Vector &dst, const Vector &src) const
  {
    if (degree == 2)
      apply_cells<2, 3>(dst, src);
    else
      apply_cells<-1, 0>(dst, src);
    for (const unsigned int i : constrained)
      dst.local_element(i) = src.local_element(i);
  }

  template <int dim>
  template <int fe_degree, int n_q>
  void MomentumOperator<dim>::compute_diagonal(Vector &diagonal, const double mass,
                                              const double viscosity) const
  {
    // The operator acts on each velocity component alike, and the
    // constraints that couple DoFs (hanging nodes, periodicity) do too, so
    // its diagonal is computed for the first component with a scalar
    // FEEvaluation and copied to the others: the unit vectors of one cell
    // are then 27 scalar ones instead of 81 three-component ones (in 3D,
    // Q2), and one component instead of dim. A Dirichlet value of one
    // component only (e.g. a slip wall) decouples nothing from the free
    // DoFs, but where the first component is constrained and another is
    // not, the first has no value to copy: then every component is
    // computed. deal.II's compute_diagonal() selects the component in a
    // vector of vectors only.
    const EvaluationFlags::EvaluationFlags flags =
      (mass != 0. ? EvaluationFlags::values : EvaluationFlags::nothing) |
      (viscosity != 0. ? EvaluationFlags::gradients : EvaluationFlags::nothing);
    // only the terms with a non-zero coefficient: the mass diagonal needs
    // no gradients, the viscous one no values
    const auto component_diagonal = [&](std::vector<Vector> &components, const unsigned int c) {
      MatrixFreeTools::compute_diagonal<dim, fe_degree, n_q, 1, double, VectorizedArray<double>>(
        matrix_free, components, [&](FEEvaluation<dim, fe_degree, n_q, 1, double> &u) {
          u.evaluate(flags);
          for (const unsigned int q : u.quadrature_point_indices())
            {
              if (mass != 0.)
                u.submit_value(mass * u.get_value(q), q);
              if (viscosity != 0.)
                u.submit_gradient(viscosity * u.get_gradient(q), q);
            }
          u.integrate(flags);
        },
        0, 0, c);
    };
    // the other components' vectors only if they are computed (below)
    std::vector<Vector> components(dim);
    matrix_free.initialize_dof_vector(components[0]);
    component_diagonal(components, 0);
    matrix_free.initialize_dof_vector(diagonal);
    diagonal = components[0];

    // copy: on each locally owned cell, DoF (c, i) takes the value of
    // (0, i); a support point's DoFs share one owner
    std::vector<bool> is_constrained(diagonal.locally_owned_size(), false);
    for (const unsigned int i : constrained)
      is_constrained[i] = true;
    bool                      first_alone_constrained = false;
    const DoFHandler<dim>    &dof_handler = matrix_free.get_dof_handler(0);
    const FiniteElement<dim> &fe          = dof_handler.get_fe();
    const auto               &partitioner = *diagonal.get_partitioner();
    std::vector<types::global_dof_index> dofs(fe.n_dofs_per_cell());
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          cell->get_dof_indices(dofs);
          for (unsigned int i = 0; i < fe.n_dofs_per_cell(); ++i)
            {
              const auto [component, index] = fe.system_to_component_index(i);
              if (component == 0 || !partitioner.in_local_range(dofs[i]))
                continue;
              const unsigned int target = partitioner.global_to_local(dofs[i]);
              const unsigned int source =
                partitioner.global_to_local(dofs[fe.component_to_system_index(0, index)]);
              diagonal.local_element(target) = components[0].local_element(source);
              first_alone_constrained |= is_constrained[source] && !is_constrained[target];
            }
        }
    if (Utilities::MPI::logical_or(first_alone_constrained, diagonal.get_mpi_communicator()))
      {
        for (unsigned int c = 1; c < dim; ++c)
          {
            matrix_free.initialize_dof_vector(components[c]);
            component_diagonal(components, c);
          }
        diagonal = 0.;
        for (const auto &v : components)
          diagonal += v;
      }
  }

  template <int dim>
  void MomentumOperator<dim>::set_coefficients(const double mass_, const double viscosity_)
  {
    mass      = mass_;
    viscosity = viscosity_;
  }

  template <int dim>
  void MomentumOperator<dim>::InverseDiagonal::vmult(Vector &dst, const Vector &src) const
  {
    const double *m = op->mass_diagonal.begin(), *k = op->viscous_diagonal.begin();
    const double *in  = src.begin();
    double       *out = dst.begin();
    for (unsigned int i = 0; i < src.locally_owned_size(); ++i)
      {
        const double d = op->mass * m[i] + op->viscosity * k[i];
        out[i]         = (d > 0. ? 1. / d : 1.) * in[i];
      }
  }

  template <int dim>
  std::size_t MomentumOperator<dim>::vector_memory() const
  {
    return mass_diagonal.memory_consumption() + viscous_diagonal.memory_consumption() +
           x_local.memory_consumption() + b_local.memory_consumption() +
           advection_values.memory_consumption() + advection_half_divergence.memory_consumption();
  }

  template <int dim>
  unsigned int MomentumOperator<dim>::solve(VectorType &x, const VectorType &b,
                                            const double tolerance) const
  {
    copy_locally_owned(b, b_local);
    copy_locally_owned(x, x_local);
    for (const unsigned int i : constrained)
      b_local.local_element(i) = x_local.local_element(i) = 0.;

    const double norm = b_local.l2_norm();
    unsigned int iterations = 0;
    if (norm == 0.)
      x_local = 0.;
    else
      {
        SolverControl control(5000, tolerance * norm);
        if (!advection_active)
          {
            SolverCG<Vector> cg(control);
            cg.solve(*this, x_local, b_local, InverseDiagonal{this});
          }
        else
          {
            // right preconditioning: the residual tested is b - A x, as CG's
            typename SolverGMRES<Vector>::AdditionalData data(50, true);
            SolverGMRES<Vector> gmres(control, data);
            gmres.solve(*this, x_local, b_local, InverseDiagonal{this});
          }
        iterations = control.last_step();
      }
    copy_locally_owned(x_local, x);
    return iterations;
  }

  template class MomentumOperator<2>;
  template class MomentumOperator<3>;
} // namespace Suspension::Fluid
