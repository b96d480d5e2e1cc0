#pragma once

#include <deal.II/base/table_handler.h>

#include <suspension/core/parameters.h>
#include <suspension/fluid/fluid_space.h>
#include <suspension/solid/solid_phase.h>

#include <iosfwd>
#include <string>
#include <vector>

namespace Suspension::Postprocess
{
  using namespace dealii;

  /**
   * The values at 'Output/Probe points': velocity, pressure and, with a
   * solid, its fields, sampled at every output. Owns probes.txt and the
   * end-of-run lines (the last sample). Point values are evaluated on the
   * rank that owns the point and broadcast (point_values()).
   */
  template <int dim>
  class ProbeReport
  {
  public:
    ProbeReport(const Parameters::All        &parameters,
                const Fluid::FluidSpace<dim> &space,
                const Solid::SolidPhase<dim> *solid);

    void sample(const Fluid::VectorType &velocity, const Fluid::VectorType &kinematic_pressure,
                double time);
    /// probes.txt in 'directory' (call on every rank; rank 0 writes)
    void write(const std::string &directory) const;
    /// one line per probe: its last sample
    void report(std::ostream &out) const;

    void save(std::ostream &out) const;
    void load(std::istream &in);

  private:
    const Parameters::All        &parameters;
    const Fluid::FluidSpace<dim> &space;
    const Solid::SolidPhase<dim> *solid;
    std::vector<Point<dim>>       points;
    TableHandler                  table;
    std::vector<std::string>      last_lines;
  };
} // namespace Suspension::Postprocess
