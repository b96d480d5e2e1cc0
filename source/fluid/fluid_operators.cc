#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/sparsity_tools.h>

#include <petscsys.h>

#include <suspension/fluid/fluid_operators.h>

#include <string>
#include <utility>
#include <vector>

namespace Suspension::Fluid
{
  namespace
  {
    /// BoomerAMG for a momentum matrix.
    PETScWrappers::PreconditionBoomerAMG::AdditionalData momentum_amg_data(const int  dim,
                                                                           const bool symmetric)
    {
      PETScWrappers::PreconditionBoomerAMG::AdditionalData data;
      data.symmetric_operator = symmetric;
      data.strong_threshold   = dim == 2 ? 0.25 : 0.5;
      // With small time steps the matrix is dominated by the mass matrix:
      // few strong connections, so coarsening stalls early and hypre's
      // default direct solve on the (then large) coarsest level dominates
      // the cost. Smooth there instead.
      data.relaxation_type_coarse =
        PETScWrappers::PreconditionBoomerAMG::AdditionalData::RelaxationType::symmetricSORJacobi;
      data.n_sweeps_coarse = 2;
      return data;
    }

    /// hypre options that deal.II's AdditionalData does not expose, set in
    /// PETSc's options database while one preconditioner reads them (its
    /// initialize() calls PCSetFromOptions) and removed again, so that no
    /// other preconditioner sees them.
    class ScopedPetscOptions
    {
    public:
      explicit ScopedPetscOptions(std::vector<std::pair<std::string, std::string>> options)
        : options(std::move(options))
      {
        for (const auto &[name, value] : this->options)
          AssertThrow(PetscOptionsSetValue(nullptr, name.c_str(), value.c_str()) == 0,
                      ExcMessage("PetscOptionsSetValue " + name));
      }
      ~ScopedPetscOptions()
      {
        for (const auto &option : options)
          PetscOptionsClearValue(nullptr, option.first.c_str());
      }

    private:
      const std::vector<std::pair<std::string, std::string>> options;
    };

    /// A PETSc Krylov solve to `tolerance` relative to |b|; returns the
    /// iterations (0 for b = 0).
    template <typename Solver, typename Preconditioner>
    unsigned int krylov_solve(const MatrixType                     &matrix,
                              VectorType                           &x,
                              const VectorType                     &b,
                              const Preconditioner                 &preconditioner,
                              const double                          tolerance,
                              const MPI_Comm                        communicator,
                              const typename Solver::AdditionalData &data = {})
    {
      const double norm = b.l2_norm();
      if (norm == 0.)
        {
          x = 0.;
          return 0;
        }
      SolverControl control(5000, tolerance * norm);
      Solver        solver(control, communicator, data);
      solver.solve(matrix, x, b, preconditioner);
      return control.last_step();
    }

    template <typename Preconditioner>
    unsigned int cg_solve(const MatrixType     &matrix,
                          VectorType           &x,
                          const VectorType     &b,
                          const Preconditioner &preconditioner,
                          const double          tolerance,
                          const MPI_Comm        communicator)
    {
      return krylov_solve<PETScWrappers::SolverCG>(matrix, x, b, preconditioner, tolerance,
                                                   communicator);
    }

    /// One sparsity pattern for all the given matrices (building it is
    /// the expensive part of a mesh change).
    template <int dim>
    void make_matrices(const std::vector<MatrixType *>  &matrices,
                       const DoFHandler<dim>           &dof,
                       const IndexSet                  &owned,
                       const IndexSet                  &relevant,
                       const AffineConstraints<double> &constraints,
                       const bool                       components_decoupled)
    {
      DynamicSparsityPattern dsp(relevant);
      const unsigned int     nc = dof.get_fe().n_components();
      Table<2, DoFTools::Coupling> coupling(nc, nc);
      for (unsigned int c = 0; c < nc; ++c)
        for (unsigned int d = 0; d < nc; ++d)
          coupling[c][d] = (!components_decoupled || c == d) ?
                             DoFTools::always : DoFTools::none;
      DoFTools::make_sparsity_pattern(dof, coupling, dsp, constraints, false);
      SparsityTools::distribute_sparsity_pattern(dsp, owned, dof.get_communicator(), relevant);
      // the first from the pattern, the others as copies of its structure
      // (MatDuplicate: no second pass over the pattern)
      matrices[0]->reinit(owned, owned, dsp, dof.get_communicator());
      for (unsigned int m = 1; m < matrices.size(); ++m)
        matrices[m]->reinit(*matrices[0]);
    }
  } // namespace

