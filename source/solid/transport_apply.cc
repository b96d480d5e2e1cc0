// TransportOperator::apply: the DG right-hand side of phi and B (cell and
// face terms, upwind fluxes, the THINC profile where the interface is).
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
              const VA phi_q = thinc ? seen_phi<dim>(profile, cell_point(cell, 0, q), phi.get_value(q)) :
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
                                       seen_phi<dim>(profile_m, face_point(face, q), phi_m.get_value(q)),
                                       seen_phi<dim>(profile_p, face_point(face, q), phi_p.get_value(q))) :
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
              const VA phi_q = thinc ? seen_phi<dim>(profile, face_point(face, q), phi.get_value(q)) :
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

  template class TransportOperator<2>;
  template class TransportOperator<3>;
} // namespace Suspension::Solid
