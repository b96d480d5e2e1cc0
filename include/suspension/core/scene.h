#pragma once

#include <deal.II/base/function.h>
#include <deal.II/distributed/tria.h>

#include <suspension/core/parameters.h>

#include <array>
#include <map>
#include <memory>
#include <vector>

namespace Suspension
{
  using namespace dealii;

  /**
   * The scene: geometry, boundary identifiers, periodicity and the data
   * given on the boundary and at t = 0, all as the .prm file describes them.
   *
   * The domain is a rectangle/box whose faces carry boundary ids
   * 0 = x-, 1 = x+, 2 = y-, 3 = y+, 4 = z-, 5 = z+. A channel is a box with
   * walls at +-h in the last coordinate and periodic faces in the others.
   * Solvers ask the scene which faces are periodic and which carry a
   * velocity; they never look at the parameters themselves.
   */
  template <int dim>
  class Scene
  {
  public:
    explicit Scene(const Parameters::All &parameters);

    /// Base mesh, periodicity, global refinement and the hand-made
    /// refinement region of the 'Mesh' subsection.
    void create_mesh(parallel::distributed::Triangulation<dim> &tria) const;

    /// Only the base mesh and its periodicity: what Triangulation::load()
    /// of a checkpoint expects to find.
    void create_coarse_mesh(parallel::distributed::Triangulation<dim> &tria) const;

    /// Directions d whose faces 2d and 2d+1 are identified.
    const std::vector<unsigned int> &periodic_directions() const;

    /// Velocity on every non-periodic face (zero on no-slip walls),
    /// evaluated at the time set with set_time().
    std::map<types::boundary_id, const Function<dim> *>
    velocity_boundary_functions() const;

    /// The faces of velocity_boundary_functions() in the order in which
    /// their values are imposed: walls at rest (no-slip, or a velocity
    /// expression that is zero) first, so that a node shared by a wall at
    /// rest and a moving face (the corners of a lid-driven cavity) is at
    /// rest; among moving faces, by face id.
    std::vector<std::map<types::boundary_id, const Function<dim> *>>
    velocity_boundary_functions_by_priority() const;

    /// True if some face has a non-zero prescribed velocity.
    bool has_inhomogeneous_velocity() const;

    void set_time(double time) const;

    /// Initial velocity (dim components).
    const Function<dim> &initial_velocity() const;

    /// Domain measure |Omega|.
    double volume() const;

    /// The no-slip faces as (direction, coordinate of the plane).
    std::vector<std::pair<unsigned int, double>> no_slip_walls() const;

    /// Length of each periodic direction, 0 for the others.
    std::array<double, dim> periods() const;

    Point<dim> lower_corner() const;
    Point<dim> upper_corner() const;

  private:
    const Parameters::All                              &parameters;
    std::vector<unsigned int>                           periodic;
    std::map<types::boundary_id, std::unique_ptr<Function<dim>>> boundary_velocity;
    std::unique_ptr<Function<dim>>                      initial_velocity_function;
  };

  /// A deal.II FunctionParser for a parameter expression, variables
  /// x, y[, z], t.
  template <int dim>
  std::unique_ptr<Function<dim>>
  make_function(const Parameters::FunctionExpression &expression,
                unsigned int                          n_components);
} // namespace Suspension
