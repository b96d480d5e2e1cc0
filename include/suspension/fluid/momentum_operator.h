#pragma once

#include <deal.II/lac/la_parallel_vector.h>
#include <deal.II/matrix_free/matrix_free.h>

#include <deal.II/lac/generic_linear_algebra.h>

#include <suspension/fluid/fluid_space.h>

#include <utility>
#include <vector>

namespace Suspension::Fluid
{
  /**
   * The momentum predictor's operator A = (alpha/dt) M + nu K without an
   * assembled matrix (issue 14, item 1): applied cell by cell with
   * FEEvaluation (sum factorisation), the hanging-node, periodic and
   * Dirichlet constraints of the velocity resolved on the fly; CG (GMRES
   * with semi-implicit convection, set_advection) with the
   * Jacobi preconditioner of its diagonal, computed matrix-free: the
   * diagonals of M and of K once per mesh, combined on the fly in every
   * application of the preconditioner, so that a change of dt costs
   * nothing (with the adaptive time step dt changes every step);
   * a mesh change only the MatrixFree data and those two diagonals. The
   * vectors of the rest of the fluid stay PETSc's: a solve copies the
   * right-hand side in and the solution out (locally owned entries; the
   * same DoF numbering).
   */
  using VectorType = LinearAlgebraPETSc::MPI::Vector;

  /// The locally owned entries of a PETSc vector into a deal.II one (or
  /// back) on the same DoFs: contiguous and in the same order in both
  /// (the DoFHandler's locally owned range; MatrixFree does not renumber).
  void copy_locally_owned(const VectorType &from, LinearAlgebra::distributed::Vector<double> &to);
  void copy_locally_owned(const LinearAlgebra::distributed::Vector<double> &from, VectorType &to);

  /// c_0 v_0 + c_1 v_1 + ...: a field formed from the time levels where it
  /// is needed instead of being stored (issue 14, item 4).
  using Combination = std::vector<std::pair<double, const VectorType *>>;

  /// The locally owned entries of `terms` into `to`, computed by PETSc on
  /// a view of `to`'s memory (VecCopy, VecScale, VecAXPY: the same
  /// arithmetic as the stored PETSc copies this replaces).
  void form_locally_owned(const Combination &terms, LinearAlgebra::distributed::Vector<double> &to);
  /// the same into a PETSc vector with `to`'s layout
  void form_locally_owned(const Combination &terms, VectorType &to);

  template <int dim>
  class MomentumOperator
  {
  public:
    using Vector = LinearAlgebra::distributed::Vector<double>;

    /// After every mesh change (the space rebuilt).
    void reinit(const FluidSpace<dim> &space);

    /// The coefficients (alpha/dt, nu); the Jacobi preconditioner follows
    /// them without any set-up.
    void set_coefficients(double mass, double viscosity);

    /// Semi-implicit convection (issue 14, item 5): until
    /// clear_advection(), the operator is A u + (u*.grad) u + div(u*) u / 2
    /// with u* = `terms` (the extrapolated velocity), whose values and
    /// half divergence are stored at the quadrature points here, and
    /// solve() uses GMRES. The skew-symmetric form leaves the diagonal, and
    /// so the Jacobi preconditioner, as it is: for a basis function v,
    /// (u*.grad v, v) + (div(u*) v / 2, v) = (div(u* v^2), 1) / 2 = 0.
    void set_advection(const Combination &terms);
    void clear_advection();
    bool advecting() const { return advection_active; }
    /// u* and div(u*) / 2 at point q of cell batch `cell` (while advecting)
    const Tensor<1, dim, VectorizedArray<double>> &advection_value(const unsigned int cell,
                                                                   const unsigned int q) const
    {
      return advection_values[std::size_t(cell) * n_advection_points + q];
    }
    const VectorizedArray<double> &advection_half_div(const unsigned int cell,
                                                      const unsigned int q) const
    {
      return advection_half_divergence[std::size_t(cell) * n_advection_points + q];
    }

    /// dst = A src on the unconstrained DoFs; constrained ones copied.
    void vmult(Vector &dst, const Vector &src) const;

    /// Solves A x = b to `tolerance` relative to |b| with the constrained
    /// entries of b and of the initial guess x set to zero (the caller
    /// distributes the constraints afterwards, as for the assembled A).
    /// Returns the CG (GMRES while advecting) iterations.
    unsigned int solve(VectorType &x, const VectorType &b, double tolerance) const;

    /// The two work vectors of a solve (velocity DoFs), free between
    /// solves: the right-hand side and the divergence borrow them instead
    /// of holding velocity vectors of their own (issue 14, item 4).
    Vector &work_vector(const unsigned int i) const { return i == 0 ? x_local : b_local; }

    /// Bytes of the MatrixFree data and of the vectors held here.
    std::size_t matrix_free_memory() const { return matrix_free.memory_consumption(); }
    std::size_t vector_memory() const;

    /// The cell data, shared with the matrix-free right-hand side: the
    /// velocity DoFs (homogeneous constraints) and the pressure DoFs, one
    /// Gauss quadrature of velocity degree + 1 points per direction.
    const MatrixFree<dim, double> &get_matrix_free() const { return matrix_free; }
    unsigned int velocity_degree() const { return degree; }
    static constexpr unsigned int velocity_index = 0, pressure_index = 1;

  private:
    template <int degree, int n_q>
    void apply_cells(Vector &dst, const Vector &src) const;
    template <int degree, int n_q>
    void evaluate_advection(const Vector &u_star);
    /// diag(mass M + viscosity K) into `diagonal`
    template <int degree, int n_q>
    void compute_diagonal(Vector &diagonal, double mass, double viscosity) const;

    /// Jacobi: dst = src / (mass diag M + viscosity diag K), formed on the
    /// fly from the two diagonals (zero at constrained DoFs, which are left
    /// as they are) instead of a third stored vector.
    struct InverseDiagonal
    {
      const MomentumOperator *op;
      void vmult(Vector &dst, const Vector &src) const;
    };

    MatrixFree<dim, double> matrix_free;
    unsigned int            degree = 2;
    double                  mass = -1., viscosity = -1.;
    Vector                  mass_diagonal, viscous_diagonal; // of M and K
    std::vector<unsigned int> constrained; // local indices, all constrained DoFs
    mutable Vector          x_local, b_local;
    /// u* and div(u*) / 2 at the quadrature points of every cell batch
    /// (index batch * points per cell + q); empty without advection
    AlignedVector<Tensor<1, dim, VectorizedArray<double>>> advection_values;
    AlignedVector<VectorizedArray<double>>                 advection_half_divergence;
    unsigned int                                           n_advection_points = 0;
    /// set between set_advection() and clear_advection(); the arrays are
    /// kept (not reallocated every step) and freed only by reinit()
    bool advection_active = false;
  };
} // namespace Suspension::Fluid
