#pragma once

#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/la_parallel_vector.h>

#include <vector>

namespace Suspension::Solid
{
  using namespace dealii;

  /**
   * Algebraic interface sharpening (Aliabadi & Tezduyar 2000): every DG
   * node value of phi is mapped by
   *
   *   phi' = c^(1-a) phi^a                  (phi <  c),
   *   phi' = 1 - (1-c)^(1-a) (1-phi)^a      (phi >= c),
   *
   * a > 1 the sharpness, c (about 1/2) found by bisection so that the
   * integral of phi is unchanged; the remainder of the bisection is spread
   * over the interface nodes in proportion to phi (1 - phi), so that the
   * integral is kept to round-off. The map fixes 0, c and 1 and keeps
   * 0 <= phi <= 1: it steepens the profile about its c level set without
   * moving it, against the widening of the diffuse interface by the DG
   * transport (doc/method.md, "Where the solid ends").
   *
   * The integral is sum_i w_i phi_i with w_i the integral of the basis
   * function of DoF i, computed once per mesh: one bisection step is a
   * pass over the locally owned phi DoFs and one reduction.
   */
  template <int dim>
  class InterfaceSharpening
  {
  public:
    using VectorType = LinearAlgebra::distributed::Vector<double>;

    /// Basis integrals of the phi component (component 0) of dof_handler.
    void reinit(const DoFHandler<dim> &dof_handler);

    /// Sharpens phi in `solution` with sharpness a; returns c.
    double apply(VectorType &solution, double sharpness) const;

  private:
    MPI_Comm            communicator = MPI_COMM_SELF;
    std::vector<unsigned int> phi_dofs; // local indices of the owned phi DoFs
    std::vector<double>       weights;  // their basis integrals
  };
} // namespace Suspension::Solid
