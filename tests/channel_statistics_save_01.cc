// ChannelStatistics::save()/load(): sums accumulated from two samples of a
// sheared Poiseuille-like field, saved, loaded into a fresh object and
// saved again must give the same text, and both objects the same summary.

#include <deal.II/base/function.h>
#include <deal.II/base/mpi.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/numerics/vector_tools.h>

#include <suspension/core/parameters.h>
#include <suspension/core/scene.h>
#include <suspension/fluid/fluid_space.h>
#include <suspension/postprocess/channel_statistics.h>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>

using namespace dealii;
using namespace Suspension;

// Poiseuille plus a streamwise wave and ramp: fluctuations, a Reynolds
// stress and N1 = 2 mu a (from du/dx = a on average) are not zero
class Velocity : public Function<2>
{
public:
  Velocity(const double a) : Function<2>(2), a(a) {}
  double value(const Point<2> &p, const unsigned int c) const override
  {
    const double s = std::sin(numbers::PI * p[0]), w = 1. - p[1] * p[1];
    return c == 0 ? 1.5 * w + a * s * w + a * p[0] : a * s * w * p[1];
  }
  const double a;
};

int main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  const std::string prm = "channel_statistics_save_01.prm";
  {
    std::ofstream f(prm);
    f << "set Dimension = 2\n"
         "subsection Geometry\n  set Streamwise length = 2\nend\n"
         "subsection Mesh\n  set Global refinements = 2\nend\n"
         "subsection Material\n  set Viscosity = 0.1\nend\n"
         "subsection Statistics\n  set Enabled = true\n  set Number of bins = 8\nend\n";
  }
  const auto parameters = Parameters::read(prm, 2);
  std::remove(prm.c_str());

  parallel::distributed::Triangulation<2> tria(MPI_COMM_WORLD);
  Scene<2>                                scene(parameters);
  scene.create_mesh(tria);
  Fluid::FluidSpace<2> space(tria, 2, 1);
  space.setup(scene);

  Postprocess::ChannelStatistics<2> statistics(parameters, MPI_COMM_WORLD);
  for (const double a : {0.1, 0.2})
    {
      Fluid::VectorType owned(space.owned_velocity, MPI_COMM_WORLD);
      VectorTools::interpolate(space.dof_velocity, Velocity(a), owned);
      Fluid::VectorType ghosted(space.owned_velocity, space.relevant_velocity, MPI_COMM_WORLD);
      ghosted = owned;
      statistics.sample(space, ghosted, a, 0.3 + a, nullptr, nullptr);
    }

  std::stringstream saved;
  statistics.save(saved);
  Postprocess::ChannelStatistics<2> restarted(parameters, MPI_COMM_WORLD);
  restarted.load(saved);
  std::stringstream saved_again;
  restarted.save(saved_again);
  std::ostringstream summary, summary_restarted;
  statistics.print_summary(summary, 0., false);
  restarted.print_summary(summary_restarted, 0., false);

  if (Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0)
    {
      std::ofstream out("output");
      out << summary.str();
      out << "save -> load -> save gives the same text: "
          << (saved.str() == saved_again.str() ? "yes" : "no") << std::endl;
      out << "same summary after load: "
          << (summary.str() == summary_restarted.str() ? "yes" : "no") << std::endl;
    }
}
