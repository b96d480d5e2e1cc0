#pragma once

#include <limits>

#include <deal.II/base/function.h>
#include <deal.II/distributed/solution_transfer.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>

#include <suspension/core/parameters.h>
#include <suspension/fluid/fluid_operators.h>
#include <suspension/fluid/fluid_space.h>
#include <suspension/fluid/momentum_source.h>
#include <suspension/solid/initial_fraction.h>
#include <suspension/solid/interface_sharpening.h>
#include <suspension/solid/stress_weight.h>
#include <suspension/solid/transport_operator.h>

#include <array>
#include <iosfwd>
#include <memory>

namespace Suspension::Solid
{
  /// Bounds and integrals of the solid fields after a step.
  struct SolidDiagnostics
  {
    double       volume = 0., volume_drift = 0.; // integral of phi, relative change
    double       initial_volume = 0.;
    /// phi that left through the boundary since t = 0 (outflow minus
    /// inflow, integrated over the steps), and the balance
    /// (volume - initial volume + boundary_outflow) / initial volume,
    /// zero up to round-off
    double       boundary_outflow = 0., mass_balance = 0.;
    /// what rounds phi since t = 0: transport sub-steps, mesh transfers,
    /// sharpenings (each rounds every nodal value a bounded number of
    /// times; the round-off bound of mass_balance is proportional to it)
    unsigned long long updates = 0;
    double       min_phi = 0., max_phi = 0.;
    unsigned int limited_cells = 0, out_of_bound_means = 0, substeps = 0;
    double       min_det_B = 1., min_eigenvalue_B = 1.;
    double       max_eigenvalue_B = 1.; // all three where B is checked (see solid_threshold)
    /// largest H(phi) lambda_max(B): the elastic wave speed is sqrt(G H lambda / rho)
    double       wave_stiffness   = 1.;
    std::array<double, 3> worst_B_location{}; // where min_eigenvalue_B is
    double                worst_B_phi = 1.;    // phi there
    /// share of the elastic energy (G/2) H (tr B - dim - ln det B) where phi < 1/2
    double       tail_energy_share = 0.;
    /// cells across 0.01 < phi < 0.99: its measure over the length (area)
    /// of the phi = 1/2 surface and the cell size
    double       interface_width = 0.;
  };

  /**
   * Round-off bound of |SolidDiagnostics::mass_balance| after `updates`
   * transport sub-steps, mesh transfers and sharpenings. Each sub-step
   * rounds every nodal value of phi about 20 times (three RK stages, each
   * an add and an sadd of vectors, the limiter's shift towards the cell
   * mean, the rounding of M^{-1} R); a rounding moves the nodal value by at
   * most u |phi_i|, u = 2^-53, and, the nodal weights int v_i being
   * positive, int phi by at most u int |phi| <= u int phi(0) (phi >= 0, no
   * phi flows in). 32 per update leaves room for the residual's own
   * rounding; one more for the two integrals (compensated sums, a few u).
   * A worst case: round-to-nearest errors have no sign, and the runs
   * measured stay within a few u in all (doc/verification.md).
   */
  inline double mass_balance_bound(const unsigned long long updates)
  {
    return 32. * (updates + 1.) * std::numeric_limits<double>::epsilon() / 2.;
  }

  /// What a cell holds, from the values of phi at its nodes and
  /// quadrature points (see SolidPhase::classify_cells()).
  enum CellPhase : unsigned char
  {
    fluid_cell     = 0,
    interface_cell = 1,
    solid_cell     = 2
  };

  /// Shape of one particle from the moments of phi.
  template <int dim>
  struct ParticleShape
  {
    Point<dim>     centroid;
    Tensor<1, dim> velocity;
    double         taylor_deformation = 0.; // (L - S) / (L + S)
    double         inclination        = 0.; // degrees, long axis against x
    double         solid_area         = 0.; // measure of {phi >= 1/2} at Gauss points
    /// the same on sub-cells of the cells the level 1/2 crosses, and the
    /// Taylor deformation of that region
    double         solid_area_subcell = 0., taylor_deformation_half = 0., inclination_half = 0.;
    /// the same from the moments of phi itself (tail included)
    double         taylor_deformation_phi = 0., inclination_phi = 0.;
    /// the stretch of the material, from the mean of B where H(phi) = 1:
    /// (L - S) / (L + S) with L, S the square roots of its eigenvalues
    double         taylor_deformation_B = 0., inclination_B = 0.;
  };