  template <int dim>
  void FluidOperators<dim>::reinit(const FluidSpace<dim> &space)
  {
    communicator = space.communicator();
    if (matrix_free_momentum)
      {
        momentum_operator.reinit(space);
        divergence_operator.reinit(momentum_operator);
      }
    else
      make_matrices({&M, &K, &A}, space.dof_velocity, space.owned_velocity,
                    space.relevant_velocity, space.velocity_constraints, true);
    if (step_matrix)
      make_matrices({&A_step}, space.dof_velocity, space.owned_velocity,
                    space.relevant_velocity, space.velocity_constraints, false);
    make_matrices({&L}, space.dof_pressure, space.owned_pressure, space.relevant_pressure,
                  space.increment_constraints, false);
    make_matrices({&Mp}, space.dof_pressure, space.owned_pressure, space.relevant_pressure,
                  space.pressure_constraints, false);

    // D: pressure rows condensed, velocity columns kept as they are.
    const AffineConstraints<double> no_constraints;
    if (!matrix_free_momentum)
      {
        DynamicSparsityPattern dsp(space.dof_pressure.n_dofs(),
                                   space.dof_velocity.n_dofs(),
                                   space.relevant_pressure);
        std::vector<types::global_dof_index> p_dofs(space.fe_pressure.n_dofs_per_cell());
        std::vector<types::global_dof_index> u_dofs(space.fe_velocity.n_dofs_per_cell());
        for (const auto &cell : space.dof_velocity.active_cell_iterators())
          if (cell->is_locally_owned())
            {
              cell->get_dof_indices(u_dofs);
              FluidSpace<dim>::cell_of(cell, space.dof_pressure)->get_dof_indices(p_dofs);
              space.pressure_constraints.add_entries_local_to_global(p_dofs, no_constraints, u_dofs, dsp, false);
            }
        SparsityTools::distribute_sparsity_pattern(dsp, space.owned_pressure, communicator,
                                                   space.relevant_pressure);
        D.reinit(space.owned_pressure, space.owned_velocity, dsp, communicator);
      }

    flux_weights.reinit(space.owned_velocity, communicator);
    unit_force.reinit(space.owned_velocity, communicator);

    // (velocity gradients only for the assembled M, K and D)
    FEValues<dim> fe_u(space.fe_velocity, space.quadrature,
                       update_values | update_JxW_values |
                         (matrix_free_momentum ? update_default : update_gradients));
    FEValues<dim> fe_p(space.fe_pressure, space.quadrature,
                       update_values | update_gradients | update_JxW_values);
    const unsigned int nu = space.fe_velocity.n_dofs_per_cell();
    const unsigned int np = space.fe_pressure.n_dofs_per_cell();
    FullMatrix<double> cell_M(nu, nu), cell_K(nu, nu), cell_L(np, np),
      cell_Mp(np, np), cell_D(np, nu);
    Vector<double> cell_flux(nu), cell_force(nu);
    std::vector<types::global_dof_index> u_dofs(nu), p_dofs(np);
    std::vector<unsigned int> component(nu);
    for (unsigned int i = 0; i < nu; ++i)
      component[i] = space.fe_velocity.system_to_component_index(i).first;

    for (const auto &cell : space.dof_velocity.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          const auto pcell = FluidSpace<dim>::cell_of(cell, space.dof_pressure);
          fe_u.reinit(cell);
          fe_p.reinit(pcell);
          cell_M = 0; cell_K = 0; cell_L = 0; cell_Mp = 0; cell_D = 0;
          cell_flux = 0; cell_force = 0;
          for (const unsigned int q : fe_u.quadrature_point_indices())
            {
              const double JxW = fe_u.JxW(q);
              for (unsigned int i = 0; i < nu; ++i)
                {
                  const unsigned int ci = component[i];
                  const double       vi = fe_u.shape_value(i, q);
                  if (ci == 0)
                    {
                      cell_flux(i) += vi * JxW;
                      cell_force(i) += vi * JxW;
                    }
                  if (matrix_free_momentum)
                    continue;
                  const auto &gi = fe_u.shape_grad(i, q);
                  for (unsigned int j = 0; j < nu; ++j)
                    if (component[j] == ci)
                      {
                        cell_M(i, j) += vi * fe_u.shape_value(j, q) * JxW;
                        cell_K(i, j) += gi * fe_u.shape_grad(j, q) * JxW;
                      }
                  for (unsigned int k = 0; k < np; ++k)
                    cell_D(k, i) += fe_p.shape_value(k, q) * gi[ci] * JxW;
                }
              for (unsigned int k = 0; k < np; ++k)
                for (unsigned int l = 0; l < np; ++l)
                  {
                    cell_L(k, l) += fe_p.shape_grad(k, q) * fe_p.shape_grad(l, q) * JxW;
                    cell_Mp(k, l) += fe_p.shape_value(k, q) * fe_p.shape_value(l, q) * JxW;
                  }
            }
          cell->get_dof_indices(u_dofs);
          pcell->get_dof_indices(p_dofs);
          if (!matrix_free_momentum)
            {
              space.velocity_constraints.distribute_local_to_global(cell_M, u_dofs, M);
              space.velocity_constraints.distribute_local_to_global(cell_K, u_dofs, K);
            }
          space.velocity_constraints.distribute_local_to_global(cell_force, u_dofs, unit_force);
          flux_weights.add(u_dofs, cell_flux);
          space.increment_constraints.distribute_local_to_global(cell_L, p_dofs, L);
          space.pressure_constraints.distribute_local_to_global(cell_Mp, p_dofs, Mp);
          if (!matrix_free_momentum)
            space.pressure_constraints.distribute_local_to_global(cell_D, p_dofs, no_constraints,
                                                                  u_dofs, D);
        }
    for (auto *m : {&M, &K, &L, &Mp, &D})
      if (m->m() > 0)
        m->compress(VectorOperation::add);
    flux_weights.compress(VectorOperation::add);
    unit_force.compress(VectorOperation::add);

    amg_pressure = std::make_unique<PETScWrappers::PreconditionBoomerAMG>();
    PETScWrappers::PreconditionBoomerAMG::AdditionalData data;
    data.symmetric_operator = true;
    data.strong_threshold   = dim == 2 ? 0.25 : 0.5;
    // In 3D, HMIS coarsening with extended+i interpolation truncated to 4
    // entries per row (hypre's advice for 3D): coarse operators with fewer
    // entries, a V-cycle 2.5 times cheaper on the reduced 3D box for 6 %
    // more iterations. In 2D it saved nothing (doc/performance.md, session 33).
    std::vector<std::pair<std::string, std::string>> options;
    if (dim == 3)
      options = {{"-pc_hypre_boomeramg_coarsen_type", "HMIS"},
                 {"-pc_hypre_boomeramg_interp_type", "ext+i"},
                 {"-pc_hypre_boomeramg_P_max", "4"}};
    const ScopedPetscOptions hypre_options(std::move(options));
    amg_pressure->initialize(L, data);
    jacobi_mass = std::make_unique<PETScWrappers::PreconditionJacobi>(Mp);

    momentum_alpha_over_dt = momentum_nu = -1.;
  }

