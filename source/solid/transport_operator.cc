// TransportOperator: set-up on a mesh (MatrixFree data, the lanes of the
// interface cells, vectors) and the marking of the cells that carry B.
#include <deal.II/base/bounding_box.h>
#include <deal.II/base/memory_consumption.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/distributed/tria_base.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/base/qprojector.h>
#include <deal.II/fe/mapping_q1.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/matrix_free/fe_evaluation.h>
#include <deal.II/matrix_free/operators.h>

#include <suspension/solid/transport_kernels.h>
#include <suspension/solid/transport_operator.h>

#include <algorithm>
#include <numeric>
#include <sstream>
#include <functional>
#include <memory>

namespace Suspension::Solid
{
  using namespace internal;

  template <int dim>
  void TransportOperator<dim>::reinit(const DoFHandler<dim>           &dof_solid,
                                      const DoFHandler<dim>           &dof_velocity,
                                      const AffineConstraints<double> &velocity_constraints,
                                      const bool                       with_B_)
  {
    with_B = with_B_;
    const unsigned int k   = dof_solid.get_fe().degree;
    const unsigned int k_u = dof_velocity.get_fe().degree;
    // (u phi, grad v) has degree k_u + 2k per direction: Gauss exact for it.
    const unsigned int n_q = (k_u + 2 * k + 2) / 2;

    typename MatrixFree<dim, double>::AdditionalData data;
    data.tasks_parallel_scheme = MatrixFree<dim, double>::AdditionalData::none;
    // no quadrature points: cell_point() and face_point() compute them
    data.mapping_update_flags = update_values | update_gradients | update_JxW_values;
    data.mapping_update_flags_inner_faces =
      update_values | update_gradients | update_JxW_values | update_normal_vectors;
    data.mapping_update_flags_boundary_faces =
      update_values | update_JxW_values | update_normal_vectors;

    const AffineConstraints<double> no_constraints;
    const std::vector<const DoFHandler<dim> *>           dofs = {&dof_solid, &dof_velocity};
    const std::vector<const AffineConstraints<double> *> constraints = {&no_constraints,
                                                                        &velocity_constraints};
    // quadrature 0: integrals; 1: k+1 Gauss points for the inverse mass
    const std::vector<Quadrature<1>> quadratures = {QGauss<1>(n_q), QGauss<1>(k + 1)};
    matrix_free.reinit(MappingQ1<dim>(), dofs, constraints, quadratures, data);
    for (unsigned int i = 0; i < 2; ++i)
      unit_cell_points[i] = QGauss<dim>(quadratures[i].size()).get_points();
    for (const unsigned int f : GeometryInfo<dim>::face_indices())
      unit_face_points[f] = QProjector<dim>::project_to_face(ReferenceCells::get_hypercube<dim>(),
                                                             QGauss<dim - 1>(n_q), f)
                              .get_points();

    // B everywhere until mark_solid_cells() says where
    const unsigned int n_batches = matrix_free.n_cell_batches() + matrix_free.n_ghost_cell_batches();
    b_active.resize_fast(n_batches);
    for (unsigned int cell = 0; cell < n_batches; ++cell)
      b_active[cell] = 1.;
    lane_cell_index.assign(n_batches * VectorizedArray<double>::size(), numbers::invalid_unsigned_int);
    for (unsigned int cell = 0; cell < n_batches; ++cell)
      for (unsigned int v = 0; v < matrix_free.n_active_entries_per_cell_batch(cell); ++v)
        lane_cell_index[cell * VectorizedArray<double>::size() + v] =
          matrix_free.get_cell_iterator(cell, v)->active_cell_index();
    owned_cell_lane.assign(dof_solid.get_triangulation().n_active_cells(), numbers::invalid_unsigned_int);
    for (unsigned int cell = 0; cell < matrix_free.n_cell_batches(); ++cell)
      for (unsigned int v = 0; v < matrix_free.n_active_entries_per_cell_batch(cell); ++v)
        owned_cell_lane[lane_cell_index[cell * VectorizedArray<double>::size() + v]] =
          cell * VectorizedArray<double>::size() + v;

    // the periodic faces among the inner faces (a cell's face on the
    // domain's boundary that has a neighbour across it)
    periodic_face_lane.assign(matrix_free.n_inner_face_batches() * VectorizedArray<double>::size(), 0);
    for (unsigned int face = 0; face < matrix_free.n_inner_face_batches(); ++face)
      for (unsigned int v = 0; v < matrix_free.n_active_entries_per_face_batch(face); ++v)
        {
          const auto [cell, face_no] = matrix_free.get_face_iterator(face, v, true);
          periodic_face_lane[face * VectorizedArray<double>::size() + v] = cell->at_boundary(face_no);
        }

    // cell sizes for the interface diffusion: a cell's smallest vertex
    // distance, a face's the smaller of its two cells'
    cell_size.resize(matrix_free.n_cell_batches());
    for (unsigned int cell = 0; cell < cell_size.size(); ++cell)
      for (unsigned int v = 0; v < matrix_free.n_active_entries_per_cell_batch(cell); ++v)
        cell_size[cell][v] = matrix_free.get_cell_iterator(cell, v)->minimum_vertex_distance();
    face_size.resize(matrix_free.n_inner_face_batches());
    for (unsigned int face = 0; face < face_size.size(); ++face)
      for (unsigned int v = 0; v < matrix_free.n_active_entries_per_face_batch(face); ++v)
        face_size[face][v] =
          std::min(matrix_free.get_face_iterator(face, v, true).first->minimum_vertex_distance(),
                   matrix_free.get_face_iterator(face, v, false).first->minimum_vertex_distance());

    if (thinc_beta > 0.)
      {
        // the mean of phi as a functional of its DoFs
        // (FE_DGQ numbers them lexicographically, as FEEvaluation does)
        const FiniteElement<dim> &base = dof_solid.get_fe().base_element(0);
        const QGauss<dim>         exact(k + 2);
        mean_weights.assign(base.n_dofs_per_cell(), 0.);
        for (unsigned int i = 0; i < base.n_dofs_per_cell(); ++i)
          for (unsigned int q = 0; q < exact.size(); ++q)
            mean_weights[i] += exact.weight(q) * base.shape_value(i, exact.point(q));
        const QGauss<dim> profile(3);
        profile_points  = profile.get_points();
        profile_weights = profile.get_weights();

        // the profile is written in the unit cell of an axis-parallel box
        const unsigned int n_cells = matrix_free.n_cell_batches() + matrix_free.n_ghost_cell_batches();
        const unsigned int n_lanes = VectorizedArray<double>::size();
        cell_corner.assign(n_cells * n_lanes, Point<dim>());
        cell_volume.assign(n_cells * n_lanes, 0.);
        cell_vertices.assign(n_cells * n_lanes * GeometryInfo<dim>::vertices_per_cell,
                             numbers::invalid_unsigned_int);
        vertex_mean.assign(dof_solid.get_triangulation().n_vertices(), 0.);
        vertex_weight.assign(dof_solid.get_triangulation().n_vertices(), 0.);
        cell_extent.assign(n_cells * n_lanes, Tensor<1, dim>());
        for (unsigned int cell = 0; cell < n_cells; ++cell)
          for (unsigned int v = 0; v < matrix_free.n_active_entries_per_cell_batch(cell); ++v)
            {
              const auto   it  = matrix_free.get_cell_iterator(cell, v);
              const auto   box = it->bounding_box();
              const double product = [&] {
                double p = 1.;
                for (unsigned int d = 0; d < dim; ++d)
                  p *= box.side_length(d);
                return p;
              }();
              if (std::abs(it->measure() - product) > 1e-10 * product)
                {
                  std::ostringstream where;
                  where << it->center();
                  throw std::runtime_error(
                    "entry 'Solid/Interface reconstruction': THINC needs axis-parallel "
                    "box cells, and the cell centred at (" + where.str() + ") is not one");
                }
              cell_corner[cell * n_lanes + v] = box.get_boundary_points().first;
              cell_volume[cell * n_lanes + v] = product;
              for (const unsigned int i : it->vertex_indices())
                cell_vertices[(cell * n_lanes + v) * GeometryInfo<dim>::vertices_per_cell + i] =
                  it->vertex_index(i);
              for (unsigned int d = 0; d < dim; ++d)
                cell_extent[cell * n_lanes + v][d] = box.side_length(d);
            }
        // the global index of every lane's cell, for the exchange with
        // the neighbours on other ranks
        lane_global_cell.assign(n_cells * n_lanes, numbers::invalid_unsigned_int);
        for (unsigned int cell = 0; cell < n_cells; ++cell)
          for (unsigned int v = 0; v < matrix_free.n_active_entries_per_cell_batch(cell); ++v)
            lane_global_cell[cell * n_lanes + v] =
              matrix_free.get_cell_iterator(cell, v)->global_active_cell_index();
        // vertices across periodic faces are one vertex for the averages
        // (a particle that crosses the channel's periodic ends keeps its
        // normals): union of the matching vertices of periodic face pairs
        std::vector<unsigned int> representative(vertex_mean.size());
        std::iota(representative.begin(), representative.end(), 0u);
        const auto find = [&](unsigned int v) {
          while (representative[v] != v)
            v = representative[v] = representative[representative[v]];
          return v;
        };
        for (const auto &cell : dof_solid.get_triangulation().active_cell_iterators())
          if (!cell->is_artificial())
            for (const unsigned int f : cell->face_indices())
              if (cell->has_periodic_neighbor(f) && !cell->periodic_neighbor_is_coarser(f))
                {
                  const auto         other      = cell->periodic_neighbor(f);
                  const auto         face       = cell->face(f);
                  const auto         other_face = other->face(cell->periodic_neighbor_face_no(f));
                  const unsigned int normal     = f / 2;
                  const double       tolerance  = 1e-8 * cell->minimum_vertex_distance();
                  for (const unsigned int i : face->vertex_indices())
                    for (const unsigned int j : other_face->vertex_indices())
                      {
                        bool same = true;
                        for (unsigned int d = 0; d < dim; ++d)
                          if (d != normal &&
                              std::abs(face->vertex(i)[d] - other_face->vertex(j)[d]) > tolerance)
                            same = false;
                        if (same)
                          representative[find(face->vertex_index(i))] = find(other_face->vertex_index(j));
                      }
                }
        for (auto &v : cell_vertices)
          if (v != numbers::invalid_unsigned_int)
            v = find(v);

        matrix_free.initialize_cell_data_vector(reconstruction);
        cell_mean.assign(n_cells * n_lanes, 0.);
        vertex_normal.assign(thinc_curved ? vertex_mean.size() : 0, Tensor<1, dim>());

        // Youngs' normal of an owned cell needs the means of all cells that
        // share a vertex with it; MatrixFree's ghost cells are only those
        // across faces, so the ghost layer of the mesh is listed here (its
        // vertices, volumes and cell indices)
        ghost_layer_vertices.clear();
        ghost_layer_volume.clear();
        ghost_layer_cells.clear();
        for (const auto &cell : dof_solid.active_cell_iterators())
          if (cell->is_ghost())
            {
              for (const unsigned int i : cell->vertex_indices())
                ghost_layer_vertices.push_back(find(cell->vertex_index(i)));
              ghost_layer_volume.push_back(cell->measure());
              ghost_layer_cells.push_back(cell->global_active_cell_index());
            }
        const auto *parallel =
          dynamic_cast<const parallel::TriangulationBase<dim> *>(&dof_solid.get_triangulation());
        AssertThrow(parallel != nullptr, ExcMessage("the transport needs a parallel triangulation"));
        const auto partitioner = parallel->global_active_cell_index_partitioner().lock();
        for (auto &values : cell_exchange)
          values.reinit(partitioner);
      }
  }

