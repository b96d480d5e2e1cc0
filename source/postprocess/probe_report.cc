#include <deal.II/base/mpi.h>

#include <suspension/postprocess/point_values.h>
#include <suspension/postprocess/probe_report.h>

#include <boost/archive/text_iarchive.hpp>
#include <boost/archive/text_oarchive.hpp>
#include <boost/serialization/string.hpp>
#include <boost/serialization/vector.hpp>

#include <fstream>
#include <iomanip>
#include <sstream>

namespace Suspension::Postprocess
{
  template <int dim>
  ProbeReport<dim>::ProbeReport(const Parameters::All        &parameters,
                                const Fluid::FluidSpace<dim> &space,
                                const Solid::SolidPhase<dim> *solid)
    : parameters(parameters)
    , space(space)
    , solid(solid)
  {
    for (const auto &c : parameters.output.probe_points)
      {
        Point<dim> p;
        for (unsigned int d = 0; d < dim; ++d)
          p[d] = c[d];
        points.push_back(p);
      }
  }

  template <int dim>
  void ProbeReport<dim>::sample(const Fluid::VectorType &velocity,
                                const Fluid::VectorType &kinematic_pressure, const double time)
  {
    const auto   u   = point_values(space.dof_velocity, velocity, points);
    const auto   p   = point_values(space.dof_pressure, kinematic_pressure, points);
    const double rho = parameters.material.density;
    static const char *names[] = {"u_x", "u_y", "u_z"};
    last_lines.clear();
    for (unsigned int k = 0; k < points.size(); ++k)
      {
        std::ostringstream line;
        line << "  probe " << k << " at (" << points[k] << "): u = (" << std::scientific
             << std::setprecision(6);
        for (unsigned int d = 0; d < dim; ++d)
          line << (d > 0 ? ", " : "") << u[k][d];
        line << "), p = " << rho * p[k][0];
        if (solid)
          {
            const auto fields = solid->component_names();
            const auto values = solid->values_at({points[k]});
            for (unsigned int c = 0; c < fields.size(); ++c)
              {
                line << ", " << fields[c] << " = " << values[0][c];
                table.add_value(fields[c], values[0][c]);
                table.set_scientific(fields[c], true);
                table.set_precision(fields[c], 12);
              }
          }
        last_lines.push_back(line.str());
        table.add_value("time", time);
        table.add_value("probe", k);
        for (unsigned int d = 0; d < dim; ++d)
          table.add_value("x" + std::to_string(d), points[k][d]);
        for (unsigned int d = 0; d < dim; ++d)
          table.add_value(names[d], u[k][d]);
        table.add_value("p", rho * p[k][0]);
      }
  }

  template <int dim>
  void ProbeReport<dim>::write(const std::string &directory) const
  {
    if (Utilities::MPI::this_mpi_process(space.dof_velocity.get_communicator()) != 0)
      return;
    std::ofstream out(directory + "/probes.txt");
    TableHandler  copy = table;
    for (const auto &c : {"time", "x0", "x1", "x2", "u_x", "u_y", "u_z", "p"})
      if (dim == 3 || (std::string(c) != "x2" && std::string(c) != "u_z"))
        {
          copy.set_scientific(c, true);
          copy.set_precision(c, 10);
        }
    copy.write_text(out, TableHandler::table_with_separate_column_description);
  }

  template <int dim>
  void ProbeReport<dim>::report(std::ostream &out) const
  {
    for (const auto &line : last_lines)
      out << line << std::endl;
  }

  template <int dim>
  void ProbeReport<dim>::save(std::ostream &out) const
  {
    boost::archive::text_oarchive archive(out);
    archive << last_lines << table;
  }

  template <int dim>
  void ProbeReport<dim>::load(std::istream &in)
  {
    boost::archive::text_iarchive archive(in);
    archive >> last_lines >> table;
  }

  template class ProbeReport<2>;
  template class ProbeReport<3>;
} // namespace Suspension::Postprocess