  template <int dim>
  void FluidOperators<dim>::set_momentum_coefficients(const double alpha_over_dt,
                                                      const double nu)
  {
    if (alpha_over_dt == momentum_alpha_over_dt && nu == momentum_nu)
      return;
    momentum_alpha_over_dt = alpha_over_dt;
    momentum_nu            = nu;
    if (matrix_free_momentum)
      {
        momentum_operator.set_coefficients(alpha_over_dt, nu);
        return;
      }
    A.copy_from(K);
    A *= nu;
    // MatrixBase::add() would assume different patterns and rebuild A
    const PetscErrorCode ierr = MatAXPY(A, alpha_over_dt, M, SAME_NONZERO_PATTERN);
    AssertThrow(ierr == 0, ExcPETScError(ierr));

    if (jacobi_momentum)
      {
        jacobi_momentum_preconditioner = std::make_unique<PETScWrappers::PreconditionJacobi>(A);
        return;
      }
    amg_momentum = std::make_unique<PETScWrappers::PreconditionBoomerAMG>();
    amg_momentum->initialize(A, momentum_amg_data(dim, true));
  }

  template <int dim>
  unsigned int FluidOperators<dim>::solve_momentum(VectorType &x, const VectorType &b,
                                                   const double tolerance) const
  {
    if (matrix_free_momentum)
      return momentum_operator.solve(x, b, tolerance);
    if (jacobi_momentum)
      return cg_solve(A, x, b, *jacobi_momentum_preconditioner, tolerance, communicator);
    return cg_solve(A, x, b, *amg_momentum, tolerance, communicator);
  }

  template <int dim>
  void FluidOperators<dim>::prepare_step_matrix()
  {
    amg_step = std::make_unique<PETScWrappers::PreconditionBoomerAMG>();
    amg_step->initialize(A_step, momentum_amg_data(dim, false));
  }

  template <int dim>
  unsigned int FluidOperators<dim>::solve_step_matrix(VectorType &x, const VectorType &b,
                                                      const double tolerance) const
  {
    return krylov_solve<PETScWrappers::SolverGMRES>(A_step, x, b, *amg_step, tolerance,
                                                    communicator,
                                                    PETScWrappers::SolverGMRES::AdditionalData(50));
  }

  template <int dim>
  unsigned int FluidOperators<dim>::solve_pressure_laplace(VectorType &x, const VectorType &b,
                                                           const double tolerance) const
  {
    return cg_solve(L, x, b, *amg_pressure, tolerance, communicator);
  }

  template <int dim>
  unsigned int FluidOperators<dim>::solve_pressure_mass(VectorType &x, const VectorType &b,
                                                        const double tolerance) const
  {
    return cg_solve(Mp, x, b, *jacobi_mass, tolerance, communicator);
  }

  template <int dim>
  void FluidOperators<dim>::apply_divergence(const VectorType &u, VectorType &load)
  {
    if (matrix_free_momentum)
      divergence_operator.apply(momentum_operator, u, load);
    else
      D.vmult(load, u);
  }

  template class FluidOperators<2>;
  template class FluidOperators<3>;
} // namespace Suspension::Fluid