  template <int dim>
  Point<dim, VectorizedArray<double>>
  TransportOperator<dim>::cell_point(const unsigned int cell, const unsigned int quadrature,
                                     const unsigned int q) const
  {
    const Point<dim>                   &unit = unit_cell_points[quadrature][q];
    Point<dim, VectorizedArray<double>> x;
    for (unsigned int v = 0; v < VectorizedArray<double>::size(); ++v)
      {
        const unsigned int k = cell * VectorizedArray<double>::size() +
                               std::min(v, matrix_free.n_active_entries_per_cell_batch(cell) - 1);
        for (unsigned int d = 0; d < dim; ++d)
          x[d][v] = cell_corner[k][d] + cell_extent[k][d] * unit[d];
      }
    return x;
  }

  template <int dim>
  Point<dim, VectorizedArray<double>> TransportOperator<dim>::face_point(const unsigned int face,
                                                                         const unsigned int q) const
  {
    const auto &info = matrix_free.get_face_info(face);
    const Point<dim>                   &unit = unit_face_points[info.interior_face_no][q];
    Point<dim, VectorizedArray<double>> x;
    for (unsigned int v = 0; v < VectorizedArray<double>::size(); ++v)
      {
        const unsigned int k =
          info.cells_interior[std::min(v, matrix_free.n_active_entries_per_face_batch(face) - 1)];
        for (unsigned int d = 0; d < dim; ++d)
          x[d][v] = cell_corner[k][d] + cell_extent[k][d] * unit[d];
      }
    return x;
  }

