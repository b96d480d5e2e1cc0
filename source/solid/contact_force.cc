#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/grid/grid_tools.h>

#include <suspension/mesh/face_neighbours.h>
#include <suspension/solid/contact_force.h>
#include <suspension/solid/phi_values.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <unordered_map>

namespace Suspension::Solid
{
  namespace
  {
    constexpr types::global_cell_index no_label = std::numeric_limits<types::global_cell_index>::max();

    /// Surface points sorted into cubes of a given size, so that all points
    /// within that size of a query point are in the 3^dim cubes around it.
    template <int dim>
    class Buckets
    {
    public:
      Buckets(const Point<dim> &lower, const Point<dim> &upper, const double size,
              const std::array<double, dim> &periods)
        : lower(lower)
      {
        for (unsigned int d = 0; d < dim; ++d)
          {
            const double length = upper[d] - lower[d];
            n[d]                = std::max(1, static_cast<int>(std::floor(length / size)));
            width[d]            = length / n[d];
            periodic[d]         = periods[d] > 0.;
          }
      }

      void insert(const Point<dim> &p, const unsigned int index)
      {
        content[key(index_of(p))].push_back(index);
      }

      /// Indices of the points in the cubes around p.
      template <typename Visitor>
      void visit_near(const Point<dim> &p, const Visitor &visit) const
      {
        const auto          centre = index_of(p);
        std::vector<long long> keys;
        std::array<int, dim>   offset;
        offset.fill(-1);
        while (true)
          {
            std::array<int, dim> i = centre;
            bool                 inside = true;
            for (unsigned int d = 0; d < dim; ++d)
              {
                i[d] += offset[d];
                if (periodic[d])
                  i[d] = (i[d] % n[d] + n[d]) % n[d];
                else if (i[d] < 0 || i[d] >= n[d])
                  inside = false;
              }
            if (inside)
              keys.push_back(key(i));
            unsigned int d = 0;
            while (d < dim && offset[d] == 1)
              offset[d++] = -1;
            if (d == dim)
              break;
            ++offset[d];
          }
        std::sort(keys.begin(), keys.end());
        keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
        for (const long long k : keys)
          if (const auto it = content.find(k); it != content.end())
            for (const unsigned int index : it->second)
              visit(index);
      }

    private:
      std::array<int, dim> index_of(const Point<dim> &p) const
      {
        std::array<int, dim> i;
        for (unsigned int d = 0; d < dim; ++d)
          {
            i[d] = static_cast<int>(std::floor((p[d] - lower[d]) / width[d]));
            i[d] = periodic[d] ? (i[d] % n[d] + n[d]) % n[d] : std::clamp(i[d], 0, n[d] - 1);
          }
        return i;
      }

      long long key(const std::array<int, dim> &i) const
      {
        long long k = 0;
        for (unsigned int d = 0; d < dim; ++d)
          k = k * (n[d] + 1) + i[d];
        return k;
      }

      Point<dim>                                       lower;
      std::array<int, dim>                             n;
      std::array<double, dim>                          width;
      std::array<bool, dim>                            periodic;
      std::unordered_map<long long, std::vector<unsigned int>> content;
    };

    /// The nearest point of each of the two nearest labels.
    template <int dim>
    struct TwoNearest
    {
      struct Entry
      {
        double                   distance = std::numeric_limits<double>::max();
        types::global_cell_index label    = no_label;
        Tensor<1, dim>           to_point; // from the query point
      } first, second;

      void offer(const double distance, const types::global_cell_index label,
                 const Tensor<1, dim> &to_point)
      {
        if (label == first.label)
          {
            if (distance < first.distance)
              first = {distance, label, to_point};
          }
        else if (label == second.label)
          {
            if (distance < second.distance)
              second = {distance, label, to_point};
            if (second.distance < first.distance)
              std::swap(first, second);
          }
        else if (distance < first.distance)
          {
            second = first;
            first  = {distance, label, to_point};
          }
        else if (distance < second.distance)
          second = {distance, label, to_point};
      }
    };
  } // namespace

