#pragma once

#include <deal.II/lac/generic_linear_algebra.h>
#include <deal.II/lac/petsc_precondition.h>
#include <deal.II/lac/petsc_solver.h>

#include <suspension/fluid/divergence_operator.h>
#include <suspension/fluid/fluid_space.h>
#include <suspension/fluid/momentum_operator.h>

#include <memory>

namespace Suspension::Fluid
{
  using VectorType = LinearAlgebraPETSc::MPI::Vector;
  using MatrixType = LinearAlgebraPETSc::MPI::SparseMatrix;

  /**
   * The matrices of the projection scheme that do not depend on the
   * solution, assembled once per mesh (and, for the momentum matrix, once
   * per time-step size), with their preconditioners:
   *
   *   velocity  M (mass), K (vector Laplacian), A = (alpha/dt) M + nu K,
   *   pressure  L (Laplacian, increment constraints), Mp (mass),
   *   D         (div v_j, q_i): pressure rows (condensed), velocity columns
   *             (not condensed, so D u is exact for any u with its boundary
   *             values); with the matrix-free momentum operator applied
   *             matrix-free instead (DivergenceOperator),
   *   flux      m_x . u = integral of u_x, and b_x = (e_x, v) condensed,
   *             the load of a unit streamwise force.
   *
   * Convection is explicit, so A is symmetric positive definite and the
   * whole step needs CG with BoomerAMG only.
   */
  template <int dim>
  class FluidOperators
  {
  public:
    /// Assembles everything for the current mesh.
    void reinit(const FluidSpace<dim> &space);

    /// A = (alpha/dt) M + nu K and its preconditioner. Cheap to call with
    /// unchanged arguments (nothing is done).
    void set_momentum_coefficients(double alpha_over_dt, double nu);

    /// Semi-implicit elastic coupling: the step matrix A + theta dt/rho E
    /// couples the velocity components and changes every step; assembled
    /// by the projection scheme into `A_step`, then this sets up its
    /// preconditioner.
    void         prepare_step_matrix();
    /// GMRES + BoomerAMG on A_step (E is not symmetric for B != I).
    unsigned int solve_step_matrix(VectorType &x, const VectorType &b, double tolerance) const;

    /// Solves with CG + the stored preconditioner; returns iterations.
    unsigned int solve_momentum(VectorType &x, const VectorType &b, double tolerance) const;
    unsigned int solve_pressure_laplace(VectorType &x, const VectorType &b, double tolerance) const;
    unsigned int solve_pressure_mass(VectorType &x, const VectorType &b, double tolerance) const;

    /// load = D u, (div u, q_i): matrix-free with the matrix-free momentum
    /// operator, else with the assembled D.
    void apply_divergence(const VectorType &u, VectorType &load);

    MatrixType M, K, A, L, Mp, D;
    MatrixType A_step; // only with 'step_matrix'
    /// Allocate A_step (semi-implicit elastic coupling).
    bool step_matrix = false;
    VectorType flux_weights; // m_x
    VectorType unit_force;   // b_x
    double     momentum_alpha_over_dt = -1., momentum_nu = -1.;
    /// Jacobi instead of BoomerAMG for A (no set-up cost).
    bool jacobi_momentum = false;
    /// A applied matrix-free (M, K and A are then not assembled; CG with
    /// the Jacobi preconditioner of its matrix-free diagonal).
    bool matrix_free_momentum = false;
    MomentumOperator<dim> momentum_operator;
    DivergenceOperator<dim> divergence_operator;

  private:
    MPI_Comm                                             communicator;
    std::unique_ptr<PETScWrappers::PreconditionBoomerAMG> amg_momentum, amg_pressure, amg_step;
    std::unique_ptr<PETScWrappers::PreconditionJacobi>    jacobi_mass, jacobi_momentum_preconditioner;
  };
} // namespace Suspension::Fluid
