#pragma once

#include <deal.II/base/conditional_ostream.h>

#include <suspension/core/parameters.h>
#include <suspension/fluid/fluid_space.h>
#include <suspension/postprocess/flow_verification.h>

#include <iosfwd>
#include <utility>
#include <vector>

namespace Suspension::Postprocess
{
  using namespace dealii;

  /**
   * The flow against what is known of it (FlowVerification): the errors
   * against an exact solution at 'Verification/Report times' and at the
   * end, kept as a history; the end-of-run verdicts ('Verification/
   * Tolerance' on the error, and in a channel at constant flow rate on
   * -dp/dx against its laminar value); the comparison with tabulated
   * reference data. The errors are reduced over MPI by FlowVerification.
   */
  template <int dim>
  class VerificationReport
  {
  public:
    VerificationReport(const Parameters::All &parameters, const Fluid::FluidSpace<dim> &space);

    /// the errors at 'time' (nothing without an exact solution);
    /// steady: labelled as the steady state instead of by time
    void report_errors(const ConditionalOStream &out, const Fluid::VectorType &velocity,
                       const Fluid::VectorType &kinematic_pressure, double time, bool steady);
    /// the verdicts and reference comparisons of the end of a run
    void report_verdicts(const ConditionalOStream &out, double driving_force, bool steady) const;
    /// 'Verification/Reference data': the deviation from the tabulated flow
    void report_reference(const ConditionalOStream &out, const Fluid::VectorType &velocity) const;

    /// the last errors reported (zero before the first)
    FlowErrors last_errors() const { return errors.empty() ? FlowErrors() : errors.back().second; }
    const std::vector<std::pair<double, FlowErrors>> &history() const { return errors; }

    void save(std::ostream &out) const;
    void load(std::istream &in);

  private:
    const Parameters::All                     &parameters;
    const Fluid::FluidSpace<dim>              &space;
    FlowVerification<dim>                      verification;
    std::vector<std::pair<double, FlowErrors>> errors;
  };
} // namespace Suspension::Postprocess
