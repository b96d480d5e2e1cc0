#include <deal.II/base/geometry_info.h>
#include <deal.II/fe/fe.h>

#include <suspension/solid/strain_extension.h>

#include <array>

namespace Suspension::Solid
{
  template <int dim>
  void extend_strain_into_fluid(const DoFHandler<dim> &dof_handler,
                                const double           solid_level,
                                const unsigned int     layers,
                                VectorType            &solution,
                                VectorType            &relevant)
  {
    constexpr unsigned int    n_B     = dim * (dim + 1) / 2;
    const FiniteElement<dim> &fe      = dof_handler.get_fe();
    const unsigned int        n_nodes = fe.base_element(0).n_dofs_per_cell();
    const auto identity = [](const unsigned int c) { return c <= dim ? 1. : 0.; };
    using Mean          = std::array<double, n_B>;

    const auto kept = [solid_level](const double phi) { return phi >= solid_level; };
    // Ring 0: in every cell, the nodes where B is not kept take the mean of
    // the kept ones, or I if there are none.
    std::vector<types::global_dof_index> dofs(fe.n_dofs_per_cell());
    const auto at = [&](const unsigned int c, const unsigned int j) {
      return dofs[fe.component_to_system_index(c, j)];
    };
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          cell->get_dof_indices(dofs);
          Mean         mean{};
          unsigned int n_kept = 0;
          for (unsigned int j = 0; j < n_nodes; ++j)
            if (kept(solution(at(0, j))))
              {
                ++n_kept;
                for (unsigned int c = 1; c <= n_B; ++c)
                  mean[c - 1] += solution(at(c, j));
              }
          if (n_kept == n_nodes)
            continue;
          for (unsigned int j = 0; j < n_nodes; ++j)
            if (!kept(solution(at(0, j))))
              for (unsigned int c = 1; c <= n_B; ++c)
                solution(at(c, j)) = n_kept > 0 ? mean[c - 1] / n_kept : identity(c);
        }

    // Rings 1 ... layers: a cell without kept nodes whose B is I takes the
    // mean B of its neighbours that have kept nodes or B != I (the ring
    // before).
    std::vector<types::global_dof_index> neighbour_dofs(fe.n_dofs_per_cell());
    const auto source_mean = [&](const auto &cell, Mean &mean) {
      cell->get_dof_indices(neighbour_dofs);
      bool source = false;
      mean.fill(0.);
      for (unsigned int j = 0; j < n_nodes; ++j)
        {
          source = source || kept(relevant(neighbour_dofs[fe.component_to_system_index(0, j)]));
          for (unsigned int c = 1; c <= n_B; ++c)
            {
              const double b = relevant(neighbour_dofs[fe.component_to_system_index(c, j)]);
              source         = source || b != identity(c);
              mean[c - 1] += b / n_nodes;
            }
        }
      return source;
    };
    for (unsigned int ring = 0; ring < layers; ++ring)
      {
        relevant.copy_locally_owned_data_from(solution);
        relevant.update_ghost_values();
        for (const auto &cell : dof_handler.active_cell_iterators())
          if (cell->is_locally_owned())
            {
              Mean mean;
              if (source_mean(cell, mean))
                continue;
              Mean         sum{};
              unsigned int n_sources = 0;
              const auto   visit     = [&](const auto &neighbour) {
                if (!neighbour->is_artificial() && source_mean(neighbour, mean))
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
              cell->get_dof_indices(dofs);
              for (unsigned int j = 0; j < n_nodes; ++j)
                for (unsigned int c = 1; c <= n_B; ++c)
                  solution(at(c, j)) = sum[c - 1] / n_sources;
            }
      }
  }

  template void extend_strain_into_fluid(const DoFHandler<2> &, double, unsigned int, VectorType &,
                                         VectorType &);
  template void extend_strain_into_fluid(const DoFHandler<3> &, double, unsigned int, VectorType &,
                                         VectorType &);
} // namespace Suspension::Solid