  /**
   * The solid phase of the one-continuum model: the volume fraction phi
   * and, for an elastic solid (G > 0), the left Cauchy-Green tensor B, in
   * one discontinuous FE_DGQ(k) field on the fluid's mesh. advance()
   * carries them with a given velocity by SSP-RK3 (Shu & Osher 1988),
   * sub-stepped to the transport CFL, with the bound-preserving limiter
   * after every stage. As a MomentumSource it adds the neo-Hookean stress
   * G phi (B - I) to the fluid.
   *
   * Limits: the velocity is interpolated linearly in time between the two
   * fields handed to advance(); B is only checked (SPD), not limited.
   */
  template <int dim>
  class SolidPhase : public Fluid::MomentumSource<dim>
  {
  public:
    static constexpr unsigned int n_B = dim * (dim + 1) / 2;

    /// True if add() contributes anything (a stress or a body force).
    bool pushes_fluid() const
    {
      return fe.n_components() > 1 || body_force != nullptr;
    }

    SolidPhase(const Parameters::All &parameters,
               const parallel::distributed::Triangulation<dim> &tria);

    /// DoFs, operator and initial fields (phi from the scene, B = I); the
    /// smoothed profile is 'Interface width' cells of size `interface_h`.
    void setup(const Fluid::FluidSpace<dim> &fluid_space, double interface_h);

    /// Before the mesh changes: hands phi and B to a SolutionTransfer.
    void prepare_for_mesh_change();

    /// After the mesh (and the fluid space) changed: DoFs and operator on
    /// the new mesh, fields transferred (DG coarsening is the L2
    /// projection, so cell means and the integral of phi are kept), then
    /// limited back into 0 <= phi <= 1 and B SPD.
    void finish_mesh_change(const Fluid::FluidSpace<dim> &fluid_space);

    /// Checkpoint: hands phi and B to the triangulation's next save();
    /// checkpoint_written() lets go of them.
    void prepare_for_checkpoint();
    void checkpoint_written();

    /// After Triangulation::load() of a checkpoint (and after the fluid's
    /// resume_from_checkpoint(), the order of saving): DoFs and operator,
    /// fields as saved. Call load() too.
    void resume_from_checkpoint(const Fluid::FluidSpace<dim> &fluid_space);

    /// Initial volume, time, boundary outflow and update count (text, full
    /// precision).
    void save(std::ostream &out) const;
    void load(std::istream &in);

    /// Per active cell (index active_cell_index(), filled for locally
    /// owned cells): interface if epsilon < phi < 1 - epsilon at a node or
    /// quadrature point (or phi jumps across that range inside the cell),
    /// solid if its mean is above 1/2, fluid otherwise.
    std::vector<unsigned char> classify_cells(double epsilon) const;

    /// Largest sub-step of the transport for a velocity with
    /// max |u| k_u / h = speed_over_h.
    double max_substep(double speed_over_h) const;

    /// Advances phi (and B) by dt with the velocity going linearly from
    /// u_begin to u_end (PETSc vectors on the fluid's velocity space).
    SolidDiagnostics advance(double dt, double speed_over_h,
                             const Fluid::VectorType &u_begin,
                             const Fluid::VectorType &u_end);

    SolidDiagnostics diagnostics() const;

    /// The largest |u| over the cells the interface crosses (nodal phi
    /// between epsilon and 1 - epsilon) and their face neighbours, at both
    /// ends of the last advance(): how fast the interface moved.
    double interface_speed(double epsilon) const
    {
      return transport.interface_speed(solution, u0, u1, epsilon);
    }

    /// How the initial phi was made (exact cell fractions: cut cells).
    const InitialFractionReport &initial_fraction_report() const { return initial_report; }

    /// Moments of phi (one particle), with the velocity for its centroid.
    ParticleShape<dim> particle_shape(const Fluid::FluidSpace<dim> &space,
                                      const Fluid::VectorType      &velocity) const;

    /// Integral of phi at the start of the run.
    double initial_phi_volume() const { return initial_volume; }

    /// L1 norm of phi - exact.
    double l1_error(const Function<dim> &exact) const;