  template <int dim>
  ContactForce<dim>::ContactForce(const Parameters::All                              &parameters,
                                  const std::vector<std::pair<unsigned int, double>> &walls,
                                  const std::array<double, dim>                       &periods,
                                  const Point<dim>                                    &lower_corner,
                                  const Point<dim>                                    &upper_corner)
    : settings(parameters.solid.contact)
    , scale(parameters.material.viscosity * parameters.solid.contact.velocity_scale *
            parameters.solid.contact.radius)
    , walls(walls)
    , periods(periods)
    , lower_corner(lower_corner)
    , upper_corner(upper_corner)
  {}

  template <int dim>
  Tensor<1, dim> ContactForce<dim>::nearest_image(const Point<dim> &from, const Point<dim> &to) const
  {
    Tensor<1, dim> v = to - from;
    for (unsigned int d = 0; d < dim; ++d)
      if (periods[d] > 0.)
        v[d] -= periods[d] * std::round(v[d] / periods[d]);
    return v;
  }

  template <int dim>
  double ContactForce<dim>::magnitude(const double gap, const double dx) const
  {
    const double d = std::max(gap, dx);
    return scale * (settings.a1 / d + settings.a2 / (d * d));
  }

  template <int dim>
  void ContactForce<dim>::label_particles(const parallel::distributed::Triangulation<dim> &tria,
                                          const std::vector<double> &cell_mean)
  {
    using Cell = typename Triangulation<dim>::active_cell_iterator;
    const unsigned int n_cells = tria.n_active_cells();
    cell_label.assign(n_cells, no_label);

    // a unique starting label per core cell: rank offset + local count
    std::vector<unsigned int> cores;
    for (const auto &cell : tria.active_cell_iterators())
      if (cell->is_locally_owned() && cell_mean[cell->active_cell_index()] >= 0.5)
        cores.push_back(cell->active_cell_index());
    const auto counts = Utilities::MPI::all_gather(tria.get_communicator(),
                                                   types::global_cell_index(cores.size()));
    const types::global_cell_index offset = std::accumulate(
      counts.begin(), counts.begin() + Utilities::MPI::this_mpi_process(tria.get_communicator()),
      types::global_cell_index(0));
    for (unsigned int k = 0; k < cores.size(); ++k)
      cell_label[cores[k]] = offset + k;

    std::vector<unsigned int> parent(n_cells);
    const auto find = [&](unsigned int i) {
      while (parent[i] != i)
        i = parent[i] = parent[parent[i]];
      return i;
    };
    while (true)
      {
        GridTools::exchange_cell_data_to_ghosts<types::global_cell_index, Triangulation<dim>>(
          tria,
          [&](const Cell &cell) -> std::optional<types::global_cell_index> {
            return cell_label[cell->active_cell_index()];
          },
          [&](const Cell &cell, const types::global_cell_index &label) {
            cell_label[cell->active_cell_index()] = label;
          });

        // unite each core with its labelled neighbours (own or ghost)
        std::iota(parent.begin(), parent.end(), 0u);
        for (const auto &cell : tria.active_cell_iterators())
          if (cell->is_locally_owned() && cell_label[cell->active_cell_index()] != no_label)
            for_each_face_neighbour<dim>(cell, [&](const Cell &neighbour) {
              if (cell_label[neighbour->active_cell_index()] != no_label)
                parent[find(cell->active_cell_index())] = find(neighbour->active_cell_index());
              return false;
            });
        std::vector<types::global_cell_index> smallest(n_cells, no_label);
        for (unsigned int i = 0; i < n_cells; ++i)
          if (cell_label[i] != no_label)
            smallest[find(i)] = std::min(smallest[find(i)], cell_label[i]);

        bool changed = false;
        for (const unsigned int i : cores)
          if (smallest[find(i)] != cell_label[i])
            {
              cell_label[i] = smallest[find(i)];
              changed       = true;
            }
        if (Utilities::MPI::max(changed ? 1 : 0, tria.get_communicator()) == 0)
          break;
      }
  }

