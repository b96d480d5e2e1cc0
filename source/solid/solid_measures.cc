// SolidPhase: what is measured on the solid fields (bounds, integrals, the
// interface width, a particle's shape, errors against exact fields).
#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_dgq.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/read_write_vector.h>
#include <deal.II/numerics/vector_tools.h>

#include <suspension/core/scene.h>
#include <suspension/core/vector_values.h>
#include <suspension/postprocess/point_values.h>
#include <suspension/solid/phi_values.h>
#include <suspension/solid/solid_phase.h>

#include <algorithm>
#include <cstdlib>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace Suspension::Solid
{
  template <int dim>
  SolidDiagnostics SolidPhase<dim>::diagnostics() const
  {
    SolidDiagnostics d;
    const QGauss<dim>  quadrature(fe.degree + 2);
    // phi on every cell through its own scalar element; the system's
    // FEValues (for B) only on cells that hold solid
    PhiValues<dim>     phi_values(fe, quadrature, update_JxW_values | update_gradients);
    FEValues<dim>      fe_values(fe, quadrature, update_values | update_quadrature_points);
    const auto        &phi = phi_values.values();
    const unsigned int nc  = fe.n_components();
    const double       G   = parameters.solid.shear_modulus;
    Point<dim>         worst;
    double             worst_phi = 0.;
    std::vector<Vector<double>> values(quadrature.size(), Vector<double>(nc));
    std::vector<Tensor<1, dim>> grad_phi(quadrature.size());
    double volume = 0., lo = 1e300, hi = -1e300, det_min = 1e300, eig_min = 1e300, eig_max = 1.;
    // Neumaier's compensated sum of the cells' integrals: the mass balance
    // compares int phi with its initial value, and a running sum over
    // n = 10^4 ... 10^5 terms would blur it by about sqrt(n) u (measured:
    // +-1e-14 from one step to the next in suspension_channel_short_01)
    double     volume_error = 0.;
    const auto add_volume   = [&](const double term) {
      const double sum = volume + term;
      volume_error += std::abs(volume) >= std::abs(term) ? (volume - sum) + term : (term - sum) + volume;
      volume = sum;
    };
    double stiffness = 1.;
    // energy in the tail and in all; interface measure over h; length of
    // the phi = 1/2 surface
    double tail_energy = 0., energy = 0., band = 0., surface = 0.;
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          phi_values.reinit(cell, solution);
          const auto &scalar = phi_values.fe_values();
          bool solid = false;
          double cell_lo = 1e300, cell_hi = -1e300, cell_band = 0., variation = 0.;
          double cell_volume = 0.;
          for (const unsigned int q : scalar.quadrature_point_indices())
            {
              cell_volume += phi[q] * scalar.JxW(q);
              lo    = std::min(lo, phi[q]);
              hi    = std::max(hi, phi[q]);
              solid = solid || phi[q] >= solid_threshold;
              if (phi[q] > 0.01 && phi[q] < 0.99)
                cell_band += scalar.JxW(q);
            }
          add_volume(cell_volume);
          // nodal values too: the limiter's bounds hold there as well
          for (const double value : phi_values.dof_values())
            {
              cell_lo = std::min(cell_lo, value);
              cell_hi = std::max(cell_hi, value);
            }
          lo = std::min(lo, cell_lo);
          hi = std::max(hi, cell_hi);
          band += cell_band / cell->diameter() * std::sqrt(double(dim));
          // the total variation of phi (co-area: the mean size of its level
          // sets, the surface of a thin interface), inside the cells here,
          // across their faces below
          if (cell_hi > touches_solid)
            {
              phi_values.gradients(grad_phi);
              for (const unsigned int q : scalar.quadrature_point_indices())
                variation += grad_phi[q].norm() * scalar.JxW(q);
              surface += variation;
            }
          // B means something only where there is solid
          if (nc == 1 || !(solid || cell_hi > weight.lower))
            continue;
          fe_values.reinit(cell);
          fe_values.get_function_values(solution, values);
          for (const unsigned int q : fe_values.quadrature_point_indices())
            {
              SymmetricTensor<2, dim> B;
              for (unsigned int c = 0; c < n_B; ++c)
                B[SymmetricTensor<2, dim>::unrolled_to_component_indices(c)] = values[q][1 + c];
              const double smallest = smallest_eigenvalue(B);
              // exact in 2D, an upper bound in 3D (the others are >= smallest)
              const double largest = trace(B) - (dim - 1) * smallest;
              const double H       = weight(phi[q]);
              if (H > 0. && smallest > 0.)
                {
                  const double e =
                    0.5 * G * H * (trace(B) - dim - std::log(determinant(B))) * scalar.JxW(q);
                  energy += e;
                  if (phi[q] < 0.5)
                    tail_energy += e;
                }
              if (weight.sharp)
                stiffness = std::max(stiffness, H * largest);
              // checked where B carries stress: with the sharp weight B is
              // reset to I where H = 0, and between those nodes and the
              // solid's its interpolant at a point with H = 0 means nothing
              // (it stopped a 3D run at phi = 0.14, session 33)
              if (weight.sharp ? !(H > 0.) : phi[q] < solid_threshold)
                continue;
              det_min = std::min(det_min, determinant(B));
              eig_max = std::max(eig_max, largest);
              if (smallest < eig_min || !std::isfinite(smallest))
                {
                  eig_min = smallest;
                  worst     = fe_values.quadrature_point(q);
                  worst_phi = phi[q];
                }
            }
        }
    // matrix-free over the faces (FEInterfaceValues, which builds a map of
    // the DoFs of both cells at every face, took 19 % of the main job)
    surface += transport.face_jumps(solution, touches_solid);
    const MPI_Comm comm = dof_handler.get_communicator();
    d.volume       = Utilities::MPI::sum(volume + volume_error, comm);
    d.volume_drift = initial_volume > 0 ? (d.volume - initial_volume) / initial_volume : 0.;
    d.initial_volume   = initial_volume;
    d.boundary_outflow = boundary_outflow;
    d.updates          = updates;
    d.mass_balance =
      initial_volume > 0 ? (d.volume - initial_volume + boundary_outflow) / initial_volume : 0.;
    d.min_phi      = Utilities::MPI::min(lo, comm);
    d.max_phi      = Utilities::MPI::max(hi, comm);
    const double sums[2] = {band, surface};
    double       total[2];
    Utilities::MPI::sum(ArrayView<const double>(sums, 2), comm, ArrayView<double>(total, 2));
    d.interface_width = total[1] > 0. ? total[0] / total[1] : 0.;
    if (nc > 1)
      {
        d.min_det_B = Utilities::MPI::min(det_min, comm);
        const auto m = Utilities::MPI::min_max_avg(eig_min, comm);
        d.min_eigenvalue_B = m.min;
        d.max_eigenvalue_B = Utilities::MPI::max(eig_max, comm);
        d.wave_stiffness   = weight.sharp ? Utilities::MPI::max(stiffness, comm) : d.max_eigenvalue_B;
        const double e[2] = {tail_energy, energy};
        double       e_total[2];
        Utilities::MPI::sum(ArrayView<const double>(e, 2), comm, ArrayView<double>(e_total, 2));
        d.tail_energy_share = e_total[1] > 0. ? e_total[0] / e_total[1] : 0.;
        const Point<dim> where = Utilities::MPI::broadcast(comm, worst, m.min_index);
        for (unsigned int c = 0; c < dim; ++c)
          d.worst_B_location[c] = where[c];
        d.worst_B_phi = Utilities::MPI::broadcast(comm, worst_phi, m.min_index);
      }
    return d;
  }

  template <int dim>
  ParticleShape<dim> SolidPhase<dim>::particle_shape(const Fluid::FluidSpace<dim> &space,
                                                     const Fluid::VectorType      &velocity) const
  {
    const QGauss<dim> quadrature(fe.degree + 2);
    // The region phi >= 1/2 counted at a few Gauss points per cell jumps by
    // a share of a cell whenever a point crosses the level (+-0.8 % of a
    // disc of 16 cells per diameter from step to step). For the record
    // (statistics.txt) it is also measured on cells that the level 1/2
    // crosses at the midpoints of a 24 x 24 (8 x 8 x 8) grid of sub-cells.
    const QIterated<dim> fine(QMidpoint<1>(), dim == 2 ? 24 : 8);
    // This runs every step. FEValues on the systems copied every shape value
    // of every component on every cell (the largest cost of this function):
    // phi goes through its scalar element, u and phi at the sub-cell points
    // through tables of the scalar elements' values there, the same on
    // every cell, and the sub-cells' midpoints follow from the cell's box
    // (every cell of a box or channel is axis-parallel). B is read only on
    // the cells of the core.
    PhiValues<dim>     phi_values(fe, quadrature, update_JxW_values | update_quadrature_points);
    const auto        &fe_gauss = phi_values.fe_values();
    FEValues<dim>      fe_B(fe, quadrature, update_values);
    const auto tabulate = [](const FiniteElement<dim> &base, const Quadrature<dim> &points) {
      FullMatrix<double> shape(base.n_dofs_per_cell(), points.size());
      for (unsigned int i = 0; i < base.n_dofs_per_cell(); ++i)
        for (unsigned int q = 0; q < points.size(); ++q)
          shape(i, q) = base.shape_value(i, points.point(q));
      return shape;
    };
    const auto              &u_base     = space.fe_velocity.base_element(0);
    const FullMatrix<double> u_gauss    = tabulate(u_base, quadrature);
    const FullMatrix<double> u_fine     = tabulate(u_base, fine);
    const FullMatrix<double> phi_fine_shape = tabulate(fe.base_element(0), fine);
    Vector<double>           u_local(space.fe_velocity.n_dofs_per_cell());
    // the (component, base index) of each velocity DoF, looked up once
    std::vector<std::pair<unsigned int, unsigned int>> u_index(u_local.size());
    for (unsigned int i = 0; i < u_local.size(); ++i)
      u_index[i] = space.fe_velocity.system_to_component_index(i);
    // u at sub-cell point q: the sum of vector_value_from_scalar_base, in its order
    const auto u_at_fine = [&](const unsigned int q) {
      Tensor<1, dim> value;
      for (unsigned int i = 0; i < u_index.size(); ++i)
        value[u_index[i].first] += u_local[i] * u_fine(u_index[i].second, q);
      return value;
    };
    // Where the profile alone is phi (its weight 1) and H is the sharp
    // step, phi = 1 / (1 + exp(-2a)) at a sub-cell point is needed only
    // where H is strictly between 0 and 1, a in (atanh(2 lower - 1),
    // atanh(2 upper - 1)): beyond, phi >= 1/2 and H follow from the sign
    // of a (with a margin far above the exponential's round-off, so the
    // answers are those of the computed phi). Most sub-cell points are
    // beyond, and the exponential was the largest cost of this loop.
    const auto   band_end = [](const double level) {
      return level <= 0. ? -1e300 : (level >= 1. ? 1e300 : std::atanh(2. * level - 1.));
    };
    const double a_lower = band_end(weight.lower) - 1e-9, a_upper = band_end(weight.upper) + 1e-9;
    std::vector<Tensor<1, dim>> u(quadrature.size());
    std::vector<double>         phi_fine(fine.size());
    std::vector<Point<dim>>     x_fine(fine.size());
    Vector<double>              local(fe.n_dofs_per_cell());
    // moments of three sets, V, V x, V u, V x x^T (unrolled): the stress
    // weight H(phi) (the particle is where it would carry stress: its
    // diffuse tail does not enter), phi itself (tail included), the region
    // phi >= 1/2 on sub-cells; then area(phi >= 1/2) at the Gauss points and
    // on sub-cells
    const unsigned int  n_m = 1 + 2 * dim + dim * dim;
    // then the volume of the core (H = 1) and the integral of B over it
    const bool          elastic = fe.n_components() > 1;
    const FEValuesExtractors::SymmetricTensor<2> B_x(1);
    std::vector<SymmetricTensor<2, dim>>        B(quadrature.size());
    std::vector<double> m(3 * n_m + 2 + 1 + n_B, 0.);
    double             *core = &m[3 * n_m + 2];
    const auto add = [&](double *ms, const double w, const Point<dim> &x, const Tensor<1, dim> &v) {
      ms[0] += w;
      for (unsigned int d = 0; d < dim; ++d)
        {
          ms[1 + d] += w * x[d];
          ms[1 + dim + d] += w * v[d];
          for (unsigned int e = 0; e < dim; ++e)
            ms[1 + 2 * dim + d * dim + e] += w * x[d] * x[e];
        }
    };
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          // the range of the nodal values bounds a Q1 polynomial; a margin
          // for higher degrees
          cell->get_dof_values(solution, local);
          double lowest = 1e300, highest = -1e300;
          for (unsigned int i = 0; i < fe.n_dofs_per_cell(); ++i)
            if (fe.system_to_component_index(i).first == 0)
              {
                lowest  = std::min(lowest, local[i]);
                highest = std::max(highest, local[i]);
              }
          // with 'Shape measure = profile' the interface inside a cut cell
          // is the profile the transport carries
          const auto *profile =
            shape_on_profile ? transport.profile(cell->active_cell_index()) : nullptr;
          const bool profiled = profile != nullptr;
          // Most cells hold only fluid: every moment below is weighted by
          // phi or by a weight that vanishes with it, so they add (next to)
          // nothing, and evaluating them was most of this function's cost.
          if (std::max(highest, -lowest) < 1e-12 && !profiled)
            continue;
          phi_values.reinit(cell, solution);
          const auto &phi           = phi_values.values();
          const auto  velocity_cell = Fluid::FluidSpace<dim>::cell_of(cell, space.dof_velocity);
          velocity_cell->get_dof_values(velocity, u_local);
          vector_values_from_scalar_base(space.fe_velocity, u_local, u_gauss, u);
          const double margin = fe.degree > 1 ? 0.1 : 0.;
          const bool cut = profiled || (lowest < 0.5 + margin && highest >= 0.5 - margin);
          if (cut)
            {
              const Point<dim> corner = cell->vertex(0);
              const Point<dim> far    = cell->vertex(GeometryInfo<dim>::vertices_per_cell - 1);
              double           volume = 1.;
              for (unsigned int d = 0; d < dim; ++d)
                volume *= far[d] - corner[d];
              // the DG polynomial only where the profile does not replace it
              const bool  dg_needed = !profiled || profile->weight != 1.;
              const bool  by_argument = !dg_needed && weight.sharp;
              const auto &phi_dofs  = phi_values.dof_values();
              for (unsigned int q = 0; q < fine.size(); ++q)
                {
                  for (unsigned int d = 0; d < dim; ++d)
                    x_fine[q][d] = corner[d] + (far[d] - corner[d]) * fine.point(q)[d];
                  if (by_argument)
                    {
                      const double a = profile->argument(x_fine[q]);
                      phi_fine[q]    = a > a_upper ? 1. :
                                       a < a_lower ? 0. :
                                                     1. / (1. + std::exp(-2. * a));
                      continue;
                    }
                  double value = 0.;
                  if (dg_needed)
                    for (unsigned int i = 0; i < phi_dofs.size(); ++i)
                      value += phi_dofs[i] * phi_fine_shape(i, q);
                  phi_fine[q] = profiled ? profile->value(x_fine[q], value) : value;
                }
              for (unsigned int q = 0; q < fine.size(); ++q)
                {
                  const double H = profiled ? weight(phi_fine[q]) : 0.;
                  if (phi_fine[q] < 0.5 && H == 0.)
                    continue;
                  const double JxW = fine.weight(q) * volume;
                  const auto   u_q = u_at_fine(q);
                  if (phi_fine[q] >= 0.5)
                    {
                      m[3 * n_m + 1] += JxW;
                      add(&m[2 * n_m], JxW, x_fine[q], u_q);
                    }
                  // the profile is a step within a fraction of the cell,
                  // which a few Gauss points would snap to: the stress
                  // weight's moments and the area on the sub-cells
                  if (profiled)
                    {
                      m[3 * n_m] += (phi_fine[q] >= 0.5 ? JxW : 0.);
                      add(&m[0], H * JxW, x_fine[q], u_q);
                    }
                }
            }
          // B only where the cell reaches the core (most cells hold fluid)
          const bool core_cell =
            elastic && weight(*std::max_element(phi.begin(), phi.end())) >= 1.;
          if (core_cell)
            {
              fe_B.reinit(cell);
              fe_B[B_x].get_function_values(solution, B);
            }
          for (const unsigned int q : fe_gauss.quadrature_point_indices())
            {
              const auto  &x   = fe_gauss.quadrature_point(q);
              const double JxW = fe_gauss.JxW(q);
              if (!profiled)
                m[3 * n_m] += (phi[q] >= 0.5 ? JxW : 0.);
              if (!cut && lowest >= 0.5)
                {
                  m[3 * n_m + 1] += JxW;
                  add(&m[2 * n_m], JxW, x, u[q]);
                }
              if (core_cell && weight(phi[q]) >= 1.)
                {
                  core[0] += JxW;
                  for (unsigned int k = 0; k < n_B; ++k)
                    core[1 + k] += JxW * B[q].access_raw_entry(k);
                }
              if (!profiled)
                add(&m[0], weight(phi[q]) * JxW, x, u[q]);
              add(&m[n_m], phi[q] * JxW, x, u[q]);
            }
        }
    Utilities::MPI::sum(m, dof_handler.get_communicator(), m);
    ParticleShape<dim> s;
    s.solid_area         = m[3 * n_m];
    s.solid_area_subcell = m[3 * n_m + 1];
    // angle of a long axis against x, in (-90, 90] degrees
    const auto inclination_of = [](const Tensor<1, dim> &axis) {
      const double angle = std::atan2(axis[1], axis[0]) * 180. / numbers::PI;
      return angle > 90. ? angle - 180. : (angle <= -90. ? angle + 180. : angle);
    };
    // Equivalent ellipse (ellipsoid): second moments a^2/4 (a^2/5) of its
    // semi-axes a.
    const auto shape_of = [&](const double *ms, Point<dim> &centroid, Tensor<1, dim> &velocity,
                              double &deformation, double &inclination) {
      if (ms[0] <= 0.)
        return;
      for (unsigned int d = 0; d < dim; ++d)
        {
          centroid[d] = ms[1 + d] / ms[0];
          velocity[d] = ms[1 + dim + d] / ms[0];
        }
      SymmetricTensor<2, dim> moment;
      for (unsigned int d = 0; d < dim; ++d)
        for (unsigned int e = d; e < dim; ++e)
          moment[d][e] = ms[1 + 2 * dim + d * dim + e] / ms[0] - centroid[d] * centroid[e];
      const auto   eig    = eigenvectors(moment);
      const double factor = dim == 2 ? 4. : 5.;
      const double L      = std::sqrt(factor * std::max(0., eig.front().first));
      const double S      = std::sqrt(factor * std::max(0., eig.back().first));
      deformation         = L + S > 0 ? (L - S) / (L + S) : 0.;
      inclination         = inclination_of(eig.front().second);
    };
    shape_of(&m[0], s.centroid, s.velocity, s.taylor_deformation, s.inclination);
    Point<dim>     centroid;
    Tensor<1, dim> velocity_phi;
    shape_of(&m[n_m], centroid, velocity_phi, s.taylor_deformation_phi, s.inclination_phi);
    shape_of(&m[2 * n_m], centroid, velocity_phi, s.taylor_deformation_half, s.inclination_half);
    if (core[0] > 0.)
      {
        // the stretch of the material: a uniformly deformed particle has
        // semi-axes r sqrt(lambda_i(B)), whatever the shape of phi
        SymmetricTensor<2, dim> mean_B;
        for (unsigned int k = 0; k < n_B; ++k)
          mean_B.access_raw_entry(k) = core[1 + k] / core[0];
        const auto   eig = eigenvectors(mean_B);
        const double L = std::sqrt(std::max(0., eig.front().first));
        const double S = std::sqrt(std::max(0., eig.back().first));
        s.taylor_deformation_B = (L - S) / (L + S);
        s.inclination_B        = inclination_of(eig.front().second);
      }
    return s;
  }

  template <int dim>
  double SolidPhase<dim>::l1_error(const Function<dim> &exact) const
  {
    const QGauss<dim> quadrature(fe.degree + 3);
    FEValues<dim>     fe_values(fe, quadrature,
                            update_values | update_JxW_values | update_quadrature_points);
    const FEValuesExtractors::Scalar phi_x(0);
    std::vector<double>              phi(quadrature.size());
    double                           error = 0.;
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          fe_values.reinit(cell);
          fe_values[phi_x].get_function_values(solution, phi);
          for (const unsigned int q : fe_values.quadrature_point_indices())
            error += std::abs(phi[q] - exact.value(fe_values.quadrature_point(q))) * fe_values.JxW(q);
        }
    return Utilities::MPI::sum(error, dof_handler.get_communicator());
  }

  template <int dim>
  double SolidPhase<dim>::cell_mean_l1_error(const std::string &expression,
                                             const std::string &constants) const
  {
    Parameters::All shape                = parameters;
    shape.solid.initial_fraction         = Parameters::InitialFraction::function;
    shape.solid.fraction_expression      = expression;
    shape.solid.constants                = constants;
    VectorType exact(solution);
    project_initial_fraction(shape, dof_handler, exact);

    const QGauss<dim> quadrature(fe.degree + 1);
    FEValues<dim>     fe_values(fe, quadrature, update_values | update_JxW_values);
    const FEValuesExtractors::Scalar phi_x(0);
    std::vector<double>              phi(quadrature.size()), fraction(quadrature.size());
    double                           error = 0.;
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          fe_values.reinit(cell);
          fe_values[phi_x].get_function_values(solution, phi);
          fe_values[phi_x].get_function_values(exact, fraction);
          double difference = 0.;
          for (const unsigned int q : fe_values.quadrature_point_indices())
            difference += (phi[q] - fraction[q]) * fe_values.JxW(q);
          error += std::abs(difference);
        }
    return Utilities::MPI::sum(error, dof_handler.get_communicator());
  }

  template <int dim>
  std::vector<Vector<double>>
  SolidPhase<dim>::values_at(const std::vector<Point<dim>> &points) const
  {
    return Postprocess::point_values(dof_handler, solution, points);
  }

  template class SolidPhase<2>;
  template class SolidPhase<3>;
} // namespace Suspension::Solid
