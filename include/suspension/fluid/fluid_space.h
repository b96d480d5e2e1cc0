#pragma once

#include <deal.II/base/index_set.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/lac/affine_constraints.h>

#include <suspension/core/scene.h>

namespace Suspension::Fluid
{
  using namespace dealii;

  /**
   * The discrete spaces of the projection scheme on one mesh: continuous
   * Q_k velocity (dim components, one DoFHandler) and Q_{k-1} pressure,
   * their index sets and constraints.
   *
   * Constraints hold hanging nodes, periodicity and (for the velocity)
   * Dirichlet faces. The velocity constraints here are homogeneous: the
   * constant matrices are built with them; a step asks for inhomogeneous
   * ones at its new time. The pressure increment additionally pins one
   * degree of freedom, since it solves a pure Neumann problem.
   */
  template <int dim>
  class FluidSpace
  {
  public:
    FluidSpace(const parallel::distributed::Triangulation<dim> &tria,
               unsigned int velocity_degree,
               unsigned int pressure_degree);

    /// Distributes DoFs and builds constraints; call after every mesh change.
    void setup(const Scene<dim> &scene);

    /// Hanging nodes, periodicity and the scene's boundary velocity at the
    /// time the scene was set to.
    void make_velocity_constraints(const Scene<dim>          &scene,
                                   bool                       homogeneous,
                                   AffineConstraints<double> &constraints) const;

    /// Hanging nodes and periodicity only (for fields transferred to a
    /// new mesh, whose boundary values stay as they are).
    void make_continuity_constraints(const Scene<dim>          &scene,
                                     AffineConstraints<double> &constraints) const;

    MPI_Comm communicator() const;

    const parallel::distributed::Triangulation<dim> &triangulation;
    FESystem<dim>   fe_velocity;
    FE_Q<dim>       fe_pressure;
    DoFHandler<dim> dof_velocity;
    DoFHandler<dim> dof_pressure;
    QGauss<dim>     quadrature;

    IndexSet owned_velocity, relevant_velocity;
    IndexSet owned_pressure, relevant_pressure;

    AffineConstraints<double> velocity_constraints;  // homogeneous
    AffineConstraints<double> pressure_constraints;  // hanging + periodic
    AffineConstraints<double> increment_constraints; // ... + one pinned DoF

    /// Same cell seen through another DoFHandler on the same mesh.
    template <typename Iterator>
    static typename DoFHandler<dim>::active_cell_iterator
    cell_of(const Iterator &cell, const DoFHandler<dim> &dof_handler)
    {
      return typename DoFHandler<dim>::active_cell_iterator(
        &dof_handler.get_triangulation(), cell->level(), cell->index(), &dof_handler);
    }
  };
} // namespace Suspension::Fluid
