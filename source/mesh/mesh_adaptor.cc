#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/distributed/grid_refinement.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/numerics/error_estimator.h>

#include <suspension/core/scene.h>
#include <suspension/mesh/face_neighbours.h>
#include <suspension/mesh/mesh_adaptor.h>

#include <cmath>
#include <iomanip>
#include <istream>
#include <ostream>
#include <optional>

namespace Suspension
{
  template <int dim>
  MeshAdaptor<dim>::MeshAdaptor(const Parameters::All                     &parameters,
                                parallel::distributed::Triangulation<dim> &triangulation)
    : settings(parameters.mesh_refinement)
    , triangulation(triangulation)
  {
    if (!settings.region.empty())
      region = make_function<dim>({settings.region, ""}, 1);
  }

  template <int dim>
  double MeshAdaptor<dim>::finest_cell_size() const
  {
    double h = std::numeric_limits<double>::max();
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          double size = cell->minimum_vertex_distance();
          if (settings.enabled && cell->level() < static_cast<int>(settings.maximum_level))
            size /= std::pow(2., settings.maximum_level - cell->level());
          h = std::min(h, size);
        }
    return Utilities::MPI::min(h, triangulation.get_communicator());
  }

  template <int dim>
  bool MeshAdaptor<dim>::due(const double distance_moved, const MeshLevels &levels)
  {
    if (!settings.enabled)
      return false;
    ++steps_since;
    distance_since += distance_moved;
    const bool now =
      settings.interval > 0 ?
        steps_since >= settings.interval :
        (distance_since >= settings.buffer_fraction * settings.buffer_cells * finest_cell_size() ||
         levels.interface_near_coarse_cells);
    if (now)
      {
        steps_since    = 0;
        distance_since = 0.;
      }
    return now;
  }

  template <int dim>
  void MeshAdaptor<dim>::dilate(std::vector<unsigned char> &band, const unsigned int layers) const
  {
    using Cell = typename Triangulation<dim>::active_cell_iterator;
    const auto marked_neighbour = [&](const Cell &cell) {
      return for_each_face_neighbour<dim>(
        cell, [&](const Cell &neighbour) { return band[neighbour->active_cell_index()] != 0; });
    };

    for (unsigned int layer = 0; layer < layers; ++layer)
      {
        GridTools::exchange_cell_data_to_ghosts<unsigned char, Triangulation<dim>>(
          triangulation,
          [&](const Cell &cell) -> std::optional<unsigned char> {
            return band[cell->active_cell_index()];
          },
          [&](const Cell &cell, const unsigned char &value) {
            band[cell->active_cell_index()] = value;
          });
        std::vector<unsigned char> next = band;
        for (const auto &cell : triangulation.active_cell_iterators())
          if (cell->is_locally_owned() && !band[cell->active_cell_index()] &&
              marked_neighbour(cell))
            next[cell->active_cell_index()] = 1;
        band.swap(next);
      }
  }

  template <int dim>
  bool MeshAdaptor<dim>::flag(const Solid::SolidPhase<dim> *solid,
                              const Fluid::FluidSpace<dim>  &space,
                              const Fluid::VectorType       *velocity,
                              const double                   time)
  {
    const unsigned int        n = triangulation.n_active_cells();
    std::vector<unsigned int> target(n, settings.minimum_level);

    if (solid)
      {
        const auto phase = solid->classify_cells(settings.interface_threshold);
        std::vector<unsigned char> band(n, 0);
        for (unsigned int i = 0; i < n; ++i)
          band[i] = phase[i] == Solid::interface_cell;
        dilate(band, settings.buffer_cells);
        for (unsigned int i = 0; i < n; ++i)
          {
            if (band[i])
              target[i] = settings.maximum_level;
            else if (phase[i] == Solid::solid_cell)
              target[i] = std::max(target[i], settings.solid_level);
          }
      }

    if (region)
      region->set_time(time);
    if (region)
      for (const auto &cell : triangulation.active_cell_iterators())
        if (cell->is_locally_owned() && region->value(cell->center()) > 0)
          target[cell->active_cell_index()] =
            std::max(target[cell->active_cell_index()], settings.region_level);

    if (velocity != nullptr && settings.refine_fraction > 0)
      {
        Vector<float> estimate(n);
        KellyErrorEstimator<dim>::estimate(space.dof_velocity,
                                           QGauss<dim - 1>(space.fe_velocity.degree + 1),
                                           {},
                                           *velocity,
                                           estimate);
        parallel::distributed::GridRefinement::refine_and_coarsen_fixed_fraction(
          triangulation, estimate, settings.refine_fraction, settings.coarsen_fraction);
        for (const auto &cell : triangulation.active_cell_iterators())
          if (cell->is_locally_owned())
            {
              auto &t = target[cell->active_cell_index()];
              if (cell->refine_flag_set())
                t = std::max<unsigned int>(t, cell->level() + 1);
              else if (!cell->coarsen_flag_set())
                t = std::max<unsigned int>(t, cell->level());
              cell->clear_refine_flag();
              cell->clear_coarsen_flag();
            }
      }

    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          const unsigned int t = std::clamp(target[cell->active_cell_index()],
                                            settings.minimum_level, settings.maximum_level);
          const unsigned int level = cell->level();
          cell->clear_refine_flag();
          cell->clear_coarsen_flag();
          if (level < t)
            cell->set_refine_flag();
          else if (level > t)
            cell->set_coarsen_flag();
        }
    // p4est's 2:1 balance may add flags on one side only: agree again
    for (unsigned int pass = 0; pass < 3; ++pass)
      {
        keep_periodic_faces_conforming();
        triangulation.prepare_coarsening_and_refinement();
      }

    unsigned int flagged = 0;
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned() && (cell->refine_flag_set() || cell->coarsen_flag_set()))
        ++flagged;
    return Utilities::MPI::sum(flagged, triangulation.get_communicator()) > 0;
  }

  template <int dim>
  void MeshAdaptor<dim>::keep_periodic_faces_conforming()
  {
    // Two cells facing each other across a periodic boundary move together:
    // refine if the other side is finer or will refine, coarsen only if it
    // coarsens too. The other side is often another rank's (the periodic
    // faces of a Z-order partition lie on different ranks), so the flags
    // are first copied to the ghost layer, which holds periodic neighbours.
    // Whatever remains is left to flag_periodic_hanging_faces().
    using Cell = typename Triangulation<dim>::active_cell_iterator;
    enum : unsigned char { keep = 0, refine = 1, coarsen = 2 };
    std::vector<unsigned char> flags(triangulation.n_active_cells(), keep);
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned())
        flags[cell->active_cell_index()] = cell->refine_flag_set()  ? refine :
                                           cell->coarsen_flag_set() ? coarsen :
                                                                      keep;
    GridTools::exchange_cell_data_to_ghosts<unsigned char, Triangulation<dim>>(
      triangulation,
      [&](const Cell &cell) -> std::optional<unsigned char> {
        return flags[cell->active_cell_index()];
      },
      [&](const Cell &cell, const unsigned char &value) {
        flags[cell->active_cell_index()] = value;
      });

    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned())
        for (const unsigned int f : cell->face_indices())
          if (cell->has_periodic_neighbor(f))
            {
              const auto other = cell->periodic_neighbor(f);
              if (!other->is_active())
                {
                  cell->clear_coarsen_flag();
                  cell->set_refine_flag();
                }
              else if (!other->is_artificial() && other->level() == cell->level())
                {
                  const unsigned char flag = flags[other->active_cell_index()];
                  if (flag == refine)
                    {
                      cell->clear_coarsen_flag();
                      cell->set_refine_flag();
                    }
                  else if (flag != coarsen)
                    cell->clear_coarsen_flag();
                }
            }
  }

  template <int dim>
  bool MeshAdaptor<dim>::flag_periodic_hanging_faces()
  {
    unsigned int flagged = 0;
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          cell->clear_coarsen_flag();
          for (const unsigned int f : cell->face_indices())
            if (cell->has_periodic_neighbor(f) && !cell->periodic_neighbor(f)->is_active())
              {
                cell->set_refine_flag();
                ++flagged;
                break;
              }
        }
    return Utilities::MPI::sum(flagged, triangulation.get_communicator()) > 0;
  }

  template <int dim>
  MeshLevels MeshAdaptor<dim>::levels(const Solid::SolidPhase<dim> *solid) const
  {
    const MPI_Comm comm = triangulation.get_communicator();
    std::vector<unsigned char> phase;
    if (solid)
      phase = solid->classify_cells(settings.interface_threshold);
    unsigned int             lo = std::numeric_limits<unsigned int>::max(), hi = 0;
    types::global_cell_index finest = 0, coarse_interface = 0;
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          lo = std::min<unsigned int>(lo, cell->level());
          hi = std::max<unsigned int>(hi, cell->level());
        }
    lo = Utilities::MPI::min(lo, comm);
    hi = Utilities::MPI::max(hi, comm);
    const unsigned int finest_level = settings.enabled ? settings.maximum_level : hi;
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          if (static_cast<unsigned int>(cell->level()) == hi)
            ++finest;
          if (solid && phase[cell->active_cell_index()] == Solid::interface_cell &&
              static_cast<unsigned int>(cell->level()) < finest_level)
            ++coarse_interface;
        }
    // the interface band widened by the margin (due()) reaching a cell
    // below the finest level
    bool near_coarse = false;
    if (solid && settings.enabled && follows_interface_only())
      {
        const unsigned int margin = std::max(
          1, static_cast<int>(std::floor((1. - settings.buffer_fraction) * settings.buffer_cells)));
        std::vector<unsigned char> band(triangulation.n_active_cells(), 0);
        for (unsigned int i = 0; i < band.size(); ++i)
          band[i] = phase[i] == Solid::interface_cell;
        dilate(band, margin);
        for (const auto &cell : triangulation.active_cell_iterators())
          if (cell->is_locally_owned() && band[cell->active_cell_index()] &&
              static_cast<unsigned int>(cell->level()) < finest_level)
            near_coarse = true;
        near_coarse = Utilities::MPI::logical_or(near_coarse, comm);
      }
    MeshLevels l;
    l.interface_near_coarse_cells = near_coarse;
    l.min_level              = lo;
    l.max_level              = hi;
    l.cells_on_finest        = Utilities::MPI::sum(finest, comm);
    l.coarse_interface_cells = Utilities::MPI::sum(coarse_interface, comm);
    return l;
  }

  template <int dim>
  void MeshAdaptor<dim>::save(std::ostream &out) const
  {
    out << "MeshAdaptor " << steps_since << " " << std::setprecision(17) << distance_since
        << "\n";
  }

  template <int dim>
  void MeshAdaptor<dim>::load(std::istream &in)
  {
    std::string tag;
    in >> tag >> steps_since >> distance_since;
    AssertThrow(tag == "MeshAdaptor" && !in.fail(),
                ExcMessage("checkpoint: cannot read the mesh adaptor's counters"));
  }

  template class MeshAdaptor<2>;
  template class MeshAdaptor<3>;
} // namespace Suspension
