#pragma once

#include <suspension/core/parameters.h>
#include <suspension/core/scene.h>
#include <suspension/fluid/fluid_operators.h>
#include <suspension/fluid/fluid_space.h>
#include <suspension/fluid/momentum_right_hand_side.h>
#include <suspension/fluid/momentum_source.h>

#include <deal.II/base/timer.h>
#include <deal.II/distributed/solution_transfer.h>

#include <iosfwd>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace Suspension::Fluid
{
  /// What one step did: linear iterations and the mean pressure gradient.
  struct StepReport
  {
    unsigned int momentum_iterations   = 0;
    unsigned int projection_iterations = 0;
    unsigned int mass_iterations       = 0;
    double       driving_force         = 0.; // -dp/dx (force per volume)
    bool         matrices_rebuilt      = false;
  };

  /// Integral quantities of the velocity at the end of a step.
  struct FlowDiagnostics
  {
    double kinetic_energy      = 0.; // (rho/2) integral |u|^2
    double bulk_velocity       = 0.; // integral u_x / |Omega|
    double max_speed_over_h    = 0.; // max over cells of |u| k / h
    double divergence_l2       = 0.; // || Pi div u ||, Pi: L2 projection
    double max_speed           = 0.;
  };

  /**
   * Incremental pressure-correction projection in rotational form with
   * BDF2 (Guermond, Minev & Shen 2006, Comput. Methods Appl. Mech. Engrg.
   * 195), kinematic pressure P = p / rho, nu = mu / rho:
   *
   *  1. momentum  (alpha u^{n+1} - beta_1 u^n + beta_2 u^{n-1}) / dt
   *               - nu lap u^{n+1} = - (u*.grad) u* - div(u*) u* / 2
   *               - grad P# + (f + div tau) / rho + F e_x / rho,
   *     u* and P# = P^n + (4 psi^n - psi^{n-1}) / 3 extrapolated,
   *  2. flow rate F chosen so that the bulk velocity is exact: by linearity
   *     u^{n+1} = u_0 + F u_1 with u_1 the (stored) response to a unit force,
   *  3. projection  -lap psi^{n+1} = -(alpha / dt) div u^{n+1}, Neumann,
   *  4. pressure    P^{n+1} = P^n + psi^{n+1} - nu Pi div u^{n+1}.
   *
   * Convection is explicit, so the momentum matrix is constant between
   * mesh or time-step changes. The first step is BDF1; variable steps use
   * the variable-step BDF2 coefficients.
   */
  template <int dim>
  class ProjectionScheme
  {
  public:
    ProjectionScheme(const Parameters::All &parameters,
                     const Scene<dim>      &scene,
                     const FluidSpace<dim> &space,
                     FluidOperators<dim>   &operators);

    /// Optional: time the sub-steps in these sections.
    void set_timer(TimerOutput &timer) { this->timer = &timer; }

    /// Allocates the time levels and sets u^0 from the scene (or from
    /// `velocity`, a prescribed field, as it is), P^0 = 0.
    void initialize(Function<dim> *velocity = nullptr);

    /// Before the mesh changes: hands the time levels the next step reads
    /// (u^n, u^{n-1}, P^n, psi^n, psi^{n-1}) to SolutionTransfer.
    void prepare_for_mesh_change();

    /// After the mesh changed (the space and, unless the velocity is
    /// prescribed, the operators rebuilt): the time levels on the new
    /// mesh, hanging-node and periodic constraints applied. A prescribed
    /// velocity is interpolated afresh instead.
    void finish_mesh_change(Function<dim> *prescribed_velocity = nullptr);

    /// Checkpoint: hands the same time levels, and Pi div u (the initial
    /// guess of the next mass solve), to the triangulation's next save() (SolutionTransfer::prepare_for_serialization); the copies
    /// live until checkpoint_written().
    void prepare_for_checkpoint();
    void checkpoint_written();

    /// After Triangulation::load() of a checkpoint and the space (and
    /// operators) set up: the time levels back, as they were saved (no
    /// constraints applied: they hold already). Call load() too.
    void resume_from_checkpoint();

    /// Time, step number and last step size (text, full precision).
    void save(std::ostream &out) const;
    void load(std::istream &in);

    /// Advances from the current time by dt.
    StepReport advance(double dt, const std::vector<const MomentumSource<dim> *> &sources);

    /// Prescribed-velocity mode: u^{n+1} is the interpolant of `velocity`
    /// at t + dt; nothing is solved and no matrix is needed.
    void prescribe(double dt, Function<dim> &velocity);

    /// Velocity extrapolated to t + dt from the last two levels (for the
    /// transport of the solid over the coming step).
    VectorType extrapolated_velocity(double dt) const;

    FlowDiagnostics compute_diagnostics() const;

    /// max |u^{n+1} - u^n| / (dt max |u^{n+1}|)
    double relative_change_rate() const;

    double time() const { return current_time; }
    unsigned int step_number() const { return n_steps; }

    /// Bytes per part of the fluid on this rank (the run summary's
    /// memory line): DoFHandlers, constraints, MatrixFree, the assembled
    /// matrices (entries and column indices, without BoomerAMG's
    /// hierarchy), vectors.
    std::vector<std::pair<std::string, std::size_t>> memory_by_part() const;

    const VectorType &velocity() const { return velocity_ghosted; }
    /// Kinematic pressure P = p / rho (ghosted).
    const VectorType &kinematic_pressure() const { return pressure_ghosted; }

  private:
    /// rhs_u from `load`'s fields (the coefficients and sources are
    /// filled in here)
    void       assemble_momentum_rhs(MomentumLoad<dim> &load, double dt, double t_new,
                                     const std::vector<const MomentumSource<dim> *> &sources);
    /// max_i |a_i - b_i| over the locally owned entries of all ranks,
    /// without a temporary vector
    double     max_difference(const VectorType &a, const VectorType &b) const;
    void       allocate_vectors();
    /// Ghosted copies of the transferred time levels, handed to new
    /// SolutionTransfer objects.
    void       attach_time_levels(bool serialization);
    /// The response to a unit pressure gradient for the present alpha/dt,
    /// starting from the last one scaled by the ratio of the coefficients
    /// (the operator is mass-dominated, so the response scales nearly as
    /// dt / alpha), or from zero after a mesh change.
    void       update_unit_response();
    double     flux(const VectorType &u) const;

    const Parameters::All &parameters;
    const Scene<dim>      &scene;
    const FluidSpace<dim> &space;
    FluidOperators<dim>   &operators;
    const double           nu;
    TimerOutput           *timer = nullptr;

    /// with boundary data at t^{n+1}; empty unless a face moves
    AffineConstraints<double> step_constraints;
    void                             make_step_constraints();
    const AffineConstraints<double> &constraints_of_step() const;

    /// The right-hand side in a matrix-free loop (with the matrix-free
    /// momentum operator, without the semi-implicit step matrix, whose
    /// cell matrices the assembled loop builds anyway); its vectors are
    /// set up on first use after a mesh change.
    MomentumRightHandSide<dim> matrix_free_rhs;
    bool                       matrix_free_rhs_ready = false;

    // time levels (owned) and ghosted views for cell loops
    VectorType u, u_old, u_older, unit_response;
    /// alpha/dt of the operator unit_response answers (0: none yet, e.g.
    /// after a restart, which does not save it)
    double     unit_response_alpha_over_dt = 0.;
    VectorType p, psi, psi_old, div_u, div_u_load;
    VectorType rhs_u, rhs_p;
    VectorType velocity_ghosted, pressure_ghosted;
    VectorType u_star_ghosted, u_history_ghosted, p_sharp_ghosted; // assembled rhs only

    double       current_time = 0., last_dt = 0.;
    unsigned int n_steps      = 0;
    double       alpha = 1., beta_1 = 1., beta_2 = 0.;
    double       last_change_rate = 0.;
    /// the driving force of the last step: with semi-implicit convection
    /// it is part of the next step's load, which then solves for its
    /// change only (advance())
    double       driving_force = 0.;

    using Transfer = parallel::distributed::SolutionTransfer<dim, VectorType>;
    std::unique_ptr<Transfer> velocity_transfer, pressure_transfer;
    std::vector<VectorType>   transfer_velocity_in, transfer_pressure_in; // ghosted copies
  };
} // namespace Suspension::Fluid
