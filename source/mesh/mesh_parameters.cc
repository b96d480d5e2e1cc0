// The parameters of the mesh: initial refinement and adaptivity.
#include <deal.II/base/utilities.h>

#include <suspension/core/parameter_parsing.h>
#include <suspension/mesh/mesh_parameters.h>

namespace Suspension::Parameters
{
  using namespace dealii;
  using namespace Parsing;

  // -------------------------------------------------------------------- Mesh
  void Mesh::declare(ParameterHandler &prm)
  {
    const Mesh d;
    prm.enter_subsection("Mesh");
    prm.declare_entry("Global refinements",
                      std::to_string(d.global_refinements),
                      Patterns::Integer(0, 12),
                      "Number of times every base cell is refined.");
    prm.declare_entry("Refinement region",
                      "",
                      Patterns::Anything(),
                      "Function expression of x, y[, z]: cells whose centre "
                      "makes it positive are refined 'Region refinements' "
                      "more times (a hand-made locally refined mesh with "
                      "hanging nodes). Empty: none.");
    prm.declare_entry("Region refinements",
                      std::to_string(d.region_refinements),
                      Patterns::Integer(0, 6),
                      "Extra refinement levels inside 'Refinement region'.");
    prm.leave_subsection();
  }

  void Mesh::parse(ParameterHandler &prm, const unsigned int dim)
  {
    prm.enter_subsection("Mesh");
    global_refinements = prm.get_integer("Global refinements");
    refinement_region  = Utilities::trim(prm.get("Refinement region"));
    region_refinements = prm.get_integer("Region refinements");
    prm.leave_subsection();
    if (!refinement_region.empty())
      check_expression("Mesh/Refinement region",
                       {refinement_region, ""},
                       1,
                       dim);
  }

  // ---------------------------------------------------------- MeshRefinement
  void MeshRefinement::declare(ParameterHandler &prm)
  {
    const MeshRefinement d;
    prm.enter_subsection("Mesh refinement");
    prm.declare_entry("Adaptive", d.enabled ? "true" : "false", Patterns::Bool(),
                      "Adapt the mesh to the solid interface (and the velocity) "
                      "during the run. The criteria below combine: each asks "
                      "for a level per cell, the largest wins.");
    prm.declare_entry("Minimum level", std::to_string(d.minimum_level),
                      Patterns::Integer(0, 16),
                      "Coarsest level allowed (refinements of the base mesh). "
                      "Equal to 'Maximum level': a uniform mesh reached "
                      "through the adaptive machinery.");
    prm.declare_entry("Maximum level", std::to_string(d.maximum_level),
                      Patterns::Integer(0, 16),
                      "Finest level: the interface band is refined to it. At "
                      "least 'Mesh/Global refinements'.");
    prm.declare_entry("Interface threshold", "0.001", Patterns::Double(0, 0.5),
                      "A cell belongs to the interface where epsilon < phi < "
                      "1 - epsilon at one of its nodes or quadrature points.");
    prm.declare_entry("Buffer cells", std::to_string(d.buffer_cells),
                      Patterns::Integer(0, 20),
                      "The interface band is widened by this many cells "
                      "(face neighbours) on each side, so that the interface "
                      "stays on the finest level between two adaptations.");
    prm.declare_entry("Solid level", std::to_string(d.solid_level),
                      Patterns::Integer(0, 16),
                      "Level inside the solid (phi > 1/2, B varies there); 0: "
                      "none.");
    prm.declare_entry("Velocity refine fraction", "0", Patterns::Double(0, 1),
                      "Kelly estimator on the velocity: the cells holding this "
                      "fraction of the estimated error are refined one level "
                      "(up to the maximum); 0 switches the estimator off.");
    prm.declare_entry("Velocity coarsen fraction", "0", Patterns::Double(0, 1),
                      "... and those holding this fraction may be coarsened.");
    prm.declare_entry("Region", "", Patterns::Anything(),
                      "Function expression of x, y[, z]: cells whose centre "
                      "makes it positive are kept at 'Region level' at least "
                      "(for example a wall band, abs(y) > 0.8). Empty: none.");
    prm.declare_entry("Region level", std::to_string(d.region_level),
                      Patterns::Integer(0, 16), "Level inside 'Region'.");
    prm.declare_entry("Interval", std::to_string(d.interval), Patterns::Integer(0),
                      "Adapt every this many steps; 0: from the CFL number, "
                      "so that the interface cannot cross 'Buffer fraction' "
                      "of the buffer between two adaptations (doc/method.md).");
    prm.declare_entry("Buffer fraction", "0.5", Patterns::Double(0.05, 1.),
                      "With Interval = 0: adapt once the fastest material "
                      "point (with 'Adaptation speed = interface': the "
                      "interface) may have moved this fraction of 'Buffer "
                      "cells' finest cells. Larger: fewer adaptations, a "
                      "thinner margin before the interface leaves the finest "
                      "band.");
    prm.declare_entry("Adaptation speed", "fastest fluid",
                      Patterns::Selection("fastest fluid|interface"),
                      "With Interval = 0, the speed whose distance 'Buffer "
                      "fraction' counts: the fastest fluid anywhere, or the "
                      "interface's (the largest |u| over the cells it "
                      "crosses; not with Kelly refinement), which also "
                      "adapts at once when an interface cell comes within "
                      "max(1, floor((1 - fraction) x buffer cells)) cells of "
                      "a coarser one. 'interface' suits one particle in a "
                      "fast flow (the cavity: 158 instead of 198 "
                      "adaptations); with many particles the margin fires "
                      "often (the main job: 196 instead of 82).");
    prm.declare_entry("Initial cycles", std::to_string(d.initial_cycles),
                      Patterns::Integer(0, 20),
                      "Adapt-and-reinitialise cycles on the initial condition; "
                      "0: maximum level - global refinements + 2.");
    prm.leave_subsection();
  }

