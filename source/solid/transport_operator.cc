#include <deal.II/base/bounding_box.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/mapping_q1.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/matrix_free/fe_evaluation.h>
#include <deal.II/matrix_free/operators.h>

#include <suspension/solid/transport_operator.h>

#include <algorithm>
#include <numeric>
#include <sstream>
#include <functional>
#include <memory>

namespace Suspension::Solid
{
  namespace
  {
    using VA = VectorizedArray<double>;

    template <int dim>
    SymmetricTensor<2, dim, VA> to_tensor(const Tensor<1, dim * (dim + 1) / 2, VA> &b)
    {
      SymmetricTensor<2, dim, VA> B;
      for (unsigned int c = 0; c < b.dimension; ++c)
        B[SymmetricTensor<2, dim>::unrolled_to_component_indices(c)] = b[c];
      return B;
    }

    template <int dim>
    Tensor<1, dim * (dim + 1) / 2, VA> to_vector(const Tensor<2, dim, VA> &B)
    {
      Tensor<1, dim * (dim + 1) / 2, VA> b;
      for (unsigned int c = 0; c < b.dimension; ++c)
        b[c] = B[SymmetricTensor<2, dim>::unrolled_to_component_indices(c)];
      return b;
    }

    // A face point seen from the cell [lower, upper] in one coordinate: on
    // a periodic face it is given on the other side of the domain, a period
    // away, and its image is the cell's far face (x below the box is the
    // upper face, x above it the lower one); otherwise it lies on the box up
    // to round-off, and clamping removes that.
    inline double on_cell_face(const double x, const double lower, const double upper)
    {
      const double half = 0.5 * (upper - lower);
      if (x < lower - half)
        return upper;
      if (x > upper + half)
        return lower;
      return std::clamp(x, lower, upper);
    }

    // phi where the transport sees it: the cell's THINC profile at x in
    // the lanes that have one, the DG value elsewhere
    template <int dim, typename Lanes>
    VA seen_phi(const Lanes &profile, const Point<dim, VA> &x, const VA &dg_value)
    {
      VA out = dg_value;
      for (unsigned int v = 0; v < VA::size(); ++v)
        if (profile[v].weight > 0.)
          {
            const auto &r        = profile[v];
            double      argument = r.offset;
            // for the curved profile: s = (x - centre) / h, n from the slope
            double s2 = 0., sn = 0., nn = 0.;
            for (unsigned int d = 0; d < dim; ++d)
              {
                const double y = on_cell_face(x[d][v], r.lower[d], r.upper[d]);
                argument += r.slope[d] * y;
                if (r.curvature == 0.)
                  continue;
                const double h = r.upper[d] - r.lower[d];
                const double s = (y - 0.5 * (r.lower[d] + r.upper[d])) / h;
                s2 += s * s;
                sn += r.slope[d] * h * s;
                nn += r.slope[d] * h * r.slope[d] * h;
              }
            if (r.curvature != 0.)
              argument += r.curvature * (s2 - sn * sn / nn);
            // 1/2 (1 + tanh a) = 1 / (1 + exp(-2a)): one exp, cheaper than
            // glibc's tanh (which goes through expm1)
            out[v] += r.weight * (1. / (1. + std::exp(-2. * argument)) - dg_value[v]);
          }
      return out;
    }

    // whether some lane of a batch is marked (B transported there)
    bool any_lane(const VA &active)
    {
      for (unsigned int v = 0; v < VA::size(); ++v)
        if (active[v] > 0.)
          return true;
      return false;
    }

    // upwind flux of a transported quantity: un > 0 takes the inside value
    template <typename T>
    T upwind(const VA &un, const T &inside, const T &outside)
    {
      return 0.5 * un * (inside + outside) + 0.5 * std::abs(un) * (inside - outside);
    }
  } // namespace

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
    data.mapping_update_flags =
      update_values | update_gradients | update_JxW_values | update_quadrature_points;
    data.mapping_update_flags_inner_faces = update_values | update_gradients |
                                            update_JxW_values | update_normal_vectors |
                                            update_quadrature_points;
    data.mapping_update_flags_boundary_faces =
      update_values | update_JxW_values | update_normal_vectors | update_quadrature_points;

    const AffineConstraints<double> no_constraints;
    const std::vector<const DoFHandler<dim> *>           dofs = {&dof_solid, &dof_velocity};
    const std::vector<const AffineConstraints<double> *> constraints = {&no_constraints,
                                                                        &velocity_constraints};
    // quadrature 0: integrals; 1: k+1 Gauss points for the inverse mass
    const std::vector<Quadrature<1>> quadratures = {QGauss<1>(n_q), QGauss<1>(k + 1)};
    matrix_free.reinit(MappingQ1<dim>(), dofs, constraints, quadratures, data);

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

    // the periodic faces among the inner faces (a cell's face on the
    // domain's boundary that has a neighbour across it)
    periodic_face_lane.assign(matrix_free.n_inner_face_batches() * VectorizedArray<double>::size(), 0);
    for (unsigned int face = 0; face < matrix_free.n_inner_face_batches(); ++face)
      for (unsigned int v = 0; v < matrix_free.n_active_entries_per_face_batch(face); ++v)
        {
          const auto [cell, face_no] = matrix_free.get_face_iterator(face, v, true);
          periodic_face_lane[face * VectorizedArray<double>::size() + v] = cell->at_boundary(face_no);
        }
    matrix_free.initialize_dof_vector(face_scratch, 0);

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
        // the phi DoFs of every lane (global, and local to the MatrixFree's
        // vectors), for the exchange of the profiles with the ghost cells
        {
          const FiniteElement<dim>            &fe = dof_solid.get_fe();
          const auto                           partitioner = matrix_free.get_vector_partitioner(0);
          std::vector<types::global_dof_index> indices(fe.n_dofs_per_cell());
          const unsigned int                   n_phi = base.n_dofs_per_cell();
          lane_phi_dofs.assign(n_cells * n_lanes * n_phi, 0);
          lane_phi_local.assign(n_cells * n_lanes * n_phi, 0);
          for (unsigned int cell = 0; cell < n_cells; ++cell)
            for (unsigned int v = 0; v < matrix_free.n_active_entries_per_cell_batch(cell); ++v)
              {
                matrix_free.get_cell_iterator(cell, v)->get_dof_indices(indices);
                for (unsigned int i = 0; i < indices.size(); ++i)
                  {
                    const auto [component, index] = fe.system_to_component_index(i);
                    if (component != 0)
                      continue;
                    const std::size_t k = (cell * n_lanes + v) * n_phi + index;
                    lane_phi_dofs[k]    = indices[i];
                    lane_phi_local[k]   = partitioner->global_to_local(indices[i]);
                  }
              }
        }
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
        if (matrix_free.n_ghost_cell_batches() > 0)
          matrix_free.initialize_dof_vector(ghosted, 0);
        if (matrix_free.n_ghost_cell_batches() > 0 && thinc_curved)
          matrix_free.initialize_dof_vector(ghosted_curvature, 0);
        vertex_normal.assign(thinc_curved ? vertex_mean.size() : 0, Tensor<1, dim>());