    /// The error measure of VOF papers: the sum over the cells of |mean
    /// of phi - exact fraction| times the cell's measure, the exact
    /// fractions of the indicator `expression` computed as for the initial
    /// phi (adaptive bisection). Zero for the initial phi of that shape.
    double cell_mean_l1_error(const std::string &expression, const std::string &constants) const;

    /// Values of all components at points (phi, then B in unrolled order).
    std::vector<Vector<double>> values_at(const std::vector<Point<dim>> &points) const;

    // MomentumSource
    void add(const typename Triangulation<dim>::active_cell_iterator &cell,
             const std::vector<Point<dim>> &points,
             const std::vector<Point<dim>> &unit_points,
             double                          time,
             std::vector<Tensor<1, dim>>          &force,
             std::vector<SymmetricTensor<2, dim>> &stress) const override;
    /// G phi and B at the points, if 'Elastic coupling = semi-implicit'.
    bool elastic_stiffness(const typename Triangulation<dim>::active_cell_iterator &cell,
                           const std::vector<Point<dim>> &unit_points,
                           std::vector<double>                  &modulus,
                           std::vector<SymmetricTensor<2, dim>> &B) const override;

    const DoFHandler<dim> &get_dof_handler() const { return dof_handler; }
    const FiniteElement<dim> &get_fe() const { return fe; }
    const VectorType      &get_solution() const { return solution; }
    /// Bytes held on this rank, by part: the DoFs, the transport's
    /// MatrixFree data, its other per-cell data and scratch, the fields.
    std::vector<std::pair<std::string, std::size_t>> memory_by_part() const;
    std::vector<std::string> component_names() const;

  private:
    void reinit_discretization(const Fluid::FluidSpace<dim> &fluid_space);
    /// cells with phi above this at a node enter the interface measures
    static constexpr double touches_solid = 1e-3;
    void check_B(const SolidDiagnostics &d, double time) const;
    /// and, with 'Interface relaxation rate' R, B - I relaxed at the rate
    /// R (1 - H(phi)) over the step dt
    void reset_B_in_fluid(double dt);
    /// 'Interface sharpening' after every 'Sharpening interval' steps
    void sharpen_interface();
    /// B = I at every node of the cell (values: the cell's DoF values):
    /// B - I vanishes in the cell, and with it the stress.
    bool unstrained(const Vector<double> &values) const;
    /// phi and B at unit_points of solid_cell, from cell_values (the
    /// cell's DoF values, read by the caller)
    const std::vector<Vector<double>> &
    values_at(const typename DoFHandler<dim>::active_cell_iterator &solid_cell,
              const std::vector<Point<dim>>                         &unit_points) const;

    /// With the stress weight H = phi, B is checked (SPD) where phi is at
    /// least this; with the sharp weight, where H(phi) > 0.
    static constexpr double solid_threshold = 0.1;
    /// Stress weight 'phi': B is reset to I in cells where phi is below
    /// this at every node.
    static constexpr double fluid_threshold = 1e-4;
    void copy_velocity(const Fluid::VectorType &in, VectorType &out) const;

    const Parameters::All &parameters;
    const StressWeight     weight;
    /// 'Shape measure = profile' and THINC on
    const bool             shape_on_profile;
    InitialFractionReport  initial_report;
    FESystem<dim>          fe;
    DoFHandler<dim>        dof_handler;
    TransportOperator<dim> transport;
    InterfaceSharpening<dim> sharpening;
    unsigned int           steps_since_sharpening = 0;
    VectorType             solution, stage, stage_rhs, u0, u1, u_stage;
    double                 initial_volume = 0., time = 0.;
    /// int_0^t int_{boundary} (u.n) phi^ ds dt, summed over the RK stages
    /// with the weights of the scheme (SolidPhase::advance)
    double                 boundary_outflow = 0.;
    unsigned long long     updates = 0; // see SolidDiagnostics::updates
    mutable std::unique_ptr<FEValues<dim>> stress_values;
    mutable std::vector<Vector<double>>    point_values; // reused: add() runs on every cell
    mutable Vector<double>                 cell_values; // of the cell add() works on
    std::unique_ptr<Function<dim>>         body_force; // null: none
    std::unique_ptr<parallel::distributed::SolutionTransfer<dim, VectorType>> transfer;
  };
} // namespace Suspension::Solid
