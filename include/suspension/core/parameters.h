#pragma once

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/point.h>

#include <suspension/core/parameter_basics.h>
#include <suspension/core/scene_parameters.h>
#include <suspension/core/study_parameters.h>
#include <suspension/fluid/fluid_parameters.h>
#include <suspension/mesh/mesh_parameters.h>
#include <suspension/postprocess/output_parameters.h>
#include <suspension/solid/solid_parameters.h>

#include <string>
#include <utility>
#include <vector>

/**
 * Run-time parameters, one struct per subsection of the .prm file, each
 * declared in its area's header (fluid/fluid_parameters.h, ...) next to
 * the file that parses it; this header assembles them into All.
 *
 * Each struct declares its entries (with a Pattern and a sentence of
 * documentation) and parses them back; defaults live only in the member
 * initialisers. Checks that need more than a Pattern (lists of the right
 * length, function expressions that parse, periodic faces in pairs) are done
 * in parse() and reported as InputError, so that a bad file is rejected
 * before anything is written.
 *
 * Dimensionless convention used by all shipped scenes: half-height h = 1,
 * bulk velocity V_b = 1, density rho = 1, hence viscosity mu = 1/Re_b.
 */
namespace Suspension::Parameters
{
  using dealii::ParameterHandler;

  struct TimeStepping
  {
    double       end_time           = 1.;
    double       time_step          = 1e-2;
    bool         adaptive           = false;
    double       cfl                = 0.5;
    double       maximum_time_step  = 1.;
    /// cost of a transport sub-step over that of a fluid step (0: the
    /// step is not fitted to the sub-steps)
    double       substep_cost       = 0.;
    double       steady_tolerance   = 0.;
    unsigned int maximum_steps      = 0;

    static void declare(ParameterHandler &prm);
    void        parse(ParameterHandler &prm);
  };

  /// Checkpoints to <Output directory>/checkpoint/ for `suspension FILE.prm
  /// --resume`.
  struct Checkpoint
  {
    unsigned int interval_steps   = 0;
    double       interval_minutes = 0.;
    /// Set from the command line (--resume), not from the file.
    bool resume = false;

    static void declare(ParameterHandler &prm);
    void        parse(ParameterHandler &prm);
  };

  /// All subsections together: what a Simulation is built from.
  struct All
  {
    unsigned int       dimension = 2;
    std::string        input_file;
    /// the command line's --set entries, applied after the file (a sweep
    /// re-reads the file with them)
    std::vector<std::pair<std::string, std::string>> overrides;
    /// every entry as used (file and overrides), in .prm form: the run
    /// record (RunRecord) writes it to the output directory
    std::string        parameters_used;
    Geometry           geometry;
    Mesh               mesh;
    MeshRefinement     mesh_refinement;
    BoundaryConditions boundary_conditions;
    FlowDriving        flow_driving;
    Material           material;
    InitialConditions  initial_conditions;
    FluidSolver        fluid_solver;
    Solid              solid;
    TimeStepping       time_stepping;
    Output             output;
    Statistics         statistics;
    Verification       verification;
    Checkpoint         checkpoint;
    Study              study;

    static void declare(ParameterHandler &prm, unsigned int dim);
    void        parse(ParameterHandler &prm, unsigned int dim);

  private:
    /// Initial fraction = random particles: places them (InputError if
    /// they do not fit).
    void seed_solid(unsigned int dim);
    /// 'Solid/Contact force': on or off, and its defaults (radius, speed).
    /// explicit particles inside the box, apart from the walls and each other
    void check_particles(unsigned int dim) const;
    /// probe points inside the box
    void check_probes(unsigned int dim) const;
    void resolve_contact_force();
  };

  /// Reads only `Dimension` from a file (other entries are skipped).
  unsigned int read_dimension(const std::string &filename);

  /// Declares, reads and checks the whole file for the given dimension.
  /// Throws InputError (or a deal.II exception from ParameterHandler).
  All read(const std::string &filename, unsigned int dim,
           const std::vector<std::pair<std::string, std::string>> &overrides = {});

} // namespace Suspension::Parameters
