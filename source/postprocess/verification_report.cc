#include <suspension/postprocess/verification_report.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <istream>
#include <ostream>
#include <sstream>

namespace Suspension::Postprocess
{
  template <int dim>
  VerificationReport<dim>::VerificationReport(const Parameters::All        &parameters,
                                              const Fluid::FluidSpace<dim> &space)
    : parameters(parameters)
    , space(space)
    , verification(parameters)
  {}

  template <int dim>
  void VerificationReport<dim>::report_errors(const ConditionalOStream &out,
                                              const Fluid::VectorType  &velocity,
                                              const Fluid::VectorType  &kinematic_pressure,
                                              const double time, const bool steady)
  {
    if (!verification.has_exact_solution())
      return;
    const FlowErrors last = verification.errors(space, velocity, kinematic_pressure, time);
    errors.emplace_back(time, last);
    std::ostringstream when;
    when << "t = " << std::setprecision(6) << time;
    // the step at which a steady state is detected may differ by one
    // between platforms or rank counts: do not print it
    out << "  " << (steady ? std::string("steady state") : when.str())
        << ": velocity L2 error " << std::scientific << std::setprecision(3) << last.velocity_l2
        << " (relative " << last.velocity_l2_relative << "), pressure L2 error "
        << last.pressure_l2 << std::defaultfloat << std::endl;
  }

  template <int dim>
  void VerificationReport<dim>::report_verdicts(const ConditionalOStream &out,
                                                const double driving_force, const bool steady) const
  {
    const double tolerance = parameters.verification.tolerance;
    const auto   verdict   = [&](const double value) { return value <= tolerance ? "yes" : "no"; };
    if (tolerance > 0 && verification.has_exact_solution())
      out << "  velocity relative L2 error <= " << tolerance << ": "
          << verdict(last_errors().velocity_l2_relative) << std::endl;

    // In a channel at constant flow rate, -dp/dx over its laminar value
    // 3 mu V_b / h^2 is the effective viscosity ratio.
    const auto &driving = parameters.flow_driving;
    if (parameters.geometry.type == Parameters::GeometryType::channel &&
        driving.type == Parameters::FlowDrivingType::constant_flow_rate && steady)
      {
        const double h       = parameters.geometry.half_height;
        const double laminar = 3. * parameters.material.viscosity * driving.bulk_velocity / (h * h);
        const double ratio   = driving_force / laminar;
        out << "  -dp/dx = " << std::setprecision(8) << driving_force
            << ", laminar 3 mu V_b / h^2 = " << laminar << ", ratio " << ratio
            << std::defaultfloat << std::endl;
        if (tolerance > 0)
          out << "  |ratio - 1| <= " << tolerance << ": " << verdict(std::abs(ratio - 1.))
              << std::endl;
      }
  }

  template <int dim>
  void VerificationReport<dim>::report_reference(const ConditionalOStream &out,
                                                 const Fluid::VectorType  &velocity) const
  {
    if (parameters.verification.reference_data != Parameters::ReferenceData::ghia_re100)
      return;
    const auto c = verification.compare_with_ghia(space, velocity);
    out << "  Ghia et al. (1982), Re = 100: max |u - u_ref| on x = 1/2: " << std::fixed
        << std::setprecision(3) << c.max_u_deviation << ", max |v - v_ref| on y = 1/2: "
        << c.max_v_deviation << std::defaultfloat << std::endl;
    out << "  within 2% of the lid speed: "
        << (std::max(c.max_u_deviation, c.max_v_deviation) <= 0.02 ? "yes" : "no") << std::endl;
  }

  template <int dim>
  void VerificationReport<dim>::save(std::ostream &out) const
  {
    out << std::setprecision(17) << errors.size();
    for (const auto &[t, e] : errors)
      out << ' ' << t << ' ' << e.velocity_l2 << ' ' << e.velocity_l2_relative << ' '
          << e.pressure_l2;
  }

  template <int dim>
  void VerificationReport<dim>::load(std::istream &in)
  {
    std::size_t n = 0;
    in >> n;
    errors.assign(n, {});
    for (auto &[t, e] : errors)
      in >> t >> e.velocity_l2 >> e.velocity_l2_relative >> e.pressure_l2;
  }

  template class VerificationReport<2>;
  template class VerificationReport<3>;
} // namespace Suspension::Postprocess
