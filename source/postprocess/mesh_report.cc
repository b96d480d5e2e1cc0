#include <suspension/postprocess/mesh_report.h>

#include <algorithm>
#include <istream>
#include <ostream>

namespace Suspension::Postprocess
{
  MeshReport::MeshReport(const bool with_solid)
    : with_solid(with_solid)
  {}

  void MeshReport::record(TableHandler &statistics, const bool row, const MeshLevels &levels,
                          const bool adapted, const double seconds)
  {
    worst_coarse_interface = std::max(worst_coarse_interface, levels.coarse_interface_cells);
    if (adapted)
      ++n_adaptations;
    if (!row)
      return;
    statistics.add_value("level_min", levels.min_level);
    statistics.add_value("level_max", levels.max_level);
    statistics.add_value("cells_finest", static_cast<unsigned long long>(levels.cells_on_finest));
    if (with_solid)
      statistics.add_value("coarse_interface_cells",
                           static_cast<unsigned long long>(levels.coarse_interface_cells));
    statistics.add_value("adapted", adapted ? 1 : 0);
    statistics.add_value("wall_time_adapt", seconds);
    statistics.set_scientific("wall_time_adapt", true);
    statistics.set_precision("wall_time_adapt", 4);
  }

  void MeshReport::report(std::ostream &out, const types::global_cell_index n_cells) const
  {
    out << "  mesh: " << n_adaptations << " adaptations, now " << n_cells << " cells";
    if (with_solid)
      out << "; interface cells below the finest level, most in any step: "
          << worst_coarse_interface;
    out << std::endl;
  }

  void MeshReport::save(std::ostream &out) const
  {
    out << n_adaptations << ' ' << static_cast<unsigned long long>(worst_coarse_interface);
  }

  void MeshReport::load(std::istream &in)
  {
    unsigned long long worst = 0;
    in >> n_adaptations >> worst;
    worst_coarse_interface = worst;
  }
} // namespace Suspension::Postprocess
