#include <suspension/postprocess/contact_report.h>

#include <algorithm>
#include <iomanip>
#include <istream>
#include <ostream>
#include <sstream>
#include <stdexcept>

namespace Suspension::Postprocess
{
  ContactReport::ContactReport(const Parameters::All &parameters)
    : parameters(parameters)
  {}

  void ContactReport::observe(const Solid::ContactDiagnostics &c)
  {
    last               = c;
    const auto smaller = [](const double seen, const double now) {
      return now < 0. ? seen : seen < 0. ? now : std::min(seen, now);
    };
    closest_gap      = smaller(closest_gap, c.closest_gap);
    closest_wall     = smaller(closest_wall, c.closest_wall);
    smallest_cell    = c.smallest_cell;
    fewest_particles = std::min(fewest_particles, c.n_particles);
    most_particles   = std::max(most_particles, c.n_particles);
  }

  void ContactReport::add_columns(TableHandler &statistics) const
  {
    const auto &c = last;
    statistics.add_value("particles", c.n_particles);
    statistics.add_value("contact_cells", c.active_cells);
    statistics.add_value("gap_min", c.closest_gap);
    statistics.add_value("wall_gap_min", c.closest_wall);
    statistics.add_value("contact_force_max", c.largest_force);
    for (const auto &column : {"gap_min", "wall_gap_min", "contact_force_max"})
      {
        statistics.set_scientific(column, true);
        statistics.set_precision(column, 6);
      }
  }

  void ContactReport::report(std::ostream &out) const
  {
    const double dx     = smallest_cell;
    const auto   seeded = parameters.solid.particles.size();
    out << "  contact: particles labelled " << fewest_particles << " to " << most_particles
        << " (seeded " << seeded << "), interface cell dx = " << std::setprecision(6) << dx
        << std::endl;
    const auto in_cells = [&](const double gap) {
      std::ostringstream s;
      if (gap < 0.)
        s << "none within " << parameters.solid.contact.range << " dx";
      else
        s << std::setprecision(4) << gap << " (" << std::setprecision(3) << gap / dx << " dx)";
      return s.str();
    };
    out << "  closest gap between particles " << in_cells(closest_gap) << ", closest to a wall "
        << in_cells(closest_wall) << std::endl;
    const bool apart = fewest_particles == seeded && most_particles == seeded &&
                       (closest_gap < 0. || closest_gap >= dx) &&
                       (closest_wall < 0. || closest_wall >= dx);
    out << "  particles never merged and kept a gap >= dx: " << (apart ? "yes" : "no")
        << std::endl;
  }

  void ContactReport::save(std::ostream &out) const
  {
    out << "ContactReport " << std::setprecision(17) << closest_gap << " " << closest_wall << " "
        << smallest_cell << " " << fewest_particles << " " << most_particles << "\n";
  }

  void ContactReport::load(std::istream &in)
  {
    std::string tag;
    in >> tag >> closest_gap >> closest_wall >> smallest_cell >> fewest_particles >> most_particles;
    if (tag != "ContactReport" || in.fail())
      throw std::runtime_error("--resume: the checkpoint has no contact record");
  }
} // namespace Suspension::Postprocess