        // Youngs' normal of an owned cell needs the means of all cells that
        // share a vertex with it; MatrixFree's ghost cells are only those
        // across faces, so the ghost layer of the mesh is listed here (its
        // vertices, volumes and phi DoFs), read from a vector with all
        // locally relevant DoFs
        ghost_layer_vertices.clear();
        ghost_layer_volume.clear();
        ghost_layer_dofs.clear();
        std::vector<types::global_dof_index> indices(dof_solid.get_fe().n_dofs_per_cell());
        for (const auto &cell : dof_solid.active_cell_iterators())
          if (cell->is_ghost())
            {
              for (const unsigned int i : cell->vertex_indices())
                ghost_layer_vertices.push_back(find(cell->vertex_index(i)));
              ghost_layer_volume.push_back(cell->measure());
              cell->get_dof_indices(indices);
              const std::size_t first = ghost_layer_dofs.size();
              ghost_layer_dofs.resize(first + base.n_dofs_per_cell());
              for (unsigned int i = 0; i < indices.size(); ++i)
                {
                  const auto [component, index] = dof_solid.get_fe().system_to_component_index(i);
                  if (component == 0)
                    ghost_layer_dofs[first + index] = indices[i];
                }
            }
        if (!ghost_layer_volume.empty())
          {
            IndexSet relevant;
            DoFTools::extract_locally_relevant_dofs(dof_solid, relevant);
            ghost_layer_values.reinit(dof_solid.locally_owned_dofs(), relevant,
                                      dof_solid.get_communicator());
            if (thinc_curved)
              normal_values.reinit(dof_solid.locally_owned_dofs(), relevant,
                                   dof_solid.get_communicator());
          }
      }
  }

  template <int dim>
  typename TransportOperator<dim>::Reconstruction
  TransportOperator<dim>::reconstruct(const double mean, const Tensor<1, dim> &gradient,
                                      const Point<dim> &x0, const Tensor<1, dim> &h,
                                      const double divergence) const
  {
    Reconstruction r;
    // cells that are (almost) all solid or all fluid, and flat cells (no
    // normal), keep their polynomial
    constexpr double tiny   = 1e-6;
    const double     norm   = gradient.norm();
    const double     margin = std::min(mean, 1. - mean);
    if (!(margin > tiny) || norm < 1e-8)
      return r;
    const Tensor<1, dim> n    = gradient / norm;
    const double         beta = thinc_beta;
    // the profile's mean is increasing in d: Newton within a bracket where
    // the profile is below 1e-6 (above 1 - 1e-6) in the whole cell
    // the curved profile: P(s) = n.s + c |s_t|^2 follows the level set of
    // a unit-normal field of divergence div n to second order, c =
    // h div n / (2 (dim - 1)) (a disc of radius R, n inwards: c = -h/2R);
    // radii below a cell are not resolved and are cut off there
    double h_mean = 1.;
    for (unsigned int c = 0; c < dim; ++c)
      h_mean *= h[c];
    h_mean = std::pow(h_mean, 1. / dim);
    const double curve = std::clamp(0.5 * h_mean * divergence / (dim - 1), -0.5, 0.5);
    std::array<double, 64> projection; // at most QGauss<3>(4)
    for (unsigned int q = 0; q < profile_points.size(); ++q)
      {
        double sn = 0., s2 = 0.;
        for (unsigned int c = 0; c < dim; ++c)
          {
            const double sc = profile_points[q][c] - 0.5;
            sn += n[c] * sc;
            s2 += sc * sc;
          }
        projection[q] = sn + curve * (s2 - sn * sn);
      }
    const double reach = 1. + std::abs(curve) * dim / 4. + 8. / beta;
    double       lo = -reach, hi = reach;
    // start from the exact offset of a profile normal to a cell face, whose
    // mean is 1/2 + ln(cosh(beta (d + 1/2)) / cosh(beta (d - 1/2))) / (2 beta)
    const double q = std::exp(beta * (2. * mean - 1.)), b = std::exp(beta);
    double       d = std::clamp(std::log((1. - q * b) / (q - b)) / (2. * beta), lo, hi);
    // 1/2 (1 + tanh(beta (P + d))) = 1 / (1 + exp(-2 beta P) exp(-2 beta d)):
    // one exp per iteration instead of a tanh per point; the exponents are
    // clamped where the profile is saturated to 1e-130 anyway, so that the
    // product can neither overflow nor be 0 times infinity at large beta
    const auto exp_clamped = [](const double x) { return std::exp(std::clamp(x, -300., 300.)); };
    std::array<double, 64> exp_projection;
    for (unsigned int q = 0; q < profile_points.size(); ++q)
      exp_projection[q] = exp_clamped(-2. * beta * projection[q]);
    for (unsigned int iteration = 0; iteration < 60; ++iteration)
      {
        double       f = -mean, df = 0.;
        const double E = exp_clamped(-2. * beta * d);
        for (unsigned int q = 0; q < profile_points.size(); ++q)
          {
            const double H = 1. / (1. + exp_projection[q] * E);
            f += profile_weights[q] * H;
            df += profile_weights[q] * 2. * beta * H * (1. - H);
          }
        if (std::abs(f) < 1e-14)
          break;
        (f > 0. ? hi : lo) = d;
        const double newton = d - f / df;
        d = (df > 0. && newton > lo && newton < hi) ? newton : 0.5 * (lo + hi);
        if (hi - lo < 1e-15)
          break;
      }
    // beta (n.(xi - 1/2) + d) with xi = (x - x0) / h, as slope.x + offset
    const double s = std::min(1., (margin - tiny) / tiny);
    r.weight       = s * s * (3. - 2. * s);
    r.curvature    = beta * curve;
    r.offset       = beta * d;
    for (unsigned int c = 0; c < dim; ++c)
      {
        r.slope[c] = beta * n[c] / h[c];
        r.offset -= beta * n[c] * (x0[c] / h[c] + 0.5);
      }
    return r;
  }

  template <int dim>
  void TransportOperator<dim>::compute_reconstruction(const VectorType &src) const
  {
    const unsigned int n_lanes  = VectorizedArray<double>::size();
    const unsigned int n_owned  = matrix_free.n_cell_batches();
    const unsigned int n_ghosts = matrix_free.n_ghost_cell_batches();
    const unsigned int n_dofs   = mean_weights.size();
    // the DoF indices of phi in a cell (lexicographic, as FE_DGQ numbers
    // them), global and local to the vectors of the MatrixFree
    const types::global_dof_index *phi_indices = nullptr;
    const unsigned int            *phi_local   = nullptr;
    const auto phi_dofs = [&](const unsigned int cell, const unsigned int v) {
      phi_indices = &lane_phi_dofs[(cell * n_lanes + v) * n_dofs];
      phi_local   = &lane_phi_local[(cell * n_lanes + v) * n_dofs];
    };

    // 1. cell means
    std::fill(cell_mean.begin(), cell_mean.end(), 0.);
    FEEvaluation<dim, -1, 0, 1, double> phi(matrix_free, 0, 0, 0);
    for (unsigned int cell = 0; cell < n_owned; ++cell)
      {
        phi.reinit(cell);
        phi.read_dof_values_plain(src);
        for (unsigned int v = 0; v < matrix_free.n_active_entries_per_cell_batch(cell); ++v)
          for (unsigned int i = 0; i < n_dofs; ++i)
            cell_mean[cell * n_lanes + v] += mean_weights[i] * phi.begin_dof_values()[i][v];
      }
    // 2. the normal (Youngs): the mean gradient of the multilinear
    // interpolant of the vertex averages of the cell means, a 3^dim
    // stencil, as VOF schemes take it from the neighbours. The DG slope of
    // a cell whose polynomial the profile's fluxes update is no reliable
    // direction (it turned the profile of a translated band around).
    constexpr unsigned int n_vertices = GeometryInfo<dim>::vertices_per_cell;
    std::fill(vertex_mean.begin(), vertex_mean.end(), 0.);
    std::fill(vertex_weight.begin(), vertex_weight.end(), 0.);
    for (unsigned int cell = 0; cell < n_owned; ++cell)
      for (unsigned int v = 0; v < matrix_free.n_active_entries_per_cell_batch(cell); ++v)
        {
          const unsigned int k = cell * n_lanes + v;
          for (unsigned int i = 0; i < n_vertices; ++i)
            {
              vertex_mean[cell_vertices[k * n_vertices + i]] += cell_volume[k] * cell_mean[k];
              vertex_weight[cell_vertices[k * n_vertices + i]] += cell_volume[k];
            }
        }
    // the ghost layer (all cells that share a vertex with an owned one)
    if (!ghost_layer_volume.empty())
      {
        ghost_layer_values.copy_locally_owned_data_from(src);
        ghost_layer_values.update_ghost_values();
        for (std::size_t g = 0; g < ghost_layer_volume.size(); ++g)
          {
            double mean = 0.;
            for (unsigned int i = 0; i < n_dofs; ++i)
              mean += mean_weights[i] * ghost_layer_values(ghost_layer_dofs[g * n_dofs + i]);
            for (unsigned int i = 0; i < n_vertices; ++i)
              {
                vertex_mean[ghost_layer_vertices[g * n_vertices + i]] += ghost_layer_volume[g] * mean;
                vertex_weight[ghost_layer_vertices[g * n_vertices + i]] += ghost_layer_volume[g];
              }
          }
        ghost_layer_values.zero_out_ghost_values();
      }

    // the gradient (integral over the unit cell) of an owned cell
    const auto unit_gradient = [&](const unsigned int k) {
      Tensor<1, dim> gradient;
      for (unsigned int i = 0; i < n_vertices; ++i)
        {
          const unsigned int vertex = cell_vertices[k * n_vertices + i];
          const double       value  = vertex_mean[vertex] / vertex_weight[vertex];
          for (unsigned int c = 0; c < dim; ++c)
            gradient[c] += ((i >> c) & 1 ? value : -value) / (n_vertices / 2);
        }
      return gradient;
    };
    // 2b. for the curved profile, div n: the unit normals of the cells
    // (owned, then the ghost layer through a vector with all locally
    // relevant DoFs), averaged at the vertices; div n of a cell is the
    // divergence of the multilinear interpolant of its vertex normals
    if (thinc_curved)
      {
        std::fill(vertex_normal.begin(), vertex_normal.end(), Tensor<1, dim>());
        const auto add_to_vertices = [&](const unsigned int *vertices, const double volume,
                                         const Tensor<1, dim> &normal) {
          for (unsigned int i = 0; i < n_vertices; ++i)
            vertex_normal[vertices[i]] += volume * normal;
        };
        const bool exchange = !ghost_layer_volume.empty();
        if (exchange)
          normal_values = 0.;
        for (unsigned int cell = 0; cell < n_owned; ++cell)
          for (unsigned int v = 0; v < matrix_free.n_active_entries_per_cell_batch(cell); ++v)
            {
              const unsigned int k = cell * n_lanes + v;
              Tensor<1, dim>     g = unit_gradient(k);
              for (unsigned int c = 0; c < dim; ++c)
                g[c] /= cell_extent[k][c];
              if (g.norm() < 1e-8 / std::pow(cell_volume[k], 1. / dim))
                continue;
              const Tensor<1, dim> normal = g / g.norm();
              add_to_vertices(&cell_vertices[k * n_vertices], cell_volume[k], normal);
              if (exchange)
                {
                  phi_dofs(cell, v);
                  for (unsigned int c = 0; c < dim; ++c)
                    normal_values(phi_indices[c]) = normal[c];
                }
            }
        if (exchange)
          {
            normal_values.update_ghost_values();
            for (std::size_t g = 0; g < ghost_layer_volume.size(); ++g)
              {
                Tensor<1, dim> normal;
                for (unsigned int c = 0; c < dim; ++c)
                  normal[c] = normal_values(ghost_layer_dofs[g * n_dofs + c]);
                if (normal.norm() > 0.)
                  add_to_vertices(&ghost_layer_vertices[g * n_vertices], ghost_layer_volume[g], normal);
              }
            normal_values.zero_out_ghost_values();
          }
      }
    const auto divergence_of_normals = [&](const unsigned int k) {
      double divergence = 0.;
      for (unsigned int i = 0; i < n_vertices; ++i)
        {
          const Tensor<1, dim> &sum = vertex_normal[cell_vertices[k * n_vertices + i]];
          const double          norm = sum.norm();
          if (norm == 0.)
            return 0.; // a vertex without a normal: no curvature
          for (unsigned int c = 0; c < dim; ++c)
            divergence += ((i >> c) & 1 ? sum[c] : -sum[c]) / norm / (n_vertices / 2) /
                          cell_extent[k][c];
        }
      return divergence;
    };

    // 3. the profiles of the owned cells; the ghost cells receive theirs
    // through the phi DoFs of a scratch vector
    for (unsigned int cell = 0; cell < n_owned; ++cell)
      for (unsigned int v = 0; v < matrix_free.n_active_entries_per_cell_batch(cell); ++v)
        {
          const unsigned int k        = cell * n_lanes + v;
          const Tensor<1, dim> gradient = unit_gradient(k);
          const double divergence =
            thinc_curved && cell_mean[k] > 1e-6 && cell_mean[k] < 1. - 1e-6 ? divergence_of_normals(k) : 0.;
          reconstruction[cell][v] =
            reconstruct(cell_mean[k], gradient, cell_corner[k], cell_extent[k], divergence);
          reconstruction[cell][v].lower = cell_corner[k];
          reconstruction[cell][v].upper = cell_corner[k] + cell_extent[k];
        }
    if (n_ghosts == 0)
      return;
    ghosted = 0.;
    if (thinc_curved)
      ghosted_curvature = 0.;
    for (unsigned int cell = 0; cell < n_owned; ++cell)
      for (unsigned int v = 0; v < matrix_free.n_active_entries_per_cell_batch(cell); ++v)
        if (const auto &r = reconstruction[cell][v]; r.weight > 0.)
          {
            phi_dofs(cell, v);
            if (thinc_curved)
              ghosted_curvature.local_element(phi_local[0]) = r.curvature;
            ghosted.local_element(phi_local[0]) = r.weight;
            ghosted.local_element(phi_local[1]) = r.offset;
            for (unsigned int c = 0; c < dim; ++c)
              ghosted.local_element(phi_local[2 + c]) = r.slope[c];
          }
    ghosted.update_ghost_values();
    if (thinc_curved)
      ghosted_curvature.update_ghost_values();
    for (unsigned int cell = n_owned; cell < n_owned + n_ghosts; ++cell)
      for (unsigned int v = 0; v < matrix_free.n_active_entries_per_cell_batch(cell); ++v)
        {
          phi_dofs(cell, v);
          auto &r  = reconstruction[cell][v];
          r.lower  = cell_corner[cell * n_lanes + v];
          r.upper  = cell_corner[cell * n_lanes + v] + cell_extent[cell * n_lanes + v];
          r.weight    = ghosted.local_element(phi_local[0]);
          r.curvature = thinc_curved ? ghosted_curvature.local_element(phi_local[0]) : 0.;
          r.offset = ghosted.local_element(phi_local[1]);
          for (unsigned int c = 0; c < dim; ++c)
            r.slope[c] = ghosted.local_element(phi_local[2 + c]);
        }
    ghosted.zero_out_ghost_values();
    if (thinc_curved)
      ghosted_curvature.zero_out_ghost_values();
  }

  template <int dim>
  bool TransportOperator<dim>::project_to_profiles(VectorType &solution) const
  {
    if (!(thinc_beta > 0.))
      return false;
    compute_reconstruction(solution);
    // the L2 projection of each profile onto Q_k (k + 1 Gauss points per
    // direction), shifted by a constant so that the cell mean is kept to
    // round-off (the profile's mean is exact only in its own quadrature)
    FEEvaluation<dim, -1, 0, 1, double> phi(matrix_free, 0, 1, 0);
    MatrixFreeOperators::CellwiseInverseMassMatrix<dim, -1, 1, double> inverse(phi);
    AlignedVector<VA> values(phi.n_q_points);
    std::vector<VA>   old_dofs(phi.dofs_per_cell);
    for (unsigned int cell = 0; cell < matrix_free.n_cell_batches(); ++cell)
      {
        bool any = false;
        for (unsigned int v = 0; v < matrix_free.n_active_entries_per_cell_batch(cell); ++v)
          any = any || reconstruction[cell][v].weight > 0.;
        if (!any)
          continue;
        phi.reinit(cell);
        phi.read_dof_values_plain(solution);
        for (unsigned int i = 0; i < phi.dofs_per_cell; ++i)
          old_dofs[i] = phi.begin_dof_values()[i];
        phi.evaluate(EvaluationFlags::values);
        for (const unsigned int q : phi.quadrature_point_indices())
          values[q] = seen_phi<dim>(reconstruction[cell], phi.quadrature_point(q), phi.get_value(q));
        inverse.transform_from_q_points_to_basis(1, values.data(), phi.begin_dof_values());
        for (unsigned int v = 0; v < matrix_free.n_active_entries_per_cell_batch(cell); ++v)
          {
            double new_mean = 0.;
            for (unsigned int i = 0; i < phi.dofs_per_cell; ++i)
              new_mean += mean_weights[i] * phi.begin_dof_values()[i][v];
            const double shift =
              cell_mean[cell * VA::size() + v] - new_mean;
            for (unsigned int i = 0; i < phi.dofs_per_cell; ++i)
              phi.begin_dof_values()[i][v] = reconstruction[cell][v].weight > 0. ?
                                               phi.begin_dof_values()[i][v] + shift :
                                               old_dofs[i][v];
          }
        phi.set_dof_values_plain(solution);
      }
    return true;
  }

  template <int dim>
  double TransportOperator<dim>::face_jumps(const VectorType &solution, const double touches) const
  {
    face_scratch.copy_locally_owned_data_from(solution);
    face_scratch.update_ghost_values();
    // quadrature 1: k + 1 Gauss points
    FEFaceEvaluation<dim, -1, 0, 1, double> phi_m(matrix_free, true, 0, 1, 0);
    FEFaceEvaluation<dim, -1, 0, 1, double> phi_p(matrix_free, false, 0, 1, 0);
    const unsigned int n_lanes = VA::size();
    const auto touching = [&](const auto &phi, const unsigned int v) {
      for (unsigned int i = 0; i < phi.dofs_per_cell; ++i)
        if (phi.begin_dof_values()[i][v] > touches)
          return true;
      return false;
    };
    double total = 0.;
    for (unsigned int face = 0; face < matrix_free.n_inner_face_batches(); ++face)
      {
        phi_m.reinit(face);
        phi_p.reinit(face);
        // the whole cells' values: the touch test reads every node
        phi_m.read_dof_values(face_scratch);
        phi_p.read_dof_values(face_scratch);
        bool any = false;
        std::array<bool, VA::size()> counts{};
        for (unsigned int v = 0; v < matrix_free.n_active_entries_per_face_batch(face); ++v)
          {
            counts[v] = !periodic_face_lane[face * n_lanes + v] &&
                        (touching(phi_m, v) || touching(phi_p, v));
            any = any || counts[v];
          }
        if (!any)
          continue;
        phi_m.evaluate(EvaluationFlags::values);
        phi_p.evaluate(EvaluationFlags::values);
        for (unsigned int v = 0; v < n_lanes; ++v)
          if (counts[v])
            for (const unsigned int q : phi_m.quadrature_point_indices())
              total += std::abs(phi_m.get_value(q)[v] - phi_p.get_value(q)[v]) * phi_m.JxW(q)[v];
      }
    face_scratch.zero_out_ghost_values();
    return total;
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
  void TransportOperator<dim>::mark_solid_cells(const VectorType &solution)
  {
    if (!with_B)
      return;
    constexpr double   threshold = 1e-8;
    const unsigned int n_lanes   = VectorizedArray<double>::size();
    const auto        &tria      = matrix_free.get_dof_handler(0).get_triangulation();
    // 1. cells that hold solid (owned), then their owners' marks on the ghosts
    std::vector<unsigned char> holds(tria.n_active_cells(), 0), marked;
    FEEvaluation<dim, -1, 0, 1, double> phi(matrix_free, 0, 0, 0);
    for (unsigned int cell = 0; cell < matrix_free.n_cell_batches(); ++cell)
      {
        phi.reinit(cell);
        phi.read_dof_values_plain(solution);
        for (unsigned int v = 0; v < matrix_free.n_active_entries_per_cell_batch(cell); ++v)
          for (unsigned int i = 0; i < phi.dofs_per_cell; ++i)
            if (phi.begin_dof_values()[i][v] > threshold)
              {
                holds[lane_cell_index[cell * n_lanes + v]] = 1;
                break;
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
    for (unsigned int cell = 0; cell < b_active.size(); ++cell)
      for (unsigned int v = 0; v < n_lanes; ++v)
        {
          const unsigned int index = lane_cell_index[cell * n_lanes + v];
          b_active[cell][v] = (index != numbers::invalid_unsigned_int && marked[index]) ? 1. : 0.;
        }
  }

  template <int dim>
  void TransportOperator<dim>::apply(const VectorType &src,
                                     VectorType       &dst,
                                     const VectorType &velocity,
                                     double           *boundary_flux) const
  {
    using Range = std::pair<unsigned int, unsigned int>;
    using Operation =
      std::function<void(const MatrixFree<dim, double> &, VectorType &, const VectorType &, const Range &)>;
    const bool compress         = compression > 0.;
    // B only in the cells mark_solid_cells() marked; I outside
    Tensor<1, n_B, VA> identity;
    for (unsigned int d = 0; d < dim; ++d)
      identity[d] = 1.; // unrolled order starts with the diagonal
    const bool thinc            = thinc_beta > 0.;
    if (thinc)
      compute_reconstruction(src);
    const double k              = matrix_free.get_dof_handler(0).get_fe().degree;
    constexpr double penalty    = 2.;
    const auto compression_flux = [this](const VA &phi, const Tensor<1, dim, VA> &grad,
                                         const Tensor<1, dim, VA> &velocity) {
      // c |u| phi (1 - phi) grad phi / |grad phi|, zero where phi is flat
      // or outside (0, 1)
      Tensor<1, dim, VA> flux;
      const VA           norm = grad.norm();
      for (unsigned int v = 0; v < VA::size(); ++v)
        {
          const double p = std::clamp(phi[v], 0., 1.);
          if (norm[v] <= 1e-12 || p <= 0. || p >= 1.)
            continue;
          const double scale = compression * velocity.norm()[v] * p * (1. - p) / norm[v];
          for (unsigned int d = 0; d < dim; ++d)
            flux[d][v] = scale * grad[d][v];
        }
      return flux;
    };

    const Operation cell_op = [&](const MatrixFree<dim, double> &mf, VectorType &out,
                             const VectorType &in, const Range &range) {
      FEEvaluation<dim, -1, 0, 1, double>   phi(mf, range, 0, 0, 0);
      FEEvaluation<dim, -1, 0, dim, double> u(mf, range, 1, 0);
      std::unique_ptr<FEEvaluation<dim, -1, 0, n_B, double>> b_ptr;
      if (with_B)
        b_ptr = std::make_unique<FEEvaluation<dim, -1, 0, n_B, double>>(mf, range, 0, 0, 1);
      for (unsigned int cell = range.first; cell < range.second; ++cell)
        {
          u.reinit(cell);
          u.read_dof_values_plain(velocity);
          u.evaluate(EvaluationFlags::values | EvaluationFlags::gradients);
          phi.reinit(cell);
          phi.gather_evaluate(in, compress ? EvaluationFlags::values | EvaluationFlags::gradients :
                                             EvaluationFlags::values);
          Lanes profile;
          if (thinc)
            profile = phi.read_cell_data(reconstruction);
          for (const unsigned int q : phi.quadrature_point_indices())
            {
              const VA phi_q = thinc ? seen_phi<dim>(profile, phi.quadrature_point(q), phi.get_value(q)) :
                                       phi.get_value(q);
              Tensor<1, dim, VA> flux = u.get_value(q) * phi_q;
              if (compress)
                flux += compression_flux(phi.get_value(q), phi.get_gradient(q), u.get_value(q)) -
                        (thickness * compression * cell_size[cell] * u.get_value(q).norm()) *
                          phi.get_gradient(q);
              phi.submit_gradient(flux, q);
            }
          phi.integrate_scatter(EvaluationFlags::gradients, out);
          if (!with_B || !any_lane(b_active[cell]))
            continue;
          const VA active = b_active[cell];
          auto    &b      = *b_ptr;
          b.reinit(cell);
          b.gather_evaluate(in, EvaluationFlags::values);
          for (const unsigned int q : b.quadrature_point_indices())
            {
              const auto velocity_q = u.get_value(q);
              const auto grad_u     = u.get_gradient(q);
              const auto bq         = b.get_value(q);
              const auto B          = Tensor<2, dim, VA>(to_tensor<dim>(bq));
              const auto source =
                trace(grad_u) * B + grad_u * B + B * transpose(grad_u);
              Tensor<1, n_B, Tensor<1, dim, VA>> flux;
              for (unsigned int c = 0; c < n_B; ++c)
                flux[c] = velocity_q * (bq[c] * active);
              b.submit_gradient(flux, q);
              b.submit_value(to_vector<dim>(source) * active, q);
            }
          b.integrate_scatter(EvaluationFlags::values | EvaluationFlags::gradients, out);
        }
    };

    const Operation face_op = [&](const MatrixFree<dim, double> &mf, VectorType &out,
                             const VectorType &in, const Range &range) {
      FEFaceEvaluation<dim, -1, 0, 1, double>   phi_m(mf, range, true, 0, 0, 0);
      FEFaceEvaluation<dim, -1, 0, 1, double>   phi_p(mf, range, false, 0, 0, 0);
      FEFaceEvaluation<dim, -1, 0, dim, double> u(mf, range, true, 1, 0);
      using FaceB = FEFaceEvaluation<dim, -1, 0, n_B, double>;
      std::unique_ptr<FaceB> bm_ptr, bp_ptr;
      if (with_B)
        {
          bm_ptr = std::make_unique<FaceB>(mf, range, true, 0, 0, 1);
          bp_ptr = std::make_unique<FaceB>(mf, range, false, 0, 0, 1);
        }
      for (unsigned int face = range.first; face < range.second; ++face)
        {
          u.reinit(face);
          u.read_dof_values_plain(velocity);
          u.evaluate(EvaluationFlags::values);
          phi_m.reinit(face);
          phi_p.reinit(face);
          const auto flags = compress ? EvaluationFlags::values | EvaluationFlags::gradients :
                                        EvaluationFlags::values;
          phi_m.gather_evaluate(in, flags);
          phi_p.gather_evaluate(in, flags);
          Lanes profile_m, profile_p;
          if (thinc)
            {
              profile_m = phi_m.read_cell_data(reconstruction);
              profile_p = phi_p.read_cell_data(reconstruction);
            }
          for (const unsigned int q : phi_m.quadrature_point_indices())
            {
              const auto &n    = phi_m.get_normal_vector(q);
              const VA    un   = u.get_value(q) * n;
              VA          flux = thinc ? upwind(un,
                                       seen_phi<dim>(profile_m, phi_m.quadrature_point(q), phi_m.get_value(q)),
                                       seen_phi<dim>(profile_p, phi_m.quadrature_point(q), phi_p.get_value(q))) :
                                upwind(un, phi_m.get_value(q), phi_p.get_value(q));
              if (compress)
                {
                  // Lax-Friedrichs: the speed of c |u| phi (1 - phi) is at most c |u|
                  const VA speed = compression * u.get_value(q).norm();
                  flux += 0.5 * (compression_flux(phi_m.get_value(q), phi_m.get_gradient(q),
                                                  u.get_value(q)) +
                                 compression_flux(phi_p.get_value(q), phi_p.get_gradient(q),
                                                  u.get_value(q))) * n +
                          0.5 * speed * (phi_m.get_value(q) - phi_p.get_value(q));
                  // the diffusion eps c |u| grad phi that holds the profile
                  // at a width eps against the compression (incomplete
                  // interior penalty)
                  const VA kappa = thickness * compression * face_size[face] * u.get_value(q).norm();
                  const VA sigma = penalty * (k + 1.) * (k + 1.) / face_size[face];
                  flux += kappa * (-0.5 * (phi_m.get_gradient(q) + phi_p.get_gradient(q)) * n +
                                   sigma * (phi_m.get_value(q) - phi_p.get_value(q)));
                }
              phi_m.submit_value(-flux, q);
              phi_p.submit_value(flux, q);
            }
          phi_m.integrate_scatter(EvaluationFlags::values, out);
          phi_p.integrate_scatter(EvaluationFlags::values, out);
          if (!with_B)
            continue;
          auto &b_m = *bm_ptr;
          auto &b_p = *bp_ptr;
          b_m.reinit(face);
          b_p.reinit(face);
          // a side whose cell is not marked holds B = I and takes nothing
          const VA   active_m = b_m.read_cell_data(b_active);
          const VA   active_p = b_p.read_cell_data(b_active);
          const bool inside = any_lane(active_m), outside = any_lane(active_p);
          if (!inside && !outside)
            continue;
          if (inside)
            b_m.gather_evaluate(in, EvaluationFlags::values);
          if (outside)
            b_p.gather_evaluate(in, EvaluationFlags::values);
          for (const unsigned int q : b_m.quadrature_point_indices())
            {
              const VA   un  = u.get_value(q) * b_m.get_normal_vector(q);
              const auto b_q = [&](const auto &b, const bool any, const VA &active) {
                return any ? b.get_value(q) * active + identity * (1. - active) : identity;
              };
              const auto flux =
                upwind(un, b_q(b_m, inside, active_m), b_q(b_p, outside, active_p));
              if (inside)
                b_m.submit_value(-flux * active_m, q);
              if (outside)
                b_p.submit_value(flux * active_p, q);
            }
          if (inside)
            b_m.integrate_scatter(EvaluationFlags::values, out);
          if (outside)
            b_p.integrate_scatter(EvaluationFlags::values, out);
        }
    };

    const Operation boundary_op = [&](const MatrixFree<dim, double> &mf, VectorType &out,
                                 const VectorType &in, const Range &range) {
      FEFaceEvaluation<dim, -1, 0, 1, double>   phi(mf, range, true, 0, 0, 0);
      FEFaceEvaluation<dim, -1, 0, dim, double> u(mf, range, true, 1, 0);
      using FaceB = FEFaceEvaluation<dim, -1, 0, n_B, double>;
      std::unique_ptr<FaceB> b_ptr;
      if (with_B)
        b_ptr = std::make_unique<FaceB>(mf, range, true, 0, 0, 1);
      for (unsigned int face = range.first; face < range.second; ++face)
        {
          u.reinit(face);
          u.read_dof_values_plain(velocity);
          u.evaluate(EvaluationFlags::values);
          phi.reinit(face);
          phi.gather_evaluate(in, EvaluationFlags::values);
          Lanes profile;
          if (thinc)
            profile = phi.read_cell_data(reconstruction);
          VA outflow = 0.;
          for (const unsigned int q : phi.quadrature_point_indices())
            {
              const VA un   = u.get_value(q) * phi.get_normal_vector(q);
              const VA phi_q = thinc ? seen_phi<dim>(profile, phi.quadrature_point(q), phi.get_value(q)) :
                                       phi.get_value(q);
              const VA flux = upwind(un, phi_q, VA(0.));
              phi.submit_value(-flux, q);
              outflow += flux * phi.JxW(q);
            }
          phi.integrate_scatter(EvaluationFlags::values, out);
          if (boundary_flux)
            for (unsigned int v = 0; v < mf.n_active_entries_per_face_batch(face); ++v)
              *boundary_flux += outflow[v];
          if (!with_B)
            continue;
          auto &b = *b_ptr;
          b.reinit(face);
          const VA active = b.read_cell_data(b_active);
          if (!any_lane(active))
            continue;
          b.gather_evaluate(in, EvaluationFlags::values);
          for (const unsigned int q : b.quadrature_point_indices())
            {
              const VA un = u.get_value(q) * b.get_normal_vector(q);
              b.submit_value(-upwind(un, b.get_value(q), identity) * active, q);
            }
          b.integrate_scatter(EvaluationFlags::values, out);
        }
    };

    const auto access = compress ? MatrixFree<dim, double>::DataAccessOnFaces::gradients :
                                   MatrixFree<dim, double>::DataAccessOnFaces::values;
    matrix_free.loop(cell_op, face_op, boundary_op, dst, src, true, access, access);

    // dst <- M^{-1} dst, cell by cell (exact for FE_DGQ on affine cells)
    const Operation inverse_mass = [&](const MatrixFree<dim, double> &mf, VectorType &out,
                                       const VectorType &in, const Range &range) {
        using CellB = FEEvaluation<dim, -1, 0, n_B, double>;
        using InverseB = MatrixFreeOperators::CellwiseInverseMassMatrix<dim, -1, n_B, double>;
        FEEvaluation<dim, -1, 0, 1, double> phi(mf, range, 0, 1, 0);
        MatrixFreeOperators::CellwiseInverseMassMatrix<dim, -1, 1, double> inverse_phi(phi);
        std::unique_ptr<CellB>    b_ptr;
        std::unique_ptr<InverseB> inverse_b_ptr;
        if (with_B)
          {
            b_ptr         = std::make_unique<CellB>(mf, range, 0, 1, 1);
            inverse_b_ptr = std::make_unique<InverseB>(*b_ptr);
          }
        for (unsigned int cell = range.first; cell < range.second; ++cell)
          {
            phi.reinit(cell);
            phi.read_dof_values(in);
            inverse_phi.apply(phi.begin_dof_values(), phi.begin_dof_values());
            phi.set_dof_values(out);
            if (!with_B || !any_lane(b_active[cell]))
              continue;
            auto &b = *b_ptr;
            b.reinit(cell);
            b.read_dof_values(in);
            inverse_b_ptr->apply(b.begin_dof_values(), b.begin_dof_values());
            b.set_dof_values(out);
          }
      };
    matrix_free.cell_loop(inverse_mass, dst, dst);
  }

  template <int dim>
  LimiterReport TransportOperator<dim>::limit(VectorType &solution, const bool scale) const
  {
    LimiterReport                       report;
    FEEvaluation<dim, -1, 0, 1, double> phi(matrix_free, 0, 0, 0);
    const unsigned int                  n_batches = matrix_free.n_cell_batches();
    const unsigned int                  n_lanes   = VectorizedArray<double>::size();

    // Pass 1: cell means and volumes. A mean outside [0, 1] (possible where
    // the discrete velocity is not divergence-free) cannot be fixed by
    // scaling within the cell: it is clipped, and the clipped mass is given
    // back to interface cells in proportion to mean (1 - mean), so that
    // the total is conserved to round-off.
    std::vector<double> mean(n_batches * n_lanes, 0.), volume(n_batches * n_lanes, 0.);
    double              excess = 0., capacity = 0.;
    for (unsigned int cell = 0; cell < n_batches; ++cell)
      {
        phi.reinit(cell);
        phi.read_dof_values(solution);
        phi.evaluate(EvaluationFlags::values);
        for (unsigned int v = 0; v < matrix_free.n_active_entries_per_cell_batch(cell); ++v)
          {
            double integral = 0., vol = 0.;
            for (const unsigned int q : phi.quadrature_point_indices())
              {
                integral += phi.get_value(q)[v] * phi.JxW(q)[v];
                vol += phi.JxW(q)[v];
              }
            const unsigned int k = cell * n_lanes + v;
            mean[k]   = integral / vol;
            volume[k] = vol;
            if (mean[k] < 0. || mean[k] > 1.)
              {
                ++report.out_of_bound_means;
                const double clipped = std::min(1., std::max(0., mean[k]));
                excess += (mean[k] - clipped) * vol;
              }
            else
              capacity += mean[k] * (1. - mean[k]) * vol;
          }
      }
    // one reduction instead of three (the limiter runs after every stage)
    const MPI_Comm comm     = matrix_free.get_dof_handler(0).get_communicator();
    const double   local[3] = {excess, capacity, double(report.out_of_bound_means)};
    double         global[3];
    Utilities::MPI::sum(ArrayView<const double>(local, 3), comm, ArrayView<double>(global, 3));
    excess                  = global[0];
    capacity                = global[1];
    const bool   redistribute = scale && global[2] > 0.;
    const double lambda       = (redistribute && capacity > 0.) ? excess / capacity : 0.;

    // Pass 2: new means, then Zhang-Shu scaling towards them.
    for (unsigned int cell = 0; cell < n_batches; ++cell)
      {
        phi.reinit(cell);
        phi.read_dof_values(solution);
        phi.evaluate(EvaluationFlags::values);
        bool changed = false;
        for (unsigned int v = 0; v < matrix_free.n_active_entries_per_cell_batch(cell); ++v)
          {
            const unsigned int k        = cell * n_lanes + v;
            const double       old_mean = mean[k];
            double             target   = old_mean;
            if (redistribute)
              target = (old_mean < 0. || old_mean > 1.) ?
                         std::min(1., std::max(0., old_mean)) :
                         old_mean + lambda * old_mean * (1. - old_mean);
            double lo = 1e300, hi = -1e300;
            for (const unsigned int q : phi.quadrature_point_indices())
              {
                lo = std::min(lo, phi.get_value(q)[v] - old_mean + target);
                hi = std::max(hi, phi.get_value(q)[v] - old_mean + target);
              }
            for (unsigned int i = 0; i < phi.dofs_per_cell; ++i)
              {
                lo = std::min(lo, phi.begin_dof_values()[i][v] - old_mean + target);
                hi = std::max(hi, phi.begin_dof_values()[i][v] - old_mean + target);
              }
            // the mean of a Lagrange field moves by adding a constant
            double theta = 1.;
            if (hi > 1. && hi > target)
              theta = std::min(theta, std::max(0., 1. - target) / (hi - target));
            if (lo < 0. && lo < target)
              theta = std::min(theta, std::max(0., target) / (target - lo));
            if (scale && (theta < 1. || target != old_mean))
              {
                if (theta < 1.)
                  ++report.limited_cells;
                changed = true;
                for (unsigned int i = 0; i < phi.dofs_per_cell; ++i)
                  phi.begin_dof_values()[i][v] =
                    target + theta * (phi.begin_dof_values()[i][v] - old_mean);
                lo = target + theta * (lo - target);
                hi = target + theta * (hi - target);
              }
            report.min_phi = std::min(report.min_phi, lo);
            report.max_phi = std::max(report.max_phi, hi);
          }
        if (changed)
          phi.set_dof_values(solution);
      }
    return report;
  }

  template <int dim>
  unsigned int TransportOperator<dim>::limit_B(VectorType &solution) const
  {
    if (!with_B)
      return 0;
    unsigned int                          n_limited = 0;
    FEEvaluation<dim, -1, 0, n_B, double> b(matrix_free, 0, 0, 1);
    const auto smallest = [](const Tensor<1, n_B, VA> &t, const unsigned int v) {
      SymmetricTensor<2, dim> B;
      for (unsigned int c = 0; c < n_B; ++c)
        B[SymmetricTensor<2, dim>::unrolled_to_component_indices(c)] = t[c][v];
      return smallest_eigenvalue(B);
    };
    for (unsigned int cell = 0; cell < matrix_free.n_cell_batches(); ++cell)
      {
        if (!any_lane(b_active[cell])) // elsewhere B = I
          continue;
        b.reinit(cell);
        b.read_dof_values(solution);
        b.evaluate(EvaluationFlags::values);
        bool changed = false;
        for (unsigned int v = 0; v < matrix_free.n_active_entries_per_cell_batch(cell); ++v)
          {
            Tensor<1, n_B, VA> mean;
            double             volume = 0.;
            for (const unsigned int q : b.quadrature_point_indices())
              {
                mean += b.get_value(q) * b.JxW(q)[v];
                volume += b.JxW(q)[v];
              }
            mean /= volume;
            const double lambda_mean = smallest(mean, v);
            if (!(lambda_mean > 0.))
              continue; // nothing a scaling can do; the SPD check reports it
            // keep at least a tenth of the mean's smallest eigenvalue
            const double floor = 0.1 * lambda_mean;
            double       theta = 1.;
            const auto   consider = [&](const double lambda) {
              if (lambda < floor)
                theta = std::min(theta, (lambda_mean - floor) / (lambda_mean - lambda));
            };
            for (const unsigned int q : b.quadrature_point_indices())
              consider(smallest(b.get_value(q), v));
            const unsigned int n_nodes = b.dofs_per_component;
            for (unsigned int i = 0; i < n_nodes; ++i)
              {
                Tensor<1, n_B, VA> node;
                for (unsigned int c = 0; c < n_B; ++c)
                  node[c] = b.begin_dof_values()[c * n_nodes + i];
                consider(smallest(node, v));
              }
            if (theta < 1.)
              {
                ++n_limited;
                changed = true;
                for (unsigned int c = 0; c < n_B; ++c)
                  for (unsigned int i = 0; i < n_nodes; ++i)
                    {
                      auto &value = b.begin_dof_values()[c * n_nodes + i][v];
                      value       = mean[c][v] + theta * (value - mean[c][v]);
                    }
              }
          }
        if (changed)
          b.set_dof_values(solution);
      }
    return n_limited;
  }

  template class TransportOperator<2>;
  template class TransportOperator<3>;
} // namespace Suspension::Solid
