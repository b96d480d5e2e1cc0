#pragma once

#include <deal.II/grid/tria.h>

namespace Suspension
{
  using namespace dealii;

  /**
   * Calls `visit(neighbour)` for every active cell that shares a face with
   * the active `cell`: across interior, processor and periodic faces, and
   * on a face with hanging nodes each finer child behind it (2:1 balance).
   * Boundary faces that are not periodic have no neighbour. Stops early and
   * returns true as soon as `visit` returns true.
   *
   * Small and called per cell in hot loops, so it lives in the header.
   */
  template <int dim, typename Visitor>
  bool for_each_face_neighbour(const typename Triangulation<dim>::active_cell_iterator &cell,
                               const Visitor                                         &visit)
  {
    for (const unsigned int f : cell->face_indices())
      {
        const bool periodic = cell->has_periodic_neighbor(f);
        if (cell->at_boundary(f) && !periodic)
          continue;
        const auto neighbour = cell->neighbor_or_periodic_neighbor(f);
        if (neighbour->is_active())
          {
            if (visit(typename Triangulation<dim>::active_cell_iterator(neighbour)))
              return true;
            continue;
          }
        for (unsigned int sf = 0; sf < GeometryInfo<dim>::max_children_per_face; ++sf)
          {
            const typename Triangulation<dim>::active_cell_iterator child =
              periodic ? cell->periodic_neighbor_child_on_subface(f, sf) :
                         cell->neighbor_child_on_subface(f, sf);
            if (visit(child))
              return true;
          }
      }
    return false;
  }
} // namespace Suspension
