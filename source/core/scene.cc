#include <deal.II/base/function_parser.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/grid_tools.h>

#include <suspension/core/scene.h>

namespace Suspension
{
  template <int dim>
  std::unique_ptr<Function<dim>>
  make_function(const Parameters::FunctionExpression &expression,
                const unsigned int                    n_components)
  {
    auto f = std::make_unique<FunctionParser<dim>>(n_components);
    f->initialize(Parameters::variable_names(dim),
                  expression.expression,
                  expression.constant_map(),
                  /*time_dependent=*/true);
    return f;
  }

  template <int dim>
  Scene<dim>::Scene(const Parameters::All &parameters)
    : parameters(parameters)
  {
    const auto &bc = parameters.boundary_conditions;
    for (unsigned int d = 0; d < dim; ++d)
      if (bc.type[2 * d] == Parameters::BoundaryType::periodic)
        periodic.push_back(d);
    for (unsigned int f = 0; f < 2 * dim; ++f)
      if (bc.type[f] == Parameters::BoundaryType::no_slip)
        boundary_velocity[f] = std::make_unique<Functions::ZeroFunction<dim>>(dim);
      else if (bc.type[f] == Parameters::BoundaryType::velocity)
        boundary_velocity[f] = make_function<dim>(bc.velocity[f], dim);
    initial_velocity_function =
      make_function<dim>(parameters.initial_conditions.velocity, dim);
  }

  template <int dim>
  Point<dim> Scene<dim>::lower_corner() const
  {
    Point<dim> p;
    for (unsigned int d = 0; d < dim; ++d)
      p[d] = parameters.geometry.box_lower[d];
    return p;
  }

  template <int dim>
  Point<dim> Scene<dim>::upper_corner() const
  {
    Point<dim> p;
    for (unsigned int d = 0; d < dim; ++d)
      p[d] = parameters.geometry.box_upper[d];
    return p;
  }

  template <int dim>
  std::vector<std::pair<unsigned int, double>> Scene<dim>::no_slip_walls() const
  {
    std::vector<std::pair<unsigned int, double>> walls;
    for (unsigned int f = 0; f < 2 * dim; ++f)
      if (parameters.boundary_conditions.type[f] == Parameters::BoundaryType::no_slip)
        walls.emplace_back(f / 2, f % 2 == 0 ? lower_corner()[f / 2] : upper_corner()[f / 2]);
    return walls;
  }

  template <int dim>
  std::array<double, dim> Scene<dim>::periods() const
  {
    std::array<double, dim> lengths{};
    for (const unsigned int d : periodic)
      lengths[d] = upper_corner()[d] - lower_corner()[d];
    return lengths;
  }

  template <int dim>
  double Scene<dim>::volume() const
  {
    double v = 1.;
    for (unsigned int d = 0; d < dim; ++d)
      v *= upper_corner()[d] - lower_corner()[d];
    return v;
  }

  template <int dim>
  void
  Scene<dim>::create_coarse_mesh(parallel::distributed::Triangulation<dim> &tria) const
  {
    GridGenerator::subdivided_hyper_rectangle(tria,
                                              parameters.geometry.subdivisions,
                                              lower_corner(),
                                              upper_corner(),
                                              /*colorize=*/true);
    if (!periodic.empty())
      {
        std::vector<GridTools::PeriodicFacePair<
          typename parallel::distributed::Triangulation<dim>::cell_iterator>>
          pairs;
        for (const unsigned int d : periodic)
          GridTools::collect_periodic_faces(tria, 2 * d, 2 * d + 1, d, pairs);
        tria.add_periodicity(pairs);
      }
  }

  template <int dim>
  void
  Scene<dim>::create_mesh(parallel::distributed::Triangulation<dim> &tria) const
  {
    create_coarse_mesh(tria);
    tria.refine_global(parameters.mesh.global_refinements);

    if (!parameters.mesh.refinement_region.empty())
      {
        FunctionParser<dim> region(1);
        region.initialize(Parameters::variable_names(dim),
                          parameters.mesh.refinement_region,
                          {},
                          true);
        for (unsigned int r = 0; r < parameters.mesh.region_refinements; ++r)
          {
            for (const auto &cell : tria.active_cell_iterators())
              if (cell->is_locally_owned() && region.value(cell->center()) > 0)
                cell->set_refine_flag();
            tria.execute_coarsening_and_refinement();
          }
      }
  }

  template <int dim>
  const std::vector<unsigned int> &Scene<dim>::periodic_directions() const
  {
    return periodic;
  }

  template <int dim>
  std::map<types::boundary_id, const Function<dim> *>
  Scene<dim>::velocity_boundary_functions() const
  {
    std::map<types::boundary_id, const Function<dim> *> out;
    for (const auto &[id, f] : boundary_velocity)
      out[id] = f.get();
    return out;
  }

  template <int dim>
  std::vector<std::map<types::boundary_id, const Function<dim> *>>
  Scene<dim>::velocity_boundary_functions_by_priority() const
  {
    const auto &bc = parameters.boundary_conditions;
    std::vector<std::map<types::boundary_id, const Function<dim> *>> out(1);
    for (const auto &[id, f] : boundary_velocity)
      if (bc.type[id] == Parameters::BoundaryType::no_slip || bc.velocity[id].is_zero())
        out[0][id] = f.get();
    for (const auto &[id, f] : boundary_velocity)
      if (out[0].count(id) == 0)
        out.push_back({{id, f.get()}});
    return out;
  }

  template <int dim>
  bool Scene<dim>::has_inhomogeneous_velocity() const
  {
    const auto &bc = parameters.boundary_conditions;
    for (unsigned int f = 0; f < 2 * dim; ++f)
      if (bc.type[f] == Parameters::BoundaryType::velocity &&
          !bc.velocity[f].is_zero())
        return true;
    return false;
  }

  template <int dim>
  void Scene<dim>::set_time(const double time) const
  {
    for (const auto &[id, f] : boundary_velocity)
      f->set_time(time);
  }

  template <int dim>
  const Function<dim> &Scene<dim>::initial_velocity() const
  {
    return *initial_velocity_function;
  }

  template class Scene<2>;
  template class Scene<3>;
  template std::unique_ptr<Function<2>>
  make_function<2>(const Parameters::FunctionExpression &, unsigned int);
  template std::unique_ptr<Function<3>>
  make_function<3>(const Parameters::FunctionExpression &, unsigned int);
} // namespace Suspension
