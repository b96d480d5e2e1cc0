#pragma once

#include <deal.II/base/parameter_handler.h>

#include <suspension/core/parameter_basics.h>

#include <string>

/// 'Mesh' and 'Mesh refinement' (mesh/mesh_parameters.cc).
namespace Suspension::Parameters
{
  using dealii::ParameterHandler;

  struct Mesh
  {
    unsigned int global_refinements = 2;
    // cells whose centre makes this expression positive are refined
    // `region_refinements` more times (hanging nodes by hand)
    std::string  refinement_region;
    unsigned int region_refinements = 0;

    static void declare(ParameterHandler &prm);
    void        parse(ParameterHandler &prm, unsigned int dim);
  };

  /// Interface-adaptive meshes: which cells are refined, how often.
  /// Levels count refinements of the base mesh (cell->level()).
  struct MeshRefinement
  {
    bool         enabled             = false;
    unsigned int minimum_level       = 0;
    unsigned int maximum_level       = 0;
    double       interface_threshold = 1e-3; // epsilon < phi < 1 - epsilon
    unsigned int buffer_cells        = 3;
    unsigned int solid_level         = 0;    // 0: no extra level inside
    double       refine_fraction     = 0.;   // Kelly on the velocity; 0: off
    double       coarsen_fraction    = 0.;
    std::string  region;                     // expression > 0 at the centre
    unsigned int region_level        = 0;
    unsigned int interval            = 0;    // steps; 0: from the CFL number
    double       buffer_fraction     = 0.5;  // of the buffer crossed, Interval 0
    bool         interface_speed     = false; // time adaptations by the interface's speed
    unsigned int initial_cycles      = 0;    // 0: maximum - global + 2

    static void declare(ParameterHandler &prm);
    void        parse(ParameterHandler &prm, unsigned int dim, const Mesh &mesh);
  };
} // namespace Suspension::Parameters
