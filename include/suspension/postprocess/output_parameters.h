#pragma once

#include <deal.II/base/parameter_handler.h>

#include <suspension/core/parameter_basics.h>

#include <string>
#include <vector>

/// What a run writes and checks: 'Output', 'Statistics', 'Verification'
/// (postprocess/output_parameters.cc).
namespace Suspension::Parameters
{
  using dealii::ParameterHandler;

  struct Output
  {
    std::string                     directory = "output";
    bool                            write_vtu = true;
    bool                            write_phi_cells = false;
    unsigned int                    patch_subdivisions = 0; // 0: the velocity degree
    unsigned int                    interval_steps = 0;
    double                          interval_time  = 0.;
    std::vector<std::vector<double>> probe_points;
    unsigned int                    progress_interval = 10;
    unsigned int                    statistics_interval = 1; // steps per row of statistics.txt
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
    /// |area(phi >= 1/2) / int phi(0) - 1| of the single particle at most
    /// this at every step (0: off)
    double              area_tolerance = 0.;

    static void declare(ParameterHandler &prm, unsigned int dim);
    void        parse(ParameterHandler &prm, unsigned int dim);
  };
} // namespace Suspension::Parameters
