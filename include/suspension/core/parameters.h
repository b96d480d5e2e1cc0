#pragma once

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/point.h>

#include <array>
#include <map>
#include <string>
#include <vector>

/**
 * Run-time parameters, one struct per subsection of the .prm file.
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

  /// A parse error in the user's input: which entry, and what is wrong.
  struct InputError : std::runtime_error
  {
    InputError(const std::string &entry, const std::string &message)
      : std::runtime_error("entry '" + entry + "': " + message)
    {}
  };

  /// A function expression with its constants; the variables are
  /// x, y[, z], t. Components are separated by ';'.
  struct FunctionExpression
  {
    std::string expression;
    std::string constants;
    std::map<std::string, double> constant_map() const;
    bool        is_zero() const;
  };

  enum class GeometryType
  {
    channel,
    box
  };

  struct Geometry
  {
    GeometryType type = GeometryType::channel;
    // channel: x in [0, Lx], (3D) y in [0, Ly], wall-normal in [-h, h]
    double streamwise_length = 6.;
    double spanwise_length   = 3.;
    double half_height       = 1.;
    // box
    std::vector<double> box_lower{0., 0., 0.};
    std::vector<double> box_upper{1., 1., 1.};
    // base cells per direction; empty: cells of aspect ratio one
    std::vector<unsigned int> subdivisions;
    bool                      subdivisions_given = false;

    static void declare(ParameterHandler &prm, unsigned int dim);
    void        parse(ParameterHandler &prm, unsigned int dim);
  };

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
    unsigned int initial_cycles      = 0;    // 0: maximum - global + 2

    static void declare(ParameterHandler &prm);
    void        parse(ParameterHandler &prm, unsigned int dim, const Mesh &mesh);
  };

  enum class BoundaryType
  {
    no_slip,
    velocity,
    periodic
  };

  /// Faces are numbered as GridGenerator colours them:
  /// 0 = x-, 1 = x+, 2 = y-, 3 = y+, 4 = z-, 5 = z+.
  struct BoundaryConditions
  {
    std::array<BoundaryType, 6>       type;
    std::array<FunctionExpression, 6> velocity;

    BoundaryConditions();
    static std::string face_name(unsigned int face);
    static void        declare(ParameterHandler &prm, unsigned int dim);
    void               parse(ParameterHandler &prm, unsigned int dim);
  };

  enum class FlowDrivingType
  {
    none,
    constant_flow_rate,
    constant_pressure_gradient
  };

  struct FlowDriving
  {
    FlowDrivingType    type          = FlowDrivingType::none;
    double             bulk_velocity = 1.;
    double             pressure_gradient = 0.; // driving force -dp/dx
    FunctionExpression body_force{"", ""};

    static void declare(ParameterHandler &prm, unsigned int dim);
    void        parse(ParameterHandler &prm, unsigned int dim);
  };

  struct Material
  {
    double density   = 1.;
    double viscosity = 1.;

    static void declare(ParameterHandler &prm);
    void        parse(ParameterHandler &prm);
  };

  struct InitialConditions
  {
    FunctionExpression velocity{"", ""};

    static void declare(ParameterHandler &prm, unsigned int dim);
    void        parse(ParameterHandler &prm, unsigned int dim);
  };

  enum class ProjectionForm
  {
    rotational,
    standard
  };

  enum class ConvectionForm
  {
    skew_symmetric,
    none
  };

  enum class VelocityMode
  {
    navier_stokes,
    prescribed
  };

  struct FluidSolver
  {
    VelocityMode       mode = VelocityMode::navier_stokes;
    FunctionExpression prescribed_velocity{"", ""};
    unsigned int   velocity_degree = 2;
    unsigned int   pressure_degree = 1;
    ProjectionForm projection      = ProjectionForm::rotational;
    ConvectionForm convection      = ConvectionForm::skew_symmetric;
    double         solver_tolerance = 1e-10;
    bool           jacobi_momentum  = false; // else BoomerAMG
    bool           matrix_free_momentum = true; // else assembled M, K, A

    static void declare(ParameterHandler &prm, unsigned int dim);
    void        parse(ParameterHandler &prm, unsigned int dim);
  };

  enum class InitialFraction
  {
    none,
    particles,
    random_particles,
    function
  };

  /// The solid phase: initial fraction, elasticity, DG transport.
  struct Solid
  {
    InitialFraction                  initial_fraction = InitialFraction::none;
    std::vector<std::vector<double>> particles; // centre..., radius
    double                           interface_width = 0.; // in cells; 0: exact cell fractions
    std::string                      fraction_expression;
    std::string                      constants;
    double                           shear_modulus = 0.;
    unsigned int                     degree        = 1;
    bool                             limiter       = true;
    double                           transport_cfl = 0.5;
    double                           elastic_number = 0.5;
    /// semi-implicit: the stress increment dt G phi (grad u B + B grad u^T),
    /// linear in the new velocity, goes into the momentum predictor
    bool                             semi_implicit = false;
    /// stress G H(phi) (B - I): H a smooth step across 1/2 (sharp) or phi
    bool                             sharp_stress        = true;
    double                           stress_weight_width = 0.2;
    double                           interface_compression = 0.; // c of the compressive flux
    double                           interface_thickness   = 0.25; // eps / h of its diffusion
    /// THINC profile of phi in interface cells for the transport fluxes
    bool                             thinc_reconstruction = true;
    double                           thinc_sharpness      = 3.5; // beta, per cell
    bool                             thinc_curvature      = true; // curved profile
    double                           B_reset_fraction = -1.; // < 0: where H = 0
    double                           interface_relaxation = 0.; // R of B - I at rate R (1 - H)
    /// algebraic sharpening of phi after every `sharpening_interval` steps
    double                           interface_sharpening = 1.; // a; 1: off
    unsigned int                     sharpening_interval  = 1;
    /// force per unit volume of solid, applied as phi g (x, t)
    FunctionExpression               body_force{"", ""};

    /// 'Initial fraction = random particles': filled into `particles` by
    /// All::parse once the box and its periodic faces are known.
    struct Seeding
    {
      unsigned int n_particles     = 0;
      double       volume_fraction = 0.1;
      double       radius          = 0.1;
      double       minimum_gap     = 0.;
      double       wall_clearance  = 0.;
      unsigned int seed            = 1;
      unsigned int attempts        = 10000;
    } seeding;
    /// Short-range repulsion between particles and from walls (Rosti et
    /// al.): f = mu V r (a1/d + a2/d^2) n for gaps dx <= d <= range dx.
    struct Contact
    {
      std::string mode           = "auto"; // auto | on | off
      bool        enabled        = false;  // resolved by All::parse
      double      a1             = 550.;
      double      a2             = 35.;
      double      velocity_scale = 0.;     // 0: the bulk velocity
      double      radius         = 0.;     // 0: the particles' radius
      double      range          = 3.;     // in cells
    } contact;

    bool   seeded                  = false;
    double seeded_volume_fraction  = 0.;
    double seeded_closest_gap      = 0.;
    double seeded_closest_wall     = 0.;

    bool enabled() const { return initial_fraction != InitialFraction::none; }
    bool elastic() const { return enabled() && shear_modulus > 0.; }

    static void declare(ParameterHandler &prm, unsigned int dim);
    void        parse(ParameterHandler &prm, unsigned int dim);
  };

  struct TimeStepping
  {
    double       end_time           = 1.;
    double       time_step          = 1e-2;
    bool         adaptive           = false;
    double       cfl                = 0.5;
    double       maximum_time_step  = 1.;
    double       steady_tolerance   = 0.;
    unsigned int maximum_steps      = 0;

    static void declare(ParameterHandler &prm);
    void        parse(ParameterHandler &prm);
  };

  struct Output
  {
    std::string                     directory = "output";
    bool                            write_vtu = true;
    bool                            write_phi_cells = false;
    unsigned int                    interval_steps = 0;
    double                          interval_time  = 0.;
    std::vector<std::vector<double>> probe_points;
    unsigned int                    progress_interval = 10;
    bool                            timer_summary     = true;
    bool                            run_header        = true;

    static void declare(ParameterHandler &prm);
    void        parse(ParameterHandler &prm, unsigned int dim);
  };

  /// Channel statistics (Postprocess::ChannelStatistics): wall-normal
  /// profiles and bulk rheology averaged over samples in time.
  struct Statistics
  {
    bool         enabled         = false;
    double       start_time      = 0.;
    unsigned int sample_interval = 10; // steps
    unsigned int n_bins          = 64; // across the whole channel
    /// Stationarity: 0 takes it for granted from start_time on; > 0
    /// compares the means over the last two windows of this length
    double       steady_window    = 0.;
    double       steady_tolerance = 0.005; // relative change allowed
    /// 0: sample to the end time; > 0: end the run after this much
    /// statistically steady time
    double       sampling_time    = 0.;

    static void declare(ParameterHandler &prm);
    void        parse(ParameterHandler &prm);
  };

  enum class ExactSolutionType
  {
    none,
    function,
    channel_startup
  };

  enum class ReferenceData
  {
    none,
    ghia_re100
  };

  enum class StudyCases
  {
    grid,  // every Re x Ca x Phi
    paper  // the paper's seven (Re, Ca) pairs x Phi
  };

  /// A study of cases that differ in Re, Ca and Phi (scripts/study); the
  /// scene itself is the base case. Declared and parsed in
  /// core/study_cases.cc, next to the code that turns it into cases.
  struct Study
  {
    StudyCases          cases = StudyCases::grid;
    std::vector<double> reynolds_numbers, capillary_numbers, volume_fractions;
    std::string         directory = "output/study";
    unsigned int        ranks_per_case = 1;

    static void declare(ParameterHandler &prm);
    void        parse(ParameterHandler &prm);
  };

  /// What the run is compared with, and how a study repeats it.
  struct Verification
  {
    ExactSolutionType   exact_solution = ExactSolutionType::none;
    std::string         exact_fraction; // compared in L1 at the end
    std::string         exact_solid_at_probes; // phi; B components
    FunctionExpression  exact_velocity{"", ""};
    std::string         exact_pressure;
    std::vector<double> report_times;
    ReferenceData       reference_data = ReferenceData::none;
    unsigned int        refinement_cycles = 1;
    unsigned int        time_step_cycles  = 1;
    double              tolerance         = 0.;
    double              minimum_velocity_rate = 0.;
    double              minimum_pressure_rate = 0.;
    // a sweep over one entry, e.g. "Solid/Shear modulus"
    std::string         sweep_entry;
    std::vector<std::string> sweep_values;
    std::string         sweep_expected_deformation; // function of x = value
    double              sweep_agreement      = 0.; // |D_last / D_first - 1|
    double              sweep_cell_reduction = 0.; // cells_first / cells_last
    /// the D that 'Tolerance' and 'Steady tolerance' judge: the shape's
    /// (moments of H(phi)) or the material's stretch (mean B of the core)
    bool                sweep_material_deformation = false;
    /// |D(end) / D(first report time) - 1| of the single particle at most this (0: off)
    double              steady_tolerance = 0.;

    static void declare(ParameterHandler &prm, unsigned int dim);
    void        parse(ParameterHandler &prm, unsigned int dim);
  };

  /// All subsections together: what a Simulation is built from.
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

  /// Variable names for function expressions: "x,y,t" or "x,y,z,t".
  std::string variable_names(unsigned int dim);
} // namespace Suspension::Parameters