  void MeshRefinement::parse(ParameterHandler &prm, const unsigned int dim, const Mesh &mesh)
  {
    prm.enter_subsection("Mesh refinement");
    enabled             = prm.get_bool("Adaptive");
    minimum_level       = prm.get_integer("Minimum level");
    maximum_level       = prm.get_integer("Maximum level");
    interface_threshold = prm.get_double("Interface threshold");
    buffer_cells        = prm.get_integer("Buffer cells");
    solid_level         = prm.get_integer("Solid level");
    refine_fraction     = prm.get_double("Velocity refine fraction");
    coarsen_fraction    = prm.get_double("Velocity coarsen fraction");
    region              = Utilities::trim(prm.get("Region"));
    region_level        = prm.get_integer("Region level");
    interval            = prm.get_integer("Interval");
    buffer_fraction     = prm.get_double("Buffer fraction");
    interface_speed     = prm.get("Adaptation speed") == "interface";
    initial_cycles      = prm.get_integer("Initial cycles");
    prm.leave_subsection();
    if (!enabled)
      return;
    if (maximum_level < mesh.global_refinements)
      throw InputError("Mesh refinement/Maximum level",
                       "must be at least 'Mesh/Global refinements' (" +
                         std::to_string(mesh.global_refinements) + ")");
    if (minimum_level > maximum_level)
      throw InputError("Mesh refinement/Minimum level", "must be at most 'Maximum level'");
    if (solid_level > maximum_level || region_level > maximum_level)
      throw InputError(solid_level > maximum_level ? "Mesh refinement/Solid level" :
                                                     "Mesh refinement/Region level",
                       "must be at most 'Maximum level'");
    if (refine_fraction + coarsen_fraction > 1.)
      throw InputError("Mesh refinement/Velocity coarsen fraction",
                       "refine and coarsen fractions add up to more than 1");
    if (!region.empty())
      check_expression("Mesh refinement/Region", {region, ""}, 1, dim);
    if (!mesh.refinement_region.empty())
      throw InputError("Mesh/Refinement region",
                       "a hand-made region and an adaptive mesh do not mix; use "
                       "'Mesh refinement/Region'");
    if (initial_cycles == 0)
      initial_cycles = maximum_level - std::min(mesh.global_refinements, minimum_level) + 2;
  }
} // namespace Suspension::Parameters
