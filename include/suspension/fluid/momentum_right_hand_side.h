#pragma once

#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/la_parallel_vector.h>
#include <deal.II/matrix_free/matrix_free.h>

#include <suspension/fluid/fluid_space.h>
#include <suspension/fluid/momentum_operator.h>
#include <suspension/fluid/momentum_source.h>

#include <vector>

namespace Suspension::Fluid
{
  /// The fields and coefficients the momentum predictor's load is made of.
  template <int dim>
  struct MomentumLoad
  {
    Combination history; // (beta_1 u^n - beta_2 u^{n-1}) / dt
    Combination u_star;  // extrapolated velocity (convection)
    Combination p_sharp; // P# (pressure dofs)
    const std::vector<const MomentumSource<dim> *> *sources = nullptr;
    double time          = 0.;  // t^{n+1}, at which the sources are evaluated
    double alpha_over_dt = 0.;  // of (alpha/dt) M + nu K, for the lifting
    double viscosity     = 0.;  // nu
    double inverse_density = 1.;
    bool   convection    = true;
    bool   stress        = true; // some source adds a stress
  };

  /**
   * The explicit right-hand side of the momentum predictor (issue 14,
   * item 1) in one matrix-free cell loop on the momentum operator's
   * MatrixFree data (velocity DoFs 0, pressure DoFs 1, one quadrature):
   *
   *   b_i = (history - (u*.grad) u* - div(u*) u* / 2 - grad P# + f/rho, v_i)
   *         - (tau/rho, grad v_i) - (A g)_i,
   *
   * with f and tau from the momentum sources at the quadrature points and
   * g the lifting of the step's boundary data (the inhomogeneities of the
   * step's constraints, zero elsewhere), so that A x = b gives u - g on
   * the free DoFs, as the assembled path does with
   * distribute_local_to_global(cell rhs, cell matrix). The fields are read
   * as they are stored (read_dof_values_plain: boundary values included),
   * the load condensed with the homogeneous constraints (Dirichlet rows
   * zero, hanging and periodic DoFs summed into their masters).
   *
   * FEEvaluation's sum factorisation replaces FEValues' shape-function
   * tables; the sources keep their interface (they are called per cell
   * with the real and unit quadrature points).
   *
   * Memory: the history and the result live in the momentum operator's
   * two work vectors (free outside its solves); the extrapolated velocity
   * is held only with convection and the lifting only while some face
   * moves, so a channel holds one velocity vector here, not five.
   */
  template <int dim>
  class MomentumRightHandSide
  {
  public:
    /// After every mesh change (the operator's MatrixFree rebuilt).
    void reinit(const MomentumOperator<dim> &op);

    /// rhs (PETSc, locally owned) from `load`; `step_constraints` are the
    /// velocity constraints with the boundary data at t^{n+1}.
    void assemble(const MomentumOperator<dim>     &op,
                  const FluidSpace<dim>           &space,
                  const AffineConstraints<double> &step_constraints,
                  const MomentumLoad<dim>         &load,
                  VectorType                      &rhs);

    std::size_t memory_consumption() const
    {
      return u_star.memory_consumption() + lifting.memory_consumption() +
             p_sharp.memory_consumption();
    }

  private:
    template <int degree, int n_q>
    void cell_loop(const MomentumOperator<dim> &op, const FluidSpace<dim> &space,
                   const MomentumLoad<dim> &load, bool lifted);

    using Vector = LinearAlgebra::distributed::Vector<double>;
    Vector u_star, lifting, p_sharp; // u_star, lifting: allocated on first use
  };
} // namespace Suspension::Fluid
