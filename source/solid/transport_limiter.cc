// TransportOperator: the bound-preserving limiter of phi and the SPD
// limiter of B.
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
    const auto tensor = [](const Tensor<1, n_B, VA> &t, const unsigned int v) {
      SymmetricTensor<2, dim> B;
      for (unsigned int c = 0; c < n_B; ++c)
        B[SymmetricTensor<2, dim>::unrolled_to_component_indices(c)] = t[c][v];
      return B;
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
            const SymmetricTensor<2, dim> B_mean = tensor(mean, v);
            // the smallest eigenvalue is at most the smallest diagonal entry
            double upper = B_mean[0][0];
            for (unsigned int d = 1; d < dim; ++d)
              upper = std::min(upper, B_mean[d][d]);
            if (!(upper > 0.))
              continue; // nothing a scaling can do; the SPD check reports it
            const unsigned int n_nodes     = b.dofs_per_component;
            const auto         for_points = [&](const auto &action) {
              for (const unsigned int q : b.quadrature_point_indices())
                action(b.get_value(q));
              for (unsigned int i = 0; i < n_nodes; ++i)
                {
                  Tensor<1, n_B, VA> node;
                  for (unsigned int c = 0; c < n_B; ++c)
                    node[c] = b.begin_dof_values()[c * n_nodes + i];
                  action(node);
                }
            };
            // Where every point's eigenvalues exceed a tenth of that bound
            // (nearly everywhere), they exceed the floor below, and the
            // mean's eigenvalue (an eigensolver in 3D) is not needed.
            bool all_clear = true;
            for_points([&](const Tensor<1, n_B, VA> &value) {
              all_clear = all_clear && eigenvalues_exceed(tensor(value, v), 0.1 * upper);
            });
            if (all_clear)
              continue;
            const double lambda_mean = smallest_eigenvalue(B_mean);
            if (!(lambda_mean > 0.))
              continue;
            // keep at least a tenth of the mean's smallest eigenvalue
            const double floor = 0.1 * lambda_mean;
            double       theta = 1.;
            for_points([&](const Tensor<1, n_B, VA> &value) {
              const SymmetricTensor<2, dim> B = tensor(value, v);
              if (eigenvalues_exceed(B, floor)) // nearly always: no eigensolver
                return;
              const double lambda = smallest_eigenvalue(B);
              if (lambda < floor)
                theta = std::min(theta, (lambda_mean - floor) / (lambda_mean - lambda));
            });
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