  template <int dim>
  std::vector<typename ContactForce<dim>::SurfacePoint>
  ContactForce<dim>::find_surface_points(const SolidPhase<dim> &solid, double &dx) const
  {
    dx = std::numeric_limits<double>::max();
    using Cell               = typename Triangulation<dim>::active_cell_iterator;
    const auto &dof_handler  = solid.get_dof_handler();
    const auto &phi_solution = solid.get_solution();

    std::vector<Point<dim>> unit_vertices;
    for (const unsigned int v : GeometryInfo<dim>::vertex_indices())
      unit_vertices.push_back(GeometryInfo<dim>::unit_cell_vertex(v));
    PhiValues<dim> vertex_values(solid.get_fe(), Quadrature<dim>(unit_vertices), update_default);
    const auto    &phi = vertex_values.values();

    std::vector<SurfacePoint> points;
    for (const auto &dof_cell : dof_handler.active_cell_iterators())
      if (dof_cell->is_locally_owned())
        {
          vertex_values.reinit(dof_cell, phi_solution);
          const Cell   cell(dof_cell);
          const double lo = *std::min_element(phi.begin(), phi.end());
          const double hi = *std::max_element(phi.begin(), phi.end());
          if (!(lo < 0.5 && hi >= 0.5))
            continue;

          // the cores this cell belongs to or touches
          std::vector<Cell> cores;
          if (cell_label[cell->active_cell_index()] != no_label)
            cores.push_back(cell);
          else
            for_each_face_neighbour<dim>(cell, [&](const Cell &neighbour) {
              if (cell_label[neighbour->active_cell_index()] != no_label)
                cores.push_back(neighbour);
              return false;
            });
          if (cores.empty())
            continue; // a sliver of phi that belongs to no particle

          for (unsigned int line = 0; line < GeometryInfo<dim>::lines_per_cell; ++line)
            {
              const unsigned int a = GeometryInfo<dim>::line_to_cell_vertices(line, 0);
              const unsigned int b = GeometryInfo<dim>::line_to_cell_vertices(line, 1);
              if ((phi[a] < 0.5) == (phi[b] < 0.5))
                continue;
              const double     s = (0.5 - phi[a]) / (phi[b] - phi[a]);
              const Point<dim> p = cell->vertex(a) + s * (cell->vertex(b) - cell->vertex(a));
              // a cell between two particles: each crossing to its nearer core
              const Cell *owner = &cores.front();
              for (const Cell &c : cores)
                if (c->center().distance(p) < (*owner)->center().distance(p))
                  owner = &c;
              points.push_back({p, cell_label[(*owner)->active_cell_index()]});
              dx = std::min(dx, cell->minimum_vertex_distance());
            }
        }
    return points;
  }

  template <int dim>
  ContactDiagnostics ContactForce<dim>::update(const SolidPhase<dim> &solid)
  {
    const auto &dof_handler = solid.get_dof_handler();
    const auto &tria        = dof_handler.get_triangulation();
    const auto *ptria =
      dynamic_cast<const parallel::distributed::Triangulation<dim> *>(&tria);
    Assert(ptria != nullptr, ExcInternalError());
    const MPI_Comm communicator = ptria->get_communicator();

    // cell means of phi
    PhiValues<dim> phi_values(solid.get_fe(), QGauss<dim>(solid.get_fe().degree + 1),
                              update_JxW_values);
    const auto    &fe_values = phi_values.fe_values();
    const auto    &phi       = phi_values.values();
    std::vector<double> cell_mean(tria.n_active_cells(), 0.);
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          phi_values.reinit(cell, solid.get_solution());
          double integral = 0., measure = 0.;
          for (const unsigned int q : fe_values.quadrature_point_indices())
            {
              integral += phi[q] * fe_values.JxW(q);
              measure += fe_values.JxW(q);
            }
          cell_mean[cell->active_cell_index()] = integral / measure;
        }

    label_particles(*ptria, cell_mean);

    // surface points of all ranks, and dx: the smallest cell carrying one
    double     dx           = 0.;
    const auto local_points = find_surface_points(solid, dx);
    dx                      = Utilities::MPI::min(dx, communicator);
    std::vector<SurfacePoint> points;
    for (const auto &part : Utilities::MPI::all_gather(communicator, local_points))
      points.insert(points.end(), part.begin(), part.end());

    ContactDiagnostics diagnostics;
    diagnostics.smallest_cell = dx;
    cell_force.assign(tria.n_active_cells(), Tensor<1, dim>());
    if (points.empty())
      return diagnostics;

    const double range = settings.range * dx;
    Buckets<dim> buckets(lower_corner, upper_corner, range, periods);
    for (unsigned int i = 0; i < points.size(); ++i)
      buckets.insert(points[i].location, i);

