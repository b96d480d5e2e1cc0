#include <deal.II/base/mpi.h>

#include <suspension/mesh/resolution_check.h>

#include <iomanip>
#include <sstream>

namespace Suspension
{
  template <int dim>
  std::vector<std::string>
  resolution_warnings(const Parameters::All                           &parameters,
                      const parallel::distributed::Triangulation<dim> &triangulation,
                      const double                                     finest_cell_size)
  {
    constexpr double         fewest_cells_per_diameter = 4.;
    std::vector<std::string> warnings;
    if (parameters.solid.enabled() && !parameters.solid.particles.empty())
      {
        double smallest_radius = parameters.solid.particles.front()[dim];
        for (const auto &p : parameters.solid.particles)
          smallest_radius = std::min(smallest_radius, p[dim]);
        const double cells = 2. * smallest_radius / finest_cell_size;
        if (cells < fewest_cells_per_diameter)
          {
            std::ostringstream w;
            w << "warning: entry '"
              << (parameters.solid.seeded ? "Solid/Seeding/Radius" : "Solid/Particles")
              << "': a particle of radius " << smallest_radius
              << " spans " << std::setprecision(2) << cells
              << " cells per diameter on the finest mesh (below " << fewest_cells_per_diameter
              << ", it is mostly interface); refine the mesh ('Mesh/Global refinements' or "
                 "'Mesh refinement/Maximum level')";
            warnings.push_back(w.str());
          }
      }
    if (parameters.statistics.enabled)
      {
        // the coarsest cell height across the channel (last coordinate)
        double tallest = 0.;
        for (const auto &cell : triangulation.active_cell_iterators())
          if (cell->is_locally_owned())
            tallest = std::max(tallest, cell->extent_in_direction(dim - 1));
        tallest = Utilities::MPI::max(tallest, triangulation.get_communicator());
        const unsigned int rows  = parameters.fluid_solver.velocity_degree + 1; // Gauss points
        const double       width = 2. * parameters.geometry.half_height / parameters.statistics.n_bins;
        if (width < tallest / rows)
          {
            std::ostringstream w;
            w << "warning: entry 'Statistics/Number of bins': " << parameters.statistics.n_bins
              << " bins of width " << std::setprecision(3) << width
              << " are thinner than the rows of quadrature points of the coarsest cells across "
                 "the channel (height "
              << tallest << ", " << rows << " rows): a bin may hold no point; use at most "
              << static_cast<unsigned int>(2. * parameters.geometry.half_height * rows / tallest)
              << " bins";
            warnings.push_back(w.str());
          }
      }
    return warnings;
  }

  template std::vector<std::string>
  resolution_warnings(const Parameters::All &, const parallel::distributed::Triangulation<2> &,
                      double);
  template std::vector<std::string>
  resolution_warnings(const Parameters::All &, const parallel::distributed::Triangulation<3> &,
                      double);
} // namespace Suspension
