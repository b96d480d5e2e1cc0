#pragma once

#include <deal.II/base/conditional_ostream.h>
#include <deal.II/base/table_handler.h>

#include <suspension/core/parameters.h>
#include <suspension/fluid/fluid_space.h>
#include <suspension/solid/solid_phase.h>

#include <array>
#include <iosfwd>
#include <string>
#include <vector>

namespace Suspension::Postprocess
{
  using namespace dealii;

  /// One line on a single particle: centroid, D, inclination, area.
  template <int dim>
  std::string describe(const Solid::ParticleShape<dim> &shape);

  /**
   * What the solid phase reports: its columns of statistics.txt (volume
   * and mass balance, bounds of phi, B's determinant and eigenvalues, the
   * interface width and the elastic energy in phi's tail, and with a
   * single particle its shape), the end-of-run lines (mass balance and
   * bounds verdicts, B, the interface, the particle's final shape, the
   * errors against exact solid fields at probes and an exact phi). The
   * SolidPhase reduces its diagnostics over MPI.
   */
  template <int dim>
  class SolidReport
  {
  public:
    SolidReport(const Parameters::All         &parameters,
                const Solid::SolidPhase<dim>  &solid,
                const Fluid::FluidSpace<dim>  &space);

    void add_columns(TableHandler                  &statistics,
                     const Solid::SolidDiagnostics &d,
                     const Fluid::VectorType       &velocity) const;

    /// 'Verification/Exact solid at probes': errors of phi and B there
    void report_probes(const ConditionalOStream &out, double time) const;

    /// at a 'Verification/Report time': the probe errors and, with one
    /// particle, its shape (kept in deformation_history())
    void report_at(const ConditionalOStream &out, const Fluid::VectorType &velocity,
                   double time);

    /// the end of the run; computes the phi errors of an exact fraction
    void report(const ConditionalOStream &out, const Solid::SolidDiagnostics &d,
                const Fluid::VectorType &velocity, double time);

    /// < 0: no exact fraction given
    double phi_l1_error() const { return l1_error; }
    double phi_cell_l1_error() const { return cell_l1_error; }
    /// (t, D, D_B) of the single particle at the report times
    const std::vector<std::array<double, 3>> &deformation_history() const { return shapes; }

  private:
    const Parameters::All        &parameters;
    const Solid::SolidPhase<dim> &solid;
    const Fluid::FluidSpace<dim> &space;
    double                        l1_error = -1., cell_l1_error = -1.;
    std::vector<std::array<double, 3>> shapes;
    /// largest |area(phi >= 1/2) / int phi(0) - 1| of the single particle
    /// over the steps reported in statistics.txt (since this run started)
    mutable double                largest_area_error = 0.;
  };
} // namespace Suspension::Postprocess
