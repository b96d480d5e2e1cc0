#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/base/table_handler.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/lac/full_matrix.h>

#include <suspension/postprocess/channel_statistics.h>
#include <suspension/postprocess/channel_statistics_layout.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <istream>
#include <memory>
#include <ostream>
#include <sstream>

namespace Suspension::Postprocess
{
  using namespace ChannelLayout;

  namespace
  {
    /// The covariances u'u', v'v', w'w', u'v' of one bin of one sample
    /// (bin integrals I), the fluctuations taken about the least-squares
    /// fit a + b t + c t^2 of each velocity component over the bin: its
    /// plane mean as a function of y, so that the mean shear across a bin
    /// is not counted as a fluctuation (exact for a parabolic profile).
    /// Lower degrees where the bin holds too few rows of points.
    std::array<double, 4> fluctuations(const double *I)
    {
      const double V       = I[volume];
      const double T[5]    = {1., I[t1] / V, I[t2] / V, I[t3] / V, I[t4] / V};
      const double C[3][3] = {{I[u] / V, I[ut1] / V, I[ut2] / V},
                              {I[v] / V, I[vt1] / V, I[vt2] / V},
                              {I[w] / V, I[wt1] / V, I[wt2] / V}};
      // fit coefficients a_f = M^{-1} c_f, M_ij = <t^(i+j)>
      unsigned int       n = 3;
      FullMatrix<double> M;
      for (;; --n)
        {
          M.reinit(n, n);
          for (unsigned int i = 0; i < n; ++i)
            for (unsigned int j = 0; j < n; ++j)
              M(i, j) = T[i + j];
          if (n == 1 || M.determinant() > 1e-10)
            break;
        }
      M.gauss_jordan();
      double a[3][3] = {};
      for (unsigned int f = 0; f < 3; ++f)
        for (unsigned int i = 0; i < n; ++i)
          for (unsigned int j = 0; j < n; ++j)
            a[f][i] += M(i, j) * C[f][j];
      const auto residual = [&](const unsigned int product, const unsigned int f,
                                const unsigned int g) {
        double fitted = 0.;
        for (unsigned int i = 0; i < n; ++i)
          fitted += a[f][i] * C[g][i];
        return I[product] / V - fitted;
      };
      return {{std::max(0., residual(uu, 0, 0)), std::max(0., residual(vv, 1, 1)),
              std::max(0., residual(ww, 2, 2)), residual(uv, 0, 1)}};
    }

  } // namespace

  void RunningMean::add(const double x)
  {
    ++n;
    const double delta = x - mean;
    mean += delta / n;
    m2 += delta * (x - mean);
  }

  template <int dim>
  ChannelStatistics<dim>::ChannelStatistics(const Parameters::All &parameters,
                                            MPI_Comm               communicator)
    : parameters(parameters)
    , communicator(communicator)
    , h(parameters.geometry.half_height)
    , n_bins(parameters.statistics.n_bins)
    , sums(n_bins, std::vector<double>(n_stored, 0.))
    , budget(n_budget)
    , series(4 + n_budget)
    , steadiness(parameters.statistics.steady_window, parameters.statistics.steady_tolerance)
  {}

  template <int dim>
  bool ChannelStatistics<dim>::complete() const
  {
    const double sampling = parameters.statistics.sampling_time;
    const double since    = steadiness.measured() ? steadiness.steady_time() : first_time;
    return n_sampled > 0 && steadiness.steady() && sampling > 0 &&
           last_time - since >= sampling * (1. - 1e-9);
  }

  template <int dim>
  void ChannelStatistics<dim>::restart_sums()
  {
    for (auto &bin : sums)
      std::fill(bin.begin(), bin.end(), 0.);
    n_sampled = 0;
    for (RunningMean *r : {&driving, &viscosity_ratio, &n1, &n2})
      *r = RunningMean();
    for (auto &r : budget)
      r = RunningMean();
    for (auto &s : series)
      s.clear();
    sample_times.clear();
  }

  template <int dim>
  double ChannelStatistics<dim>::error(const unsigned int quantity) const
  {
    return blocked_error(series[quantity]).error;
  }