  template <int dim>
  std::size_t TransportOperator<dim>::memory_consumption() const
  {
    using MemoryConsumption::memory_consumption;
    return matrix_free.memory_consumption() + memory_consumption(cell_size) +
           memory_consumption(face_size) + memory_consumption(cell_corner) +
           memory_consumption(cell_extent) + memory_consumption(cell_volume) +
           memory_consumption(cell_vertices) + memory_consumption(lane_global_cell) +
           memory_consumption(vertex_mean) +
           memory_consumption(vertex_weight) + memory_consumption(cell_mean) +
           reconstruction.size() * sizeof(Lanes) + b_active.memory_consumption() +
           memory_consumption(lane_cell_index) + memory_consumption(owned_cell_lane) +
           memory_consumption(periodic_face_lane) + memory_consumption(vertex_normal) +
           memory_consumption(ghost_layer_vertices) + memory_consumption(ghost_layer_volume) +
           memory_consumption(ghost_layer_cells) +
           n_cell_values * cell_exchange[0].memory_consumption();
  }

  template <int dim>
  void TransportOperator<dim>::initialize_solid_vector(VectorType &v) const
  {
    matrix_free.initialize_dof_vector(v, 0);
  }

  template <int dim>
  void TransportOperator<dim>::initialize_velocity_vector(VectorType &v) const
  {
    matrix_free.initialize_dof_vector(v, 1);
  }

