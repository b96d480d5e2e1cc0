#pragma once

#include <deal.II/base/table_handler.h>

#include <suspension/core/parameters.h>
#include <suspension/solid/contact_force.h>

#include <iosfwd>
#include <limits>

namespace Suspension::Postprocess
{
  using namespace dealii;

  /**
   * What the contact force saw, step by step and over the run: its
   * columns of statistics.txt (particles, contact cells, closest gaps,
   * largest force) and the end-of-run lines (particles labelled, closest
   * gaps in cells, whether particles stayed apart). The diagnostics come
   * reduced over MPI from ContactForce::update().
   */
  class ContactReport
  {
  public:
    explicit ContactReport(const Parameters::All &parameters);

    /// after every update of the force
    void observe(const Solid::ContactDiagnostics &c);
    /// the last update's columns
    void add_columns(TableHandler &statistics) const;
    void report(std::ostream &out) const;

    void save(std::ostream &out) const;
    void load(std::istream &in);

  private:
    const Parameters::All   &parameters;
    Solid::ContactDiagnostics last;
    /// over the whole run (< 0: no gap within the contact range seen)
    double       closest_gap = -1., closest_wall = -1.;
    double       smallest_cell = 0.;
    unsigned int fewest_particles = std::numeric_limits<unsigned int>::max(), most_particles = 0;
  };
} // namespace Suspension::Postprocess
