// TransportOperator: the THINC sub-cell profile of phi in interface cells
// (reconstruction, projection to the profiles) and the face jumps of phi.
#include <deal.II/base/bounding_box.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/dofs/dof_tools.h>
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
    // what the neighbours on other ranks receive: value j of a lane's cell
    const bool exchange = !ghost_layer_volume.empty();
    const auto cell_value = [&](const unsigned int j, const unsigned int cell,
                                const unsigned int v) -> double & {
      return cell_exchange[j](lane_global_cell[cell * n_lanes + v]);
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
    if (exchange)
      {
        for (unsigned int cell = 0; cell < n_owned; ++cell)
          for (unsigned int v = 0; v < matrix_free.n_active_entries_per_cell_batch(cell); ++v)
            cell_value(0, cell, v) = cell_mean[cell * n_lanes + v];
        cell_exchange[0].update_ghost_values();
        for (std::size_t g = 0; g < ghost_layer_volume.size(); ++g)
          {
            const double mean = cell_exchange[0](ghost_layer_cells[g]);
            for (unsigned int i = 0; i < n_vertices; ++i)
              {
                vertex_mean[ghost_layer_vertices[g * n_vertices + i]] += ghost_layer_volume[g] * mean;
                vertex_weight[ghost_layer_vertices[g * n_vertices + i]] += ghost_layer_volume[g];
              }
          }
        cell_exchange[0].zero_out_ghost_values();
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
        if (exchange)
          for (unsigned int c = 0; c < dim; ++c)
            cell_exchange[c] = 0.;
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
                for (unsigned int c = 0; c < dim; ++c)
                  cell_value(c, cell, v) = normal[c];
            }
        if (exchange)
          {
            for (unsigned int c = 0; c < dim; ++c)
              cell_exchange[c].update_ghost_values();
            for (std::size_t g = 0; g < ghost_layer_volume.size(); ++g)
              {
                Tensor<1, dim> normal;
                for (unsigned int c = 0; c < dim; ++c)
                  normal[c] = cell_exchange[c](ghost_layer_cells[g]);
                if (normal.norm() > 0.)
                  add_to_vertices(&ghost_layer_vertices[g * n_vertices], ghost_layer_volume[g], normal);
              }
            for (unsigned int c = 0; c < dim; ++c)
              cell_exchange[c].zero_out_ghost_values();
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

    // 2c. the smoothed normal: Youngs' normal is exact for no curved
    // interface and its error depends on where the interface cuts the
    // 3^dim stencil, which turned a rotating disc slightly elliptic
    // (D = 0.0016 after a revolution at 16 cells per diameter). Where the
    // unit normals at the cell's vertices agree (|their mean| >= 0.995,
    // radii above about 5 cells) their mean averages that error out
    // (D = 0.0007); at corners and thin features they do not agree and
    // Youngs' normal, which keeps them sharper, stays.
    const auto smooth_normal = [&](const unsigned int k, Tensor<1, dim> &gradient) {
      Tensor<1, dim> mean;
      for (unsigned int i = 0; i < n_vertices; ++i)
        {
          const Tensor<1, dim> &sum  = vertex_normal[cell_vertices[k * n_vertices + i]];
          const double          norm = sum.norm();
          if (norm == 0.)
            return; // a vertex without a normal: keep Youngs'
          mean += sum / (norm * n_vertices);
        }
      if (mean.norm() >= 0.995)
        for (unsigned int c = 0; c < dim; ++c) // to the unit cell's coordinates
          gradient[c] = mean[c] * cell_extent[k][c];
    };

    // 3. the profiles of the owned cells; the ghost cells receive theirs
    // through the phi DoFs of a scratch vector
    for (unsigned int cell = 0; cell < n_owned; ++cell)
      for (unsigned int v = 0; v < matrix_free.n_active_entries_per_cell_batch(cell); ++v)
        {
          const unsigned int k        = cell * n_lanes + v;
          const bool     cut      = cell_mean[k] > 1e-6 && cell_mean[k] < 1. - 1e-6;
          Tensor<1, dim> gradient = unit_gradient(k);
          if (thinc_smoothed && cut)
            smooth_normal(k, gradient);
          const double divergence =
            thinc_curved && cut ? divergence_of_normals(k) : 0.;
          reconstruction[cell][v] =
            reconstruct(cell_mean[k], gradient, cell_corner[k], cell_extent[k], divergence);
          reconstruction[cell][v].lower = cell_corner[k];
          reconstruction[cell][v].upper = cell_corner[k] + cell_extent[k];
        }
    if (n_ghosts == 0)
      return;
    for (auto &values : cell_exchange)
      values = 0.;
    for (unsigned int cell = 0; cell < n_owned; ++cell)
      for (unsigned int v = 0; v < matrix_free.n_active_entries_per_cell_batch(cell); ++v)
        if (const auto &r = reconstruction[cell][v]; r.weight > 0.)
          {
            cell_value(0, cell, v) = r.weight;
            cell_value(1, cell, v) = r.offset;
            for (unsigned int c = 0; c < dim; ++c)
              cell_value(2 + c, cell, v) = r.slope[c];
            cell_value(2 + dim, cell, v) = r.curvature;
          }
    for (auto &values : cell_exchange)
      values.update_ghost_values();
    for (unsigned int cell = n_owned; cell < n_owned + n_ghosts; ++cell)
      for (unsigned int v = 0; v < matrix_free.n_active_entries_per_cell_batch(cell); ++v)
        {
          auto &r     = reconstruction[cell][v];
          r.lower     = cell_corner[cell * n_lanes + v];
          r.upper     = cell_corner[cell * n_lanes + v] + cell_extent[cell * n_lanes + v];
          r.weight    = cell_value(0, cell, v);
          r.offset    = cell_value(1, cell, v);
          for (unsigned int c = 0; c < dim; ++c)
            r.slope[c] = cell_value(2 + c, cell, v);
          r.curvature = cell_value(2 + dim, cell, v);
        }
    for (auto &values : cell_exchange)
      values.zero_out_ghost_values();
  }

  template <int dim>
  void TransportOperator<dim>::update_profiles(const VectorType &solution) const
  {
    if (thinc_beta > 0.)
      compute_reconstruction(solution);
  }

  template <int dim>
  const typename TransportOperator<dim>::Reconstruction *
  TransportOperator<dim>::profile(const unsigned int active_cell_index) const
  {
    if (!(thinc_beta > 0.))
      return nullptr;
    const unsigned int k = owned_cell_lane[active_cell_index];
    Assert(k != numbers::invalid_unsigned_int, ExcMessage("not a locally owned cell"));
    const auto &r = reconstruction[k / VA::size()][k % VA::size()];
    return r.weight > 0. ? &r : nullptr;
  }

  template <int dim>
  double TransportOperator<dim>::Reconstruction::value(const Point<dim> &x,
                                                       const double      dg_value) const
  {
    return profile_phi(*this, x, dg_value);
  }

  template <int dim>
  double TransportOperator<dim>::Reconstruction::argument(const Point<dim> &x) const
  {
    return profile_argument(*this, x);
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
          values[q] = seen_phi<dim>(reconstruction[cell], cell_point(cell, 1, q), phi.get_value(q));
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
    // the face neighbours' values in the solution's own ghost entries
    const bool had_ghosts = solution.has_ghost_elements();
    if (!had_ghosts)
      solution.update_ghost_values();
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
        phi_m.read_dof_values(solution);
        phi_p.read_dof_values(solution);
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
    if (!had_ghosts)
      solution.zero_out_ghost_values();
    return total;
  }

  template class TransportOperator<2>;
  template class TransportOperator<3>;
} // namespace Suspension::Solid