  template <int dim>
  template <typename Holds>
  std::vector<unsigned char> TransportOperator<dim>::cells_near(const VectorType &solution,
                                                                const Holds      &holds_at) const
  {
    const unsigned int n_lanes = VectorizedArray<double>::size();
    const auto        &tria    = matrix_free.get_dof_handler(0).get_triangulation();
    // 1. the owned cells whose nodal values of phi satisfy holds_at(lowest,
    // highest), then their owners' marks on the ghosts
    std::vector<unsigned char> holds(tria.n_active_cells(), 0), marked;
    FEEvaluation<dim, -1, 0, 1, double> phi(matrix_free, 0, 0, 0);
    for (unsigned int cell = 0; cell < matrix_free.n_cell_batches(); ++cell)
      {
        phi.reinit(cell);
        phi.read_dof_values_plain(solution);
        for (unsigned int v = 0; v < matrix_free.n_active_entries_per_cell_batch(cell); ++v)
          {
            double lowest = phi.begin_dof_values()[0][v], highest = lowest;
            for (unsigned int i = 1; i < phi.dofs_per_cell; ++i)
              {
                lowest  = std::min(lowest, phi.begin_dof_values()[i][v]);
                highest = std::max(highest, phi.begin_dof_values()[i][v]);
              }
            holds[lane_cell_index[cell * n_lanes + v]] = holds_at(lowest, highest);
          }
      }
    const auto exchange = [&](std::vector<unsigned char> &flags) {
      using Iterator = typename Triangulation<dim>::active_cell_iterator;
      GridTools::exchange_cell_data_to_ghosts<unsigned char, Triangulation<dim>>(
        tria,
        [&](const Iterator &cell) { return std_cxx17::optional<unsigned char>(flags[cell->active_cell_index()]); },
        [&](const Iterator &cell, const unsigned char &value) { flags[cell->active_cell_index()] = value; });
    };
    exchange(holds);
    // 2. and their face neighbours (periodic and hanging faces included):
    // the faces of owned cells are the inner faces of the MatrixFree
    marked = holds;
    for (unsigned int face = 0; face < matrix_free.n_inner_face_batches(); ++face)
      {
        const auto &info = matrix_free.get_face_info(face);
        for (unsigned int v = 0; v < matrix_free.n_active_entries_per_face_batch(face); ++v)
          {
            const unsigned int in  = lane_cell_index[info.cells_interior[v]];
            const unsigned int out = lane_cell_index[info.cells_exterior[v]];
            if (holds[in] || holds[out])
              marked[in] = marked[out] = 1;
          }
      }
    exchange(marked);
    return marked;
  }