    // the force in every locally owned fluid cell
    for (const auto &cell : tria.active_cell_iterators())
      if (cell->is_locally_owned() && cell_mean[cell->active_cell_index()] < 0.5)
        {
          const Point<dim> x = cell->center();
          TwoNearest<dim>  nearest;
          buckets.visit_near(x, [&](const unsigned int i) {
            const Tensor<1, dim> v = nearest_image(x, points[i].location);
            const double         d = v.norm();
            if (d <= range)
              nearest.offer(d, points[i].label, v);
          });
          if (nearest.first.label == no_label)
            continue;
          const auto    &a = nearest.first, &b = nearest.second;
          Tensor<1, dim> f;
          // between two particles: a's and b's surface on opposite sides
          if (b.label != no_label && a.to_point * b.to_point < 0.)
            {
              const double gap = (b.to_point - a.to_point).norm();
              if (gap <= range)
                f += magnitude(gap, dx) * a.to_point / a.distance;
            }
          // between a particle and a wall
          for (const auto &[direction, position] : walls)
            {
              const double to_wall = position - x[direction];
              if (a.to_point[direction] * to_wall >= 0.)
                continue;
              const double gap = std::abs(to_wall - a.to_point[direction]);
              if (gap > range)
                continue;
              Tensor<1, dim> n;
              if (std::abs(to_wall) < a.distance)
                n[direction] = to_wall > 0. ? 1. : -1.;
              else
                n = a.to_point / a.distance;
              f += magnitude(gap, dx) * n;
            }
          if (f.norm() > 0.)
            {
              cell_force[cell->active_cell_index()] = f;
              ++diagnostics.active_cells;
              diagnostics.largest_force = std::max(diagnostics.largest_force, f.norm());
            }
        }

    // diagnostics: closest gaps, number of particles
    double closest_gap = std::numeric_limits<double>::max();
    double closest_wall = std::numeric_limits<double>::max();
    for (const auto &p : local_points)
      {
        buckets.visit_near(p.location, [&](const unsigned int i) {
          if (points[i].label != p.label)
            closest_gap =
              std::min(closest_gap, nearest_image(p.location, points[i].location).norm());
        });
        for (const auto &[direction, position] : walls)
          closest_wall = std::min(closest_wall, std::abs(position - p.location[direction]));
      }
    closest_gap  = Utilities::MPI::min(closest_gap, communicator);
    closest_wall = Utilities::MPI::min(closest_wall, communicator);
    diagnostics.closest_gap  = closest_gap > range ? -1. : closest_gap;
    diagnostics.closest_wall = walls.empty() ? -1. : closest_wall;

    std::vector<types::global_cell_index> labels;
    for (const auto &cell : tria.active_cell_iterators())
      if (cell->is_locally_owned() && cell_label[cell->active_cell_index()] != no_label)
        labels.push_back(cell_label[cell->active_cell_index()]);
    std::sort(labels.begin(), labels.end());
    labels.erase(std::unique(labels.begin(), labels.end()), labels.end());
    std::vector<types::global_cell_index> all;
    for (const auto &part : Utilities::MPI::all_gather(communicator, labels))
      all.insert(all.end(), part.begin(), part.end());
    std::sort(all.begin(), all.end());
    diagnostics.n_particles = std::unique(all.begin(), all.end()) - all.begin();

    diagnostics.active_cells  = Utilities::MPI::sum(diagnostics.active_cells, communicator);
    diagnostics.largest_force = Utilities::MPI::max(diagnostics.largest_force, communicator);
    return diagnostics;
  }

  template <int dim>
  void ContactForce<dim>::add(const typename Triangulation<dim>::active_cell_iterator &cell,
                              const std::vector<Point<dim>> &,
                              const std::vector<Point<dim>> &,
                              double,
                              std::vector<Tensor<1, dim>> &force,
                              std::vector<SymmetricTensor<2, dim>> &) const
  {
    const Tensor<1, dim> &f = cell_force[cell->active_cell_index()];
    if (f.norm_square() == 0.)
      return;
    for (auto &value : force)
      value += f;
  }

  template class ContactForce<2>;
  template class ContactForce<3>;
} // namespace Suspension::Solid
