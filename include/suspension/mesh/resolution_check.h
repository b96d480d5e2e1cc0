#pragma once

#include <deal.II/distributed/tria.h>

#include <suspension/core/parameters.h>

#include <string>
#include <vector>

namespace Suspension
{
  using namespace dealii;

  /**
   * What the mesh cannot resolve, as warnings (the run goes on): a particle
   * with fewer than 4 finest cells per diameter (its interface spans about
   * two cells, so such a particle is mostly interface), and statistics bins
   * thinner than the rows of quadrature points of the coarsest cells across
   * the channel (such a bin may hold no point, and its profile value is
   * then missing). `finest_cell_size` is the cell size where the interface
   * is refined to (MeshAdaptor::finest_cell_size()). Same on every rank.
   */
  template <int dim>
  std::vector<std::string>
  resolution_warnings(const Parameters::All                           &parameters,
                      const parallel::distributed::Triangulation<dim> &triangulation,
                      double                                           finest_cell_size);
} // namespace Suspension