  template <int dim>
  void TransportOperator<dim>::mark_solid_cells(const VectorType &solution)
  {
    if (!with_B)
      return;
    const unsigned int n_lanes = VectorizedArray<double>::size();
    const std::vector<unsigned char> marked =
      cells_near(solution, [](const double, const double highest) { return highest > 1e-8; });
    for (unsigned int cell = 0; cell < b_active.size(); ++cell)
      for (unsigned int v = 0; v < n_lanes; ++v)
        {
          const unsigned int index = lane_cell_index[cell * n_lanes + v];
          b_active[cell][v] = (index != numbers::invalid_unsigned_int && marked[index]) ? 1. : 0.;
        }
  }

  template <int dim>
  double TransportOperator<dim>::interface_speed(const VectorType &solution,
                                                 const VectorType &u0,
                                                 const VectorType &u1,
                                                 const double      epsilon) const
  {
    const unsigned int n_lanes = VectorizedArray<double>::size();
    const std::vector<unsigned char> marked =
      cells_near(solution, [epsilon](const double lowest, const double highest) {
        return highest > epsilon && lowest < 1. - epsilon;
      });
    FEEvaluation<dim, -1, 0, dim, double> u(matrix_free, 1, 0);
    double speed = 0.;
    for (unsigned int cell = 0; cell < matrix_free.n_cell_batches(); ++cell)
      {
        bool any = false;
        for (unsigned int v = 0; v < matrix_free.n_active_entries_per_cell_batch(cell); ++v)
          any = any || marked[lane_cell_index[cell * n_lanes + v]];
        if (!any)
          continue;
        u.reinit(cell);
        for (const VectorType *velocity : {&u0, &u1})
          {
            u.read_dof_values_plain(*velocity);
            u.evaluate(EvaluationFlags::values);
            for (const unsigned int q : u.quadrature_point_indices())
              {
                const VectorizedArray<double> norm = u.get_value(q).norm();
                for (unsigned int v = 0; v < matrix_free.n_active_entries_per_cell_batch(cell); ++v)
                  if (marked[lane_cell_index[cell * n_lanes + v]])
                    speed = std::max(speed, norm[v]);
              }
          }
      }
    return Utilities::MPI::max(speed, matrix_free.get_dof_handler(0).get_communicator());
  }

  template class TransportOperator<2>;
  template class TransportOperator<3>;
} // namespace Suspension::Solid
