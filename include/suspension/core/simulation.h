#pragma once

#include <array>
#include <chrono>

#include <deal.II/base/conditional_ostream.h>
#include <deal.II/base/table_handler.h>
#include <deal.II/base/timer.h>
#include <deal.II/distributed/tria.h>

#include <suspension/core/checkpoint.h>
#include <suspension/core/parameters.h>
#include <suspension/core/scene.h>
#include <suspension/fluid/fluid_operators.h>
#include <suspension/fluid/fluid_space.h>
#include <suspension/fluid/projection_scheme.h>
#include <suspension/mesh/mesh_adaptor.h>
#include <suspension/postprocess/channel_statistics.h>
#include <suspension/postprocess/contact_report.h>
#include <suspension/postprocess/solid_report.h>
#include <suspension/postprocess/field_output.h>
#include <suspension/postprocess/flow_verification.h>
#include <suspension/postprocess/mesh_report.h>
#include <suspension/postprocess/probe_report.h>
#include <suspension/postprocess/verification_report.h>
#include <suspension/solid/contact_force.h>
#include <suspension/solid/solid_phase.h>

#include <limits>
#include <memory>
#include <vector>

namespace Suspension
{
  /// What a finished run reports to a study: its errors and resolution.
  struct RunSummary
  {
    Postprocess::FlowErrors final_errors;
    double                  phi_l1_error = -1.; // < 0: not computed
    double                  phi_cell_l1_error = -1.; // of the cell means (VOF papers' measure)
    double                  deformation = 0., inclination = 0.; // one particle
    double                  deformation_B = 0., inclination_B = 0.; // its material stretch
    /// (t, D, D_B) of the single particle at the report times
    std::vector<std::array<double, 3>> deformation_history;
    /// errors at the report times and at the end, in time order
    std::vector<std::pair<double, Postprocess::FlowErrors>> errors;
    double                  smallest_cell = 0.;
    double                  time_step     = 0.;
    unsigned int            n_steps       = 0;
    types::global_dof_index n_dofs        = 0;
    types::global_cell_index n_cells      = 0; // at the end
  };

  /**
   * One run of a scene: builds the mesh and the parts, then advances in
   * time. Owns nothing numerical itself; run() reads as the time step:
   * choose dt -> advance (transport, forces, fluid) -> check the flow ->
   * record (statistics) -> adapt the mesh -> reports -> output, progress,
   * checkpoint; a failure anywhere writes the last state once.
   */
  template <int dim>
  class Simulation
  {
  public:
    Simulation(const Parameters::All &parameters, MPI_Comm communicator);
    RunSummary run();

  private:
    /// setup() or resume(), the opening reports and the first output;
    /// returns the time step to begin with
    double start();
    /// not yet at the end time, steady, sampled enough or the step limit
    bool   running() const;
    bool   sampled_enough() const;
    /// the solid, the contact force and the fluid over one time step
    Fluid::StepReport advance(double dt);
    /// diagnostics of the new flow; throws if it is not finite
    void   check_flow();
    void   record_step(const Fluid::StepReport &report, double dt, double wall_time);
    void   adapt_if_due(double dt);
    /// 'Verification/Report times': errors, probes, the particle's shape
    void   report_at_times(double dt);
    void   write_if_due(double dt);
    /// output and tables of a failed run (errors while writing ignored)
    void   write_last_state();
    /// the last output, the end-of-run reports and the summary
    RunSummary finish(double dt);
    /// wall seconds of the run, including those before a resume
    double elapsed() const;
    void   setup();
    /// Instead of setup() with --resume: the mesh, fields and scalars of
    /// the last checkpoint. Returns the time step to continue with.
    double resume();
    void   report_seeding() const;
    void   write_checkpoint(double dt, double wall_time);
    /// Every scalar the next step and the final report depend on, and the
    /// parts' own (text; see Checkpoint).
    std::string save_state(double dt, double wall_time) const;
    /// Returns dt.
    double load_state(const std::string &state, const std::string &path);
    /// The first line of a checkpoint's state: what a resumed run must
    /// match before p4est reads the mesh (dimension, coarse cells, finite
    /// elements), and the rank count it was written on.
    std::string checkpoint_header() const;
    /// The scene's mesh, refined towards the initial interface. Returns
    /// true if the space and the solid are already set up on it (the last
    /// cycle flagged nothing), so that setup() does not build them twice.
    bool   create_initial_mesh();
    bool   adapt_mesh();
    void   change_mesh_with_fields();
    double choose_time_step(double dt, double time, const Fluid::FlowDiagnostics &d) const;
    /// dt cut to a whole number of transport sub-steps when that is cheaper
    /// ('Time stepping/Transport sub-step cost')
    double fit_to_transport_substeps(double dt, double speed_over_h) const;
    bool   output_due(double time, double dt) const;
    void   write_output();
    void   add_statistics_row(const Fluid::StepReport &r, const Fluid::FlowDiagnostics &d,
                              double dt, double wall_time);
    void   update_contact_force();
    double smallest_cell() const;
    void   print_progress(double dt, const Fluid::FlowDiagnostics &d, double elapsed) const;
    void   write_tables() const;
    void   sample_statistics(double driving_force);

    const Parameters::All                    &parameters;
    MPI_Comm                                  communicator;
    ConditionalOStream                        pcout;
    mutable TimerOutput                       timer;
    parallel::distributed::Triangulation<dim> triangulation;
    Scene<dim>                                scene;
    MeshAdaptor<dim>                          adaptor;
    Fluid::FluidSpace<dim>                    space;
    Fluid::FluidOperators<dim>                operators;
    Fluid::ProjectionScheme<dim>              fluid;
    std::unique_ptr<Fluid::MomentumSource<dim>> body_force;
    std::unique_ptr<Function<dim>>            prescribed_velocity;
    std::unique_ptr<Solid::SolidPhase<dim>>   solid;
    Solid::SolidDiagnostics                   solid_diagnostics;
    std::unique_ptr<Solid::ContactForce<dim>> contact;
    std::unique_ptr<Postprocess::ContactReport> contact_report;
    std::unique_ptr<Postprocess::SolidReport<dim>> solid_report;
    std::unique_ptr<Postprocess::MeshReport>  mesh_report;
    std::unique_ptr<Postprocess::ProbeReport<dim>> probe_report;
    Postprocess::VerificationReport<dim>      verification_report;
    Postprocess::FieldOutput<dim>             field_output;
    std::unique_ptr<Postprocess::ChannelStatistics<dim>> channel_statistics;
    TableHandler                              statistics;
    double                                    smallest_cell_size = 0.; // per mesh
    /// memory per rank estimated for the initial (refined) mesh, bytes
    double                                    initial_memory_estimate = 0.;
    double                                    last_output_time   = 0.;
    double                                    last_driving_force = 0.;
    bool                                      statistics_row     = true; // this step adds a row
    unsigned int                              n_outputs          = 0;
    /// steps and transport sub-steps of this run (since its start or resume)
    unsigned long                             steps_run = 0, transport_substeps_run = 0;
    Checkpoint<dim>                           checkpoint;
    double wall_time_before = 0.; // of the run up to the checkpoint it resumed from
    /// the step loop's state
    std::vector<const Fluid::MomentumSource<dim> *> sources;
    Fluid::FlowDiagnostics                          flow_diagnostics;
    bool                                            steady = false;
    std::chrono::steady_clock::time_point           run_start;
  };
} // namespace Suspension
