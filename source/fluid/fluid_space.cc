#include <deal.II/base/mpi.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/numerics/vector_tools.h>

#include <suspension/fluid/fluid_space.h>

namespace Suspension::Fluid
{
  template <int dim>
  FluidSpace<dim>::FluidSpace(
    const parallel::distributed::Triangulation<dim> &tria,
    const unsigned int                               velocity_degree,
    const unsigned int                               pressure_degree)
    : triangulation(tria)
    , fe_velocity(FE_Q<dim>(velocity_degree), dim)
    , fe_pressure(pressure_degree)
    , dof_velocity(tria)
    , dof_pressure(tria)
    , quadrature(velocity_degree + 1)
  {}

  template <int dim>
  MPI_Comm FluidSpace<dim>::communicator() const
  {
    return triangulation.get_communicator();
  }

  template <int dim>
  void FluidSpace<dim>::make_continuity_constraints(const Scene<dim>          &scene,
                                                    AffineConstraints<double> &constraints) const
  {
    constraints.clear();
    constraints.reinit(relevant_velocity);
    DoFTools::make_hanging_node_constraints(dof_velocity, constraints);
    for (const unsigned int d : scene.periodic_directions())
      DoFTools::make_periodicity_constraints(dof_velocity, 2 * d, 2 * d + 1, d, constraints);
    constraints.close();
  }

  template <int dim>
  void FluidSpace<dim>::make_velocity_constraints(
    const Scene<dim>          &scene,
    const bool                 homogeneous,
    AffineConstraints<double> &constraints) const
  {
    constraints.clear();
    constraints.reinit(relevant_velocity);
    DoFTools::make_hanging_node_constraints(dof_velocity, constraints);
    for (const unsigned int d : scene.periodic_directions())
      DoFTools::make_periodicity_constraints(dof_velocity, 2 * d, 2 * d + 1, d, constraints);
    const auto functions = scene.velocity_boundary_functions();
    if (homogeneous)
      {
        const Functions::ZeroFunction<dim> zero(dim);
        std::map<types::boundary_id, const Function<dim> *> zeros;
        for (const auto &[id, f] : functions)
          zeros[id] = &zero;
        VectorTools::interpolate_boundary_values(dof_velocity, zeros, constraints);
      }
    else
      // a DoF already constrained keeps its value: the first group wins
      for (const auto &group : scene.velocity_boundary_functions_by_priority())
        VectorTools::interpolate_boundary_values(dof_velocity, group, constraints);
    constraints.close();
  }

  template <int dim>
  void FluidSpace<dim>::setup(const Scene<dim> &scene)
  {
    dof_velocity.distribute_dofs(fe_velocity);
    dof_pressure.distribute_dofs(fe_pressure);

    owned_velocity = dof_velocity.locally_owned_dofs();
    owned_pressure = dof_pressure.locally_owned_dofs();
    DoFTools::extract_locally_relevant_dofs(dof_velocity, relevant_velocity);
    DoFTools::extract_locally_relevant_dofs(dof_pressure, relevant_pressure);

    make_velocity_constraints(scene, true, velocity_constraints);

    pressure_constraints.clear();
    pressure_constraints.reinit(relevant_pressure);
    DoFTools::make_hanging_node_constraints(dof_pressure, pressure_constraints);
    for (const unsigned int d : scene.periodic_directions())
      DoFTools::make_periodicity_constraints(dof_pressure, 2 * d, 2 * d + 1, d, pressure_constraints);
    pressure_constraints.close();

    // The increment solves a Neumann problem, defined up to a constant: pin
    // the lowest-numbered unconstrained DoF. Every rank that sees it must
    // know, or its rows would be assembled inconsistently.
    types::global_dof_index first = numbers::invalid_dof_index;
    for (const auto i : owned_pressure)
      if (!pressure_constraints.is_constrained(i))
        {
          first = i;
          break;
        }
    const types::global_dof_index pinned =
      Utilities::MPI::min(first, communicator());
    increment_constraints.clear();
    increment_constraints.reinit(relevant_pressure);
    increment_constraints.merge(pressure_constraints);
    if (relevant_pressure.is_element(pinned))
      increment_constraints.add_line(pinned);
    increment_constraints.close();
  }

  template class FluidSpace<2>;
  template class FluidSpace<3>;
} // namespace Suspension::Fluid
