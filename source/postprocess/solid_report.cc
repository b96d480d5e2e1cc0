#include <deal.II/base/utilities.h>

#include <suspension/core/scene.h>
#include <suspension/postprocess/solid_report.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace Suspension::Postprocess
{
  template <int dim>
  std::string describe(const Solid::ParticleShape<dim> &s)
  {
    std::ostringstream out;
    out << "particle centroid (" << std::fixed << std::setprecision(4) << s.centroid
        << "), D = " << s.taylor_deformation << ", inclination " << std::setprecision(2)
        << s.inclination << " deg, area(phi >= 1/2) " << std::setprecision(5) << s.solid_area;
    return out.str();
  }

  template <int dim>
  SolidReport<dim>::SolidReport(const Parameters::All        &parameters,
                                const Solid::SolidPhase<dim> &solid,
                                const Fluid::FluidSpace<dim> &space)
    : parameters(parameters)
    , solid(solid)
    , space(space)
  {}

  template <int dim>
  void SolidReport<dim>::add_columns(TableHandler                  &statistics,
                                     const Solid::SolidDiagnostics &d,
                                     const Fluid::VectorType       &velocity) const
  {
    statistics.add_value("solid_volume", d.volume);
    statistics.add_value("volume_drift", d.volume_drift);
    statistics.add_value("phi_outflow", d.boundary_outflow);
    statistics.add_value("mass_balance", d.mass_balance);
    statistics.add_value("phi_min", d.min_phi);
    statistics.add_value("phi_max", d.max_phi);
    statistics.add_value("limited_cells", d.limited_cells);
    statistics.add_value("bad_means", d.out_of_bound_means);
    statistics.add_value("substeps", d.substeps);
    statistics.add_value("interface_cells", d.interface_width);
    std::vector<std::string> columns = {"solid_volume", "volume_drift", "phi_outflow",
                                        "mass_balance", "phi_min", "phi_max", "interface_cells"};
    if (parameters.solid.elastic())
      {
        statistics.add_value("detB_min", d.min_det_B);
        statistics.add_value("eigB_min", d.min_eigenvalue_B);
        statistics.add_value("eigB_max", d.max_eigenvalue_B);
        statistics.add_value("tail_energy_share", d.tail_energy_share);
        columns.insert(columns.end(), {"detB_min", "eigB_min", "eigB_max", "tail_energy_share"});
        static const char *where[] = {"eigB_min_x", "eigB_min_y", "eigB_min_z"};
        for (unsigned int c = 0; c < dim; ++c)
          {
            statistics.add_value(where[c], d.worst_B_location[c]);
            columns.push_back(where[c]);
          }
      }
    if (parameters.solid.particles.size() == 1)
      {
        const auto shape = solid.particle_shape(space, velocity);
        static const char *x[] = {"x_c", "y_c", "z_c"}, *u[] = {"u_c", "v_c", "w_c"};
        for (unsigned int d = 0; d < dim; ++d)
          {
            statistics.add_value(x[d], shape.centroid[d]);
            statistics.add_value(u[d], shape.velocity[d]);
            columns.push_back(x[d]);
            columns.push_back(u[d]);
          }
        statistics.add_value("D", shape.taylor_deformation);
        statistics.add_value("theta_deg", shape.inclination);
        statistics.add_value("solid_area", shape.solid_area);
        if (solid.initial_phi_volume() > 0.)
          largest_area_error = std::max(largest_area_error,
                                        std::abs(shape.solid_area / solid.initial_phi_volume() - 1.));
        statistics.add_value("D_phi", shape.taylor_deformation_phi);
        statistics.add_value("solid_area_subcell", shape.solid_area_subcell);
        statistics.add_value("D_half", shape.taylor_deformation_half);
        columns.insert(columns.end(),
                       {"D", "theta_deg", "solid_area", "D_phi", "solid_area_subcell", "D_half"});
        if (parameters.solid.elastic())
          {
            statistics.add_value("D_B", shape.taylor_deformation_B);
            statistics.add_value("theta_B_deg", shape.inclination_B);
            columns.insert(columns.end(), {"D_B", "theta_B_deg"});
          }
      }
    for (const auto &c : columns)
      {
        statistics.set_scientific(c, true);
        statistics.set_precision(c, 10);
      }
  }

  template <int dim>
  void SolidReport<dim>::report_at(const ConditionalOStream &out,
                                   const Fluid::VectorType  &velocity, const double time)
  {
    report_probes(out, time);
    if (parameters.solid.particles.size() == 1)
      {
        const auto shape = solid.particle_shape(space, velocity);
        shapes.push_back({{time, shape.taylor_deformation, shape.taylor_deformation_B}});
        out << "  t = " << time << ": " << describe(shape) << std::endl;
      }
  }

  template <int dim>
  void SolidReport<dim>::report_probes(const ConditionalOStream &out, const double time) const
  {
    const auto &v = parameters.verification;
    if (!v.exact_solid_at_probes.empty() && !parameters.output.probe_points.empty())
      {
        auto exact = make_function<dim>({v.exact_solid_at_probes, v.exact_velocity.constants},
                                        1 + Solid::SolidPhase<dim>::n_B);
        exact->set_time(time);
        double worst = 0., worst_strain = 0.;
        for (const auto &c : parameters.output.probe_points)
          {
            Point<dim> p;
            for (unsigned int d = 0; d < dim; ++d)
              p[d] = c[d];
            const auto values = solid.values_at({p});
            double     difference = 0., strain = 0.;
            for (unsigned int k = 0; k < values[0].size(); ++k)
              {
                const double e = exact->value(p, k);
                worst = std::max(worst, std::abs(values[0][k] - e) / std::max(1., std::abs(e)));
                if (k == 0)
                  continue;
                // off-diagonal entries count twice in the Frobenius norm
                const double w = k <= dim ? 1. : 2.;
                difference += w * Utilities::fixed_power<2>(values[0][k] - e);
                strain += w * Utilities::fixed_power<2>(e - (k <= dim ? 1. : 0.));
              }
            if (strain > 1e-20)
              worst_strain = std::max(worst_strain, std::sqrt(difference / strain));
          }
        out << "  solid fields at probes: largest relative error " << std::scientific
              << std::setprecision(2) << worst << ", of B - I " << worst_strain
              << std::defaultfloat << std::endl;
        worst = std::max(worst, worst_strain);
        if (v.tolerance > 0)
          out << "  <= " << v.tolerance << ": " << (worst <= v.tolerance ? "yes" : "no")
                << std::endl;
      }
  }

  template <int dim>
  void SolidReport<dim>::report(const ConditionalOStream     &out,
                                const Solid::SolidDiagnostics &d,
                                const Fluid::VectorType       &velocity,
                                const double                   time)
  {
    out << "  solid: volume " << std::scientific << std::setprecision(8) << d.volume
          << ", relative drift " << std::setprecision(2) << d.volume_drift << ", phi in ["
          << std::setprecision(6) << d.min_phi << ", " << d.max_phi << "]" << std::defaultfloat
          << std::endl;
    // The transport changes the integral of phi only by the flux through
    // the boundary (integrated over the steps with the RK weights,
    // SolidPhase::advance), so volume - initial volume + outflow is
    // round-off, for closed boxes and open ones alike; its bound grows
    // with the sub-steps (Solid::mass_balance_bound).
    const double       bound = Solid::mass_balance_bound(d.updates);
    std::ostringstream verdict;
    verdict << "  mass balance (outflow " << std::scientific << std::setprecision(2)
            << (d.initial_volume > 0. ? d.boundary_outflow / d.initial_volume : 0.)
            << " of int phi(0)): residual " << d.mass_balance << " <= " << bound
            << " (round-off bound, " << d.updates << " sub-steps and mesh changes): "
            << (std::abs(d.mass_balance) <= bound ? "yes" : "no") << std::defaultfloat;
    out << verdict.str() << ", 0 <= phi <= 1: "
          << (d.min_phi >= -1e-14 && d.max_phi <= 1. + 1e-14 ? "yes" : "no") << std::endl;
    if (parameters.solid.elastic())
      out << "  B: min det " << std::scientific << std::setprecision(6) << d.min_det_B
            << ", min eigenvalue " << d.min_eigenvalue_B << std::defaultfloat << std::endl;
    std::ostringstream interface;
    interface << "  interface: " << std::fixed << std::setprecision(2) << d.interface_width
              << " cells across 0.01 < phi < 0.99";
    if (parameters.solid.elastic())
      interface << ", elastic energy where phi < 1/2: " << std::scientific << std::setprecision(2)
                << 100. * d.tail_energy_share << " %";
    out << interface.str() << std::endl;
    if (parameters.solid.particles.size() == 1)
      {
        out << "  final: " << describe(solid.particle_shape(space, velocity))
              << std::endl;
        if (const double tolerance = parameters.verification.area_tolerance; tolerance > 0.)
          {
            // formatted apart, so that out keeps its precision
            std::ostringstream area;
            area << "  area(phi >= 1/2) against int phi(0), largest deviation over the steps: "
                 << std::fixed << std::setprecision(3) << 100. * largest_area_error << " % <= "
                 << 100. * tolerance << " %: " << (largest_area_error <= tolerance ? "yes" : "no");
            out << area.str() << std::endl;
          }
      }
    report_probes(out, time);
    if (!parameters.verification.exact_fraction.empty())
      {
        const auto exact = make_function<dim>(
          {parameters.verification.exact_fraction, parameters.verification.exact_velocity.constants},
          1);
        l1_error = solid.l1_error(*exact);
        cell_l1_error = solid.cell_mean_l1_error(parameters.verification.exact_fraction,
                                                      parameters.verification.exact_velocity.constants);
        out << "  phi L1 error " << std::scientific << std::setprecision(4) << l1_error
              << "; of the cell means against the exact cell fractions " << cell_l1_error
              << ", over the initial volume " << cell_l1_error / solid.initial_phi_volume()
              << std::defaultfloat << std::endl;
      }
  }

  template std::string describe(const Solid::ParticleShape<2> &);
  template std::string describe(const Solid::ParticleShape<3> &);
  template class SolidReport<2>;
  template class SolidReport<3>;
} // namespace Suspension::Postprocess
