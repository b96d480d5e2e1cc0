#pragma once

#include <array>

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
#include <suspension/postprocess/field_output.h>
#include <suspension/postprocess/flow_verification.h>
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
   * choose dt -> fluid step -> diagnostics -> statistics, output, progress.
   */
  template <int dim>
  class Simulation
  {
  public:
    Simulation(const Parameters::All &parameters, MPI_Comm communicator);
    RunSummary run();

  private:
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
    void   create_initial_mesh();
    bool   adapt_mesh();
    void   change_mesh_with_fields();
    double choose_time_step(double dt, double time, const Fluid::FlowDiagnostics &d) const;
    bool   output_due(double time, double dt) const;
    void   write_output();
    void   write_probes();
    void   add_statistics_row(const Fluid::StepReport &r, const Fluid::FlowDiagnostics &d,
                              double dt, double wall_time);
    void   add_solid_statistics(const Solid::SolidDiagnostics &d);
    void   update_contact_force();
    void   add_contact_statistics();
    void   report_contact() const;
    void   add_mesh_statistics(const MeshLevels &levels, bool adapted, double adapt_time);
    /// 'Verification/Exact solid at probes': errors of phi and B there
    void   report_solid_probes();
    void   report_solid();
    double smallest_cell() const;
    void   report_errors(double time, bool steady);
    void   report_verdicts(bool steady);
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
    Solid::ContactDiagnostics                 contact_diagnostics;
    /// over the whole run: closest gaps, fewest and most particles seen
    double                                    closest_gap_seen = -1., closest_wall_seen = -1.;
    double                                    smallest_contact_cell = 0.;
    unsigned int fewest_particles = std::numeric_limits<unsigned int>::max(), most_particles = 0;
    double                                    phi_l1_error = -1., phi_cell_l1_error = -1.;
    Postprocess::FieldOutput<dim>             field_output;
    Postprocess::FlowVerification<dim>        verification;
    std::unique_ptr<Postprocess::ChannelStatistics<dim>> channel_statistics;
    TableHandler                              statistics, probes;
    Postprocess::FlowErrors                   last_errors;
    std::vector<std::pair<double, Postprocess::FlowErrors>> error_history;
    std::vector<std::array<double, 3>>                        deformation_history;
    std::vector<std::string>                  last_probe_values;
    double                                    smallest_cell_size = 0.; // per mesh
    double                                    last_output_time   = 0.;
    double                                    last_driving_force = 0.;
    types::global_cell_index                  worst_coarse_interface = 0; // over all steps
    unsigned int                              n_adaptations          = 0;
    unsigned int                              n_outputs              = 0;
    Checkpoint<dim>                           checkpoint;
    double wall_time_before = 0.; // of the run up to the checkpoint it resumed from
  };
} // namespace Suspension
