#pragma once

#include <deal.II/base/point.h>
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/base/tensor.h>
#include <deal.II/grid/tria.h>

#include <vector>

namespace Suspension::Fluid
{
  using namespace dealii;

  /**
   * The narrow interface through which anything that pushes on the fluid
   * (a body force, the hyperelastic stress G phi (B - I) of the solid, the
   * contact force between particles) enters the momentum equation
   *
   *   rho (du/dt + u.grad u) = -grad p + mu lap u + f + div tau,
   *
   * assembled as (f, v) - (tau, grad v). The fluid solver calls add() on
   * every locally owned cell with the quadrature points it integrates on;
   * a source evaluates its own fields there (on its own DoFHandler over the
   * same triangulation). The fluid code knows nothing else about it.
   */
  template <int dim>
  class MomentumSource
  {
  public:
    virtual ~MomentumSource() = default;

    /// Adds force per unit volume and stress at the points of `cell`
    /// (`points` in real space, `unit_points` on the reference cell).
    virtual void add(const typename Triangulation<dim>::active_cell_iterator &cell,
                     const std::vector<Point<dim>> &points,
                     const std::vector<Point<dim>> &unit_points,
                     double                          time,
                     std::vector<Tensor<1, dim>>          &force,
                     std::vector<SymmetricTensor<2, dim>> &stress) const = 0;

    /// False if add() only ever adds forces (saves the stress term).
    virtual bool has_stress() const
    {
      return true;
    }

    /// For a semi-implicit coupling: the stress increment of the source
    /// under a velocity gradient L held for a time dt is
    /// dt modulus[q] (L B[q] + B[q] L^T) at the points of `cell`. Returns
    /// false (and fills nothing) for sources without elastic stiffness.
    virtual bool elastic_stiffness(const typename Triangulation<dim>::active_cell_iterator &cell,
                                   const std::vector<Point<dim>> &unit_points,
                                   std::vector<double>                  &modulus,
                                   std::vector<SymmetricTensor<2, dim>> &B) const
    {
      (void)cell;
      (void)unit_points;
      (void)modulus;
      (void)B;
      return false;
    }
  };
} // namespace Suspension::Fluid