  template <int dim>
  std::string ChannelStatistics<dim>::stationarity() const
  {
    return steadiness.describe({"mu_eff", "solid wall distance"}, last_time);
  }

  template <int dim>
  bool ChannelStatistics<dim>::due(const double time, const unsigned int step) const
  {
    const auto &s = parameters.statistics;
    return time >= s.start_time * (1. - 1e-12) && step % s.sample_interval == 0;
  }

  template <int dim>
  void ChannelStatistics<dim>::sample(const Fluid::FluidSpace<dim>     &space,
                                      const Fluid::VectorType          &velocity,
                                      const double                      time,
                                      const double                      driving_force,
                                      const SolidFields<dim>           *solid,
                                      const Fluid::MomentumSource<dim> *collision)
  {
    // wall-normal, spanwise components (the geometry's convention)
    constexpr unsigned int Y = dim - 1, Z = 1;
    const double           mu = parameters.material.viscosity;
    const double           G  = solid ? solid->shear_modulus : 0.;
    const double           width = 2. * h / n_bins;

    const QGauss<dim> quadrature(space.fe_velocity.degree + 1);
    const unsigned int n_q = quadrature.size();
    FEValues<dim>      fe_u(space.fe_velocity, quadrature,
                       update_values | update_gradients | update_quadrature_points |
                         update_JxW_values);
    const FEValuesExtractors::Vector velocities(0);
    std::vector<Tensor<1, dim>>      u_q(n_q);
    std::vector<Tensor<2, dim>>      grad_u_q(n_q);

    std::unique_ptr<FEValues<dim>> fe_s;
    std::vector<Vector<double>>    s_q;
    const bool has_B = solid && solid->dof_handler.get_fe().n_components() > 1;
    if (solid)
      {
        fe_s = std::make_unique<FEValues<dim>>(solid->dof_handler.get_fe(), quadrature,
                                               update_values);
        s_q.assign(n_q, Vector<double>(solid->dof_handler.get_fe().n_components()));
      }
    // B_ij is component 1 + (unrolled index of ij) of the solid field
    const auto B_index = [](const unsigned int i, const unsigned int j) {
      return 1 + SymmetricTensor<2, dim>::component_to_unrolled_index(TableIndices<2>(i, j));
    };

    std::vector<Tensor<1, dim>>          force(n_q);
    std::vector<SymmetricTensor<2, dim>> stress(n_q);

    // per bin the integrals, then the volume integrals of u, N1, N2 and
    // the number of cells a bin boundary cuts
    std::vector<double> local(n_bins * n_integrated + 4, 0.);
    for (const auto &cell : space.dof_velocity.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          {
            double y_min = cell->vertex(0)[Y], y_max = y_min;
            for (const unsigned int i : cell->vertex_indices())
              {
                y_min = std::min(y_min, cell->vertex(i)[Y]);
                y_max = std::max(y_max, cell->vertex(i)[Y]);
              }
            if (std::ceil((y_max + h) / width - 1e-8) - std::floor((y_min + h) / width + 1e-8) > 1.)
              local[n_bins * n_integrated + 3] += 1.;
          }
          fe_u.reinit(cell);
          fe_u[velocities].get_function_values(velocity, u_q);
          fe_u[velocities].get_function_gradients(velocity, grad_u_q);
          if (solid)
            {
              fe_s->reinit(Fluid::FluidSpace<dim>::cell_of(cell, solid->dof_handler));
              fe_s->get_function_values(solid->solution, s_q);
            }
          if (collision)
            {
              // forces only: the stress is ignored (has_stress() is false)
              std::fill(force.begin(), force.end(), Tensor<1, dim>());
              collision->add(cell, fe_u.get_quadrature_points(), quadrature.get_points(), time,
                             force, stress);
            }
          for (unsigned int q = 0; q < n_q; ++q)
            {
              const double yq = fe_u.quadrature_point(q)[Y];
              const auto   k  = static_cast<unsigned int>(
                std::clamp(std::floor((yq + h) / width), 0., double(n_bins - 1)));
              double      *I  = &local[k * n_integrated];
              const double dV = fe_u.JxW(q);
              const auto  &U  = u_q[q];
              const auto  &gU = grad_u_q[q];
              const double wq = dim == 3 ? U[Z] : 0.;
              const double t  = (yq + h) / width - k - 0.5; // in [-1/2, 1/2]
              const double t_ = 2. * t;
              I[volume] += dV;
              I[y] += yq * dV;
              I[t1] += t_ * dV;
              I[t2] += t_ * t_ * dV;
              I[t3] += t_ * t_ * t_ * dV;
              I[t4] += t_ * t_ * t_ * t_ * dV;
              I[ut1] += U[0] * t_ * dV;
              I[ut2] += U[0] * t_ * t_ * dV;
              I[vt1] += U[Y] * t_ * dV;
              I[vt2] += U[Y] * t_ * t_ * dV;
              I[wt1] += wq * t_ * dV;
              I[wt2] += wq * t_ * t_ * dV;
              I[u] += U[0] * dV;
              I[v] += U[Y] * dV;
              I[w] += wq * dV;
              I[uu] += U[0] * U[0] * dV;
              I[vv] += U[Y] * U[Y] * dV;
              I[ww] += wq * wq * dV;
              I[uv] += U[0] * U[Y] * dV;
              I[viscous] += mu * gU[0][Y] * dV;
              if (collision)
                I[force_x] += force[q][0] * dV;

              double n1 = 2. * mu * (gU[0][0] - gU[Y][Y]);
              double n2 = 2. * mu * (gU[Y][Y] - (dim == 3 ? gU[Z][Z] : 0.));
              if (solid)
                {
                  const double phi_q = s_q[q][0];
                  I[phi] += phi_q * dV;
                  if (has_B)
                    {
                      const auto  &B    = s_q[q];
                      const double B_zz = dim == 3 ? B[B_index(Z, Z)] : 1.;
                      I[elastic] += G * solid->weight(phi_q) * B[B_index(0, Y)] * dV;
                      n1 += G * solid->weight(phi_q) * (B[B_index(0, 0)] - B[B_index(Y, Y)]);
                      n2 += G * solid->weight(phi_q) * (B[B_index(Y, Y)] - B_zz);
                    }
                }
              local[n_bins * n_integrated] += U[0] * dV;
              local[n_bins * n_integrated + 1] += n1 * dV;
              local[n_bins * n_integrated + 2] += n2 * dV;
            }
        }
    std::vector<double> global(local.size());
    Utilities::MPI::sum(local, communicator, global);

    // this sample's plane means, in the stored layout
    std::vector<std::vector<double>> means(n_bins, std::vector<double>(n_stored, 0.));
    double                           total_volume = 0.;
    for (unsigned int k = 0; k < n_bins; ++k)
      {
        const double *I = &global[k * n_integrated];
        auto         &m = means[k];
        m[volume]       = I[volume];
        total_volume += I[volume];
        if (I[volume] <= 0.)
          continue;
        for (unsigned int c = y; c < n_stored; ++c)
          m[c] = I[c] / I[volume];
        const auto f = fluctuations(I);
        m[uu]        = f[0];
        m[vv]        = f[1];
        m[ww]        = f[2];
        m[uv]        = f[3];
      }
    AssertThrow(total_volume > 0., ExcMessage("channel statistics: empty channel"));
    const double bulk_velocity = global[n_bins * n_integrated] / total_volume;

    straddling_cells = std::max(straddling_cells, static_cast<unsigned long long>(
                                                    global[n_bins * n_integrated + 3]));
    const double viscosity_ratio_s = driving_force / (3. * mu * bulk_velocity / (h * h));
    if (steadiness.measured() && !steadiness.steady())
      {
        // the migration: the solid's mean distance from the walls
        double solid = 0., weighted = 0.;
        for (unsigned int k = 0; k < n_bins; ++k)
          if (means[k][volume] > 0.)
            {
              solid += means[k][phi] * means[k][volume];
              weighted += means[k][phi] * means[k][volume] * (h - std::abs(means[k][y]));
            }
        if (steadiness.add(time, {viscosity_ratio_s, solid > 0. ? weighted / solid : h}))
          restart_sums(); // this sample is the first of the steady state
      }
    for (unsigned int k = 0; k < n_bins; ++k)
      for (unsigned int c = 0; c < n_stored; ++c)
        sums[k][c] += means[k][c];
    if (n_sampled == 0)
      first_time = time;
    last_time = time;
    ++n_sampled;
    const auto p = fold(means, driving_force);
    const std::vector<double> bulk = {driving_force, viscosity_ratio_s,
                                      global[n_bins * n_integrated + 1] / total_volume,
                                      global[n_bins * n_integrated + 2] / total_volume};
    driving.add(bulk[0]);
    viscosity_ratio.add(bulk[1]);
    n1.add(bulk[2]);
    n2.add(bulk[3]);
    for (unsigned int q = 0; q < 4; ++q)
      series[q].push_back(bulk[q]);
    sample_times.push_back(time);
    for (unsigned int b = 0; b < n_budget; ++b)
      {
        const double value = half_channel_mean(p, b);
        budget[b].add(value);
        series[4 + b].push_back(value);
      }
  }

