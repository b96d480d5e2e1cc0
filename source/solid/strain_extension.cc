#include <deal.II/base/geometry_info.h>
#include <deal.II/fe/fe.h>

#include <suspension/solid/strain_extension.h>

#include <array>

namespace Suspension::Solid
{
  template <int dim>
  void extend_strain_into_fluid(const DoFHandler<dim> &dof_handler,
                                const double           solid_level,
                                const double           fluid_level,
                                const unsigned int     layers,
                                VectorType            &solution,
                                VectorType            &relevant)
  {
    constexpr unsigned int    n_B     = dim * (dim + 1) / 2;
    const FiniteElement<dim> &fe      = dof_handler.get_fe();
    const unsigned int        n_nodes = fe.base_element(0).n_dofs_per_cell();
    const auto identity = [](const unsigned int c) { return c <= dim ? 1. : 0.; };
    using Mean          = std::array<double, n_B>;

    // the mean of B over the solid nodes of a cell, or else over its fluid
    // nodes if they were extended (B != I); false if neither
    const auto source_mean = [&](const std::vector<types::global_dof_index> &dofs,
                                 const VectorType &v, Mean &mean) {
      const auto at = [&](const unsigned int c, const unsigned int j) {
        return v(dofs[fe.component_to_system_index(c, j)]);
      };
      for (const bool solid : {true, false})
        {
          mean.fill(0.);
          unsigned int n = 0;
          bool         extended = false;
          for (unsigned int j = 0; j < n_nodes; ++j)
            if (solid ? at(0, j) >= solid_level : at(0, j) <= fluid_level)
              {
                ++n;
                for (unsigned int c = 1; c <= n_B; ++c)
                  {
                    mean[c - 1] += at(c, j);
                    extended = extended || at(c, j) != identity(c);
                  }
              }
          if (n > 0 && (solid || extended))
            {
              for (auto &m : mean)
                m /= n;
              return true;
            }
        }
      return false;
    };
    // sets B at the fluid nodes of a cell
    const auto set_fluid_nodes = [&](const std::vector<types::global_dof_index> &dofs,
                                     const Mean *mean) {
      for (unsigned int j = 0; j < n_nodes; ++j)
        if (solution(dofs[fe.component_to_system_index(0, j)]) <= fluid_level)
          for (unsigned int c = 1; c <= n_B; ++c)
            solution(dofs[fe.component_to_system_index(c, j)]) =
              mean != nullptr ? (*mean)[c - 1] : identity(c);
    };
    const auto has_solid_nodes = [&](const std::vector<types::global_dof_index> &dofs,
                                     const VectorType &v) {
      for (unsigned int j = 0; j < n_nodes; ++j)
        if (v(dofs[fe.component_to_system_index(0, j)]) >= solid_level)
          return true;
      return false;
    };

    // Ring 0: the fluid nodes of a cell with solid nodes take their mean,
    // all other fluid nodes I.
    std::vector<types::global_dof_index> dofs(fe.n_dofs_per_cell()), neighbour_dofs(dofs.size());
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          cell->get_dof_indices(dofs);
          Mean mean;
          const bool solid = has_solid_nodes(dofs, solution) && source_mean(dofs, solution, mean);
          set_fluid_nodes(dofs, solid ? &mean : nullptr);
        }

    // Rings 1 ... layers: a cell without solid nodes whose fluid nodes hold
    // I takes the mean of its neighbours that have solid nodes or were
    // extended in the ring before.
    for (unsigned int ring = 0; ring < layers; ++ring)
      {
        relevant.copy_locally_owned_data_from(solution);
        relevant.update_ghost_values();
        for (const auto &cell : dof_handler.active_cell_iterators())
          if (cell->is_locally_owned())
            {
              cell->get_dof_indices(dofs);
              Mean mean;
              if (has_solid_nodes(dofs, relevant) || source_mean(dofs, relevant, mean))
                continue;
              Mean         sum{};
              unsigned int n_sources = 0;
              const auto   visit     = [&](const auto &neighbour) {
                if (neighbour->is_artificial())
                  return;
                neighbour->get_dof_indices(neighbour_dofs);
                if (source_mean(neighbour_dofs, relevant, mean))
                  {
                    ++n_sources;
                    for (unsigned int c = 0; c < n_B; ++c)
                      sum[c] += mean[c];
                  }
              };
              for (const unsigned int f : cell->face_indices())
                {
                  const bool periodic = cell->has_periodic_neighbor(f);
                  if (cell->at_boundary(f) && !periodic)
                    continue;
                  const auto neighbour = periodic ? cell->periodic_neighbor(f) : cell->neighbor(f);
                  if (!neighbour->has_children())
                    visit(neighbour);
                  else
                    for (unsigned int s = 0; s < GeometryInfo<dim>::max_children_per_face; ++s)
                      visit(periodic ? cell->periodic_neighbor_child_on_subface(f, s) :
                                       cell->neighbor_child_on_subface(f, s));
                }
              if (n_sources == 0)
                continue;
              for (auto &m : sum)
                m /= n_sources;
              set_fluid_nodes(dofs, &sum);
            }
      }
  }

  template void extend_strain_into_fluid(const DoFHandler<2> &, double, double, unsigned int,
                                         VectorType &, VectorType &);
  template void extend_strain_into_fluid(const DoFHandler<3> &, double, double, unsigned int,
                                         VectorType &, VectorType &);
} // namespace Suspension::Solid