  template <int dim>
  typename ChannelStatistics<dim>::Profiles
  ChannelStatistics<dim>::fold(const std::vector<std::vector<double>> &m,
                               const double                            Pi) const
  {
    const double rho   = parameters.material.density;
    const double width = 2. * h / n_bins;
    // collision stress: int_{-h}^{y} f_x dy', to the middle of each bin
    std::vector<double> collision(n_bins);
    double              integral = 0.;
    for (unsigned int k = 0; k < n_bins; ++k)
      {
        collision[k] = integral + 0.5 * width * m[k][force_x];
        integral += width * m[k][force_x];
      }
    const auto stress = [&](const unsigned int k, const unsigned int b) {
      const double visc = m[k][viscous];
      const double re   = -rho * m[k][uv];
      const double el   = m[k][elastic];
      const double coll = collision[k];
      switch (b)
        {
          case b_viscous:
            return visc;
          case b_reynolds:
            return re;
          case b_elastic:
            return el;
          case b_collision:
            return coll;
          default:
            return visc + re + el + coll;
        }
    };

    Profiles           p;
    const unsigned int half = n_bins / 2;
    for (unsigned int k = 0; k < half; ++k)
      {
        const unsigned int r    = n_bins - 1 - k; // the mirror bin
        const auto         even = [&](const unsigned int c) { return 0.5 * (m[k][c] + m[r][c]); };
        const auto         odd  = [&](const unsigned int c) { return 0.5 * (m[k][c] - m[r][c]); };
        const auto rms  = [&](const unsigned int c) { return std::sqrt(std::max(0., even(c))); };
        p.volume.push_back(even(volume));
        p.y.push_back(odd(y));
        p.u.push_back(even(u));
        p.v.push_back(odd(v));
        p.phi.push_back(even(phi));
        p.u_rms.push_back(rms(uu));
        p.v_rms.push_back(rms(vv));
        p.w_rms.push_back(rms(ww));
        for (unsigned int b = 0; b < n_budget; ++b)
          p.stress[b].push_back(0.5 * (stress(k, b) - stress(r, b)));
        p.linear.push_back(-Pi * p.y.back());
      }
    return p;
  }

  template <int dim>
  double ChannelStatistics<dim>::half_channel_mean(const Profiles &p, const unsigned int b) const
  {
    double integral = 0., volume_sum = 0.;
    for (unsigned int k = 0; k < p.volume.size(); ++k)
      {
        integral += p.stress[b][k] * p.volume[k];
        volume_sum += p.volume[k];
      }
    return integral / volume_sum;
  }

  template <int dim>
  typename ChannelStatistics<dim>::Profiles ChannelStatistics<dim>::profiles() const
  {
    std::vector<std::vector<double>> means = sums;
    for (auto &bin : means)
      for (auto &x : bin)
        x /= std::max(1u, n_sampled);
    return fold(means, driving.mean);
  }

  template <int dim>
  double ChannelStatistics<dim>::linear_deviation(const Profiles &p) const
  {
    double worst = 0.;
    for (unsigned int k = 0; k < p.y.size(); ++k)
      worst = std::max(worst, std::abs(p.stress[b_total][k] - p.linear[k]));
    const double wall = std::abs(driving.mean * h);
    return wall > 0. ? worst / wall : worst;
  }

  template class ChannelStatistics<2>;
  template class ChannelStatistics<3>;
} // namespace Suspension::Postprocess
