#include <deal.II/base/mpi.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/numerics/vector_tools.h>

#include <suspension/core/vector_values.h>
#include <suspension/fluid/projection_scheme.h>

#include <petscmat.h>
#include <petscvec.h>

#include <algorithm>
#include <cmath>

#include <iomanip>
#include <istream>
#include <ostream>

namespace Suspension::Fluid
{
  template <int dim>
  ProjectionScheme<dim>::ProjectionScheme(const Parameters::All &parameters,
                                          const Scene<dim>      &scene,
                                          const FluidSpace<dim> &space,
                                          FluidOperators<dim>   &operators)
    : parameters(parameters)
    , scene(scene)
    , space(space)
    , operators(operators)
    , nu(parameters.material.viscosity / parameters.material.density)
  {}

  template <int dim>
  void ProjectionScheme<dim>::allocate_vectors()
  {
    const MPI_Comm comm = space.communicator();
    for (auto *v : {&u, &u_old, &u_older, &unit_response, &rhs_u})
      v->reinit(space.owned_velocity, comm);
    unit_response_alpha_over_dt = 0.;
    for (auto *v : {&p, &psi, &psi_old, &div_u, &div_u_load, &rhs_p})
      v->reinit(space.owned_pressure, comm);
    velocity_ghosted.reinit(space.owned_velocity, space.relevant_velocity, comm);
    pressure_ghosted.reinit(space.owned_pressure, space.relevant_pressure, comm);
    // the assembled right-hand side reads ghosted copies of its fields; the
    // matrix-free one forms them in its own vectors
    if (!operators.matrix_free_momentum || operators.step_matrix)
      {
        for (auto *v : {&u_star_ghosted, &u_history_ghosted})
          v->reinit(space.owned_velocity, space.relevant_velocity, comm);
        p_sharp_ghosted.reinit(space.owned_pressure, space.relevant_pressure, comm);
      }
    matrix_free_rhs_ready = false;
  }

  template <int dim>
  void ProjectionScheme<dim>::initialize(Function<dim> *velocity)
  {
    allocate_vectors();
    scene.set_time(0.);
    if (velocity != nullptr)
      {
        velocity->set_time(0.);
        VectorTools::interpolate(space.dof_velocity, *velocity, u);
      }
    else
      {
        VectorTools::interpolate(space.dof_velocity, scene.initial_velocity(), u);
        AffineConstraints<double> initial_constraints;
        space.make_velocity_constraints(scene, false, initial_constraints);
        initial_constraints.distribute(u);
      }
    make_step_constraints();
    u_old = u;
    u_older = u;
    velocity_ghosted = u;
    pressure_ghosted = p;
    current_time  = 0.;
    last_dt       = 0.;
    n_steps       = 0;
    driving_force = 0.;
  }

  template <int dim>
  void ProjectionScheme<dim>::attach_time_levels(const bool serialization)
  {
    const MPI_Comm comm = space.communicator();
    transfer_velocity_in.assign(2, VectorType());
    // a checkpoint also keeps Pi div u: the start of the next mass solve,
    // so that the resumed run iterates as the uninterrupted one
    transfer_pressure_in.assign(serialization ? 4 : 3, VectorType());
    for (auto &v : transfer_velocity_in)
      v.reinit(space.owned_velocity, space.relevant_velocity, comm);
    for (auto &v : transfer_pressure_in)
      v.reinit(space.owned_pressure, space.relevant_pressure, comm);
    transfer_velocity_in[0] = u;
    transfer_velocity_in[1] = u_old;
    transfer_pressure_in[0] = p;
    transfer_pressure_in[1] = psi;
    transfer_pressure_in[2] = psi_old;
    if (serialization)
      transfer_pressure_in[3] = div_u;
    velocity_transfer = std::make_unique<Transfer>(space.dof_velocity);
    pressure_transfer = std::make_unique<Transfer>(space.dof_pressure);
    const std::vector<const VectorType *> velocities = {&transfer_velocity_in[0],
                                                        &transfer_velocity_in[1]};
    std::vector<const VectorType *> pressures;
    for (const auto &v : transfer_pressure_in)
      pressures.push_back(&v);
    if (serialization)
      {
        velocity_transfer->prepare_for_serialization(velocities);
        pressure_transfer->prepare_for_serialization(pressures);
      }
    else
      {
        velocity_transfer->prepare_for_coarsening_and_refinement(velocities);
        pressure_transfer->prepare_for_coarsening_and_refinement(pressures);
      }
  }

  template <int dim>
  void ProjectionScheme<dim>::prepare_for_mesh_change()
  {
    attach_time_levels(false);
  }

  template <int dim>
  void ProjectionScheme<dim>::prepare_for_checkpoint()
  {
    attach_time_levels(true);
  }

  template <int dim>
  void ProjectionScheme<dim>::checkpoint_written()
  {
    velocity_transfer.reset();
    pressure_transfer.reset();
    transfer_velocity_in.clear();
    transfer_pressure_in.clear();
  }

  template <int dim>
  void ProjectionScheme<dim>::resume_from_checkpoint()
  {
    allocate_vectors();
    std::vector<VectorType *> velocities = {&u, &u_old};
    std::vector<VectorType *> pressures  = {&p, &psi, &psi_old, &div_u};
    // deserialize in the order of prepare_for_checkpoint()
    Transfer(space.dof_velocity).deserialize(velocities);
    Transfer(space.dof_pressure).deserialize(pressures);
    // The saved values satisfied the constraints already; distributing
    // again could change the last bit and the resumed run would drift
    // from the uninterrupted one.
    u_older          = u_old;
    velocity_ghosted = u;
    pressure_ghosted = p;
    make_step_constraints();
  }

  template <int dim>
  void ProjectionScheme<dim>::save(std::ostream &out) const
  {
    out << "ProjectionScheme " << std::setprecision(17) << current_time << " " << last_dt << " "
        << n_steps << " " << last_change_rate << " " << driving_force << "\n";
  }

  template <int dim>
  void ProjectionScheme<dim>::load(std::istream &in)
  {
    std::string tag;
    in >> tag >> current_time >> last_dt >> n_steps >> last_change_rate;
    AssertThrow(tag == "ProjectionScheme" && !in.fail(),
                ExcMessage("checkpoint: cannot read the fluid's time levels"));
    // checkpoints written before session 30 end here; the force is then
    // found again in full by the first step
    if (!(in >> driving_force))
      driving_force = 0.;
  }

  template <int dim>
  void ProjectionScheme<dim>::finish_mesh_change(Function<dim> *prescribed_velocity)
  {
    // (the flow-rate response starts again from zero: carrying it over as
    // a first guess saved 45 ms of its solve but cost 90 ms in the
    // transfer, which reads PETSc vectors cell by cell; session 31)
    allocate_vectors();
    std::vector<VectorType *> velocities = {&u, &u_old};
    std::vector<VectorType *> pressures  = {&p, &psi, &psi_old};
    velocity_transfer->interpolate(velocities);
    pressure_transfer->interpolate(pressures);
    velocity_transfer.reset();
    pressure_transfer.reset();
    transfer_velocity_in.clear();
    transfer_pressure_in.clear();
    {
      // continuity only (hanging nodes, periodicity): the transferred
      // boundary values stay; built here, the one place it is needed
      AffineConstraints<double> continuity;
      space.make_continuity_constraints(scene, continuity);
      for (auto *v : velocities)
        continuity.distribute(*v);
    }
    for (auto *v : pressures)
      space.pressure_constraints.distribute(*v);
    if (prescribed_velocity != nullptr)
      {
        prescribed_velocity->set_time(current_time);
        VectorTools::interpolate(space.dof_velocity, *prescribed_velocity, u);
      }
    u_older = u_old;
    velocity_ghosted = u;
    pressure_ghosted = p;
    // the step's constraints live on the old mesh's DoFs
    make_step_constraints();
  }

  template <int dim>
  void ProjectionScheme<dim>::make_step_constraints()
  {
    // Without non-zero boundary velocities the step's constraints are the
    // space's homogeneous ones: no copy (one velocity-sized AffineConstraints
    // on adaptive 3D meshes, 80 MB on the level-4 box).
    if (scene.has_inhomogeneous_velocity())
      space.make_velocity_constraints(scene, false, step_constraints);
    else
      step_constraints.clear();
  }

  template <int dim>
  const AffineConstraints<double> &ProjectionScheme<dim>::constraints_of_step() const
  {
    return scene.has_inhomogeneous_velocity() ? step_constraints : space.velocity_constraints;
  }

  template <int dim>
  double ProjectionScheme<dim>::flux(const VectorType &v) const
  {
    return operators.flux_weights * v;
  }

  template <int dim>
  void ProjectionScheme<dim>::update_unit_response()
  {
    VectorType b(operators.unit_force);
    b /= parameters.material.density;
    if (unit_response_alpha_over_dt > 0.)
      unit_response *= unit_response_alpha_over_dt / operators.momentum_alpha_over_dt;
    else
      unit_response = 0.;
    operators.solve_momentum(unit_response, b, parameters.fluid_solver.solver_tolerance);
    space.velocity_constraints.distribute(unit_response);
    unit_response_alpha_over_dt = operators.momentum_alpha_over_dt;
  }

  namespace
  {
    /// Consecutive timer sections; no-op when no timer was given.
    class Sections
    {
    public:
      Sections(TimerOutput *timer, const char *name)
        : timer(timer)
      {
        if (timer)
          timer->enter_subsection(name);
      }
      void next(const char *name)
      {
        if (timer)
          {
            timer->leave_subsection();
            timer->enter_subsection(name);
          }
      }
      ~Sections()
      {
        if (timer)
          timer->leave_subsection();
      }

    private:
      TimerOutput *timer;
    };
  } // namespace

  template <int dim>
  StepReport
  ProjectionScheme<dim>::advance(const double dt,
                                 const std::vector<const MomentumSource<dim> *> &sources)
  {
    StepReport report;
    const double t_new = current_time + dt;

    // BDF coefficients: BDF1 on the first step, variable-step BDF2 after.
    double extrapolation = 0.;
    if (n_steps == 0)
      {
        alpha = 1.; beta_1 = 1.; beta_2 = 0.;
      }
    else
      {
        const double w = dt / last_dt;
        alpha  = (1. + 2. * w) / (1. + w);
        beta_1 = 1. + w;
        beta_2 = w * w / (1. + w);
        extrapolation = w;
      }

    // Constant matrices change only with alpha / dt (and the mesh).
    Sections section(timer, "fluid: matrices for new dt");
    const double old_alpha_over_dt = operators.momentum_alpha_over_dt;
    operators.set_momentum_coefficients(alpha / dt, nu);
    const bool driven = parameters.flow_driving.type != Parameters::FlowDrivingType::none;
    const bool implicit_convection =
      parameters.fluid_solver.convection == Parameters::ConvectionForm::semi_implicit;
    // (with a step matrix the response is recomputed every step; with
    // semi-implicit convection an imposed gradient joins the load instead)
    const bool response_used =
      driven && !operators.step_matrix &&
      !(implicit_convection &&
        parameters.flow_driving.type == Parameters::FlowDrivingType::constant_pressure_gradient);
    if (operators.momentum_alpha_over_dt != old_alpha_over_dt)
      {
        report.matrices_rebuilt = true;
        if (response_used)
          update_unit_response();
      }

    // Extrapolated velocity (convection), history (time derivative) and
    // pressure P# = P^n + (4 psi^n - psi^{n-1}) / 3.
    section.next("fluid: momentum right-hand side");
    u_older = u_old;
    u_old   = u;
    MomentumLoad<dim> load;
    load.u_star  = {{1. + extrapolation, &u_old}, {-extrapolation, &u_older}};
    load.history = {{beta_1 / dt, &u_old}, {-beta_2 / dt, &u_older}};
    load.p_sharp = {{1., &p}};
    if (n_steps > 0)
      load.p_sharp.insert(load.p_sharp.end(), {{4. / 3., &psi}, {-1. / 3., &psi_old}});

    // With semi-implicit convection the force of the last step (or the
    // imposed gradient) joins the load; otherwise all of it comes from the
    // flow-rate control below.
    double imposed_force = 0.;
    if (implicit_convection)
      imposed_force =
        parameters.flow_driving.type == Parameters::FlowDrivingType::constant_pressure_gradient ?
          parameters.flow_driving.pressure_gradient :
          driving_force;

    // 1. momentum predictor
    // Boundary data only need rebuilding when a face carries a (possibly
    // time-dependent) non-zero velocity; otherwise the homogeneous
    // constraints of the space are the step's constraints.
    scene.set_time(t_new);
    if (scene.has_inhomogeneous_velocity())
      make_step_constraints();
    // semi-implicit convection: u* at the quadrature points first, the
    // lifting of boundary data in the right-hand side needs it too; the
    // guard clears it at the end of the predictor, also when a solve
    // throws (a later unit-response solve must not see a stale u*)
    struct AdvectionGuard
    {
      MomentumOperator<dim> &op;
      ~AdvectionGuard() { op.clear_advection(); }
      void                   release() { op.clear_advection(); }
    } advection_guard{operators.momentum_operator};
    if (implicit_convection)
      operators.momentum_operator.set_advection(load.u_star);
    assemble_momentum_rhs(load, dt, t_new, sources);
    const double tolerance = parameters.fluid_solver.solver_tolerance;
    if (operators.step_matrix)
      {
        section.next("fluid: semi-implicit preconditioner");
        operators.prepare_step_matrix();
        section.next("fluid: momentum solve");
        report.momentum_iterations = operators.solve_step_matrix(u, rhs_u, tolerance);
        if (driven)
          {
            VectorType b(operators.unit_force);
            b /= parameters.material.density;
            report.momentum_iterations += operators.solve_step_matrix(unit_response, b, tolerance);
            space.velocity_constraints.distribute(unit_response);
          }
      }
    else
      {
        section.next("fluid: momentum solve");
        if (implicit_convection && driven)
          rhs_u.add(imposed_force / parameters.material.density, operators.unit_force);
        report.momentum_iterations = operators.solve_momentum(u, rhs_u, tolerance);
      }
    advection_guard.release();
    constraints_of_step().distribute(u);

    // 2. flow-rate control by linearity: u + f w, w the response to a
    // unit force. With semi-implicit convection the operator of u is not
    // the one of w (A without convection, kept while dt is): the load
    // then holds the last step's force and w carries only its change, so
    // that the mismatch, change times (u*.grad) w, is of second order.
    const auto &driving = parameters.flow_driving;
    if (driving.type == Parameters::FlowDrivingType::constant_flow_rate)
      {
        const double target = driving.bulk_velocity * scene.volume();
        const double change = (target - flux(u)) / flux(unit_response);
        report.driving_force = imposed_force + change;
        u.add(change, unit_response);
      }
    else if (driving.type == Parameters::FlowDrivingType::constant_pressure_gradient)
      {
        report.driving_force = driving.pressure_gradient;
        if (!implicit_convection)
          u.add(report.driving_force, unit_response);
      }
    driving_force = report.driving_force;

    // 3. projection: the increment psi
    section.next("fluid: projection");
    operators.apply_divergence(u, div_u_load);
    rhs_p = div_u_load;
    rhs_p *= -alpha / dt;
    space.increment_constraints.set_zero(rhs_p);
    psi_old = psi;
    report.projection_iterations =
      operators.solve_pressure_laplace(psi, rhs_p, parameters.fluid_solver.solver_tolerance);
    space.increment_constraints.distribute(psi);

    // 4. pressure update; Pi div u is also the divergence diagnostic
    section.next("fluid: pressure update");
    report.mass_iterations =
      operators.solve_pressure_mass(div_u, div_u_load, parameters.fluid_solver.solver_tolerance);
    space.pressure_constraints.distribute(div_u);
    p.add(1., psi);
    if (parameters.fluid_solver.projection == Parameters::ProjectionForm::rotational)
      p.add(-nu, div_u);

    {
      const double umax = u.linfty_norm();
      last_change_rate  = umax > 0 ? max_difference(u, u_old) / (dt * umax) : 0.;
    }

    velocity_ghosted = u;
    pressure_ghosted = p;
    current_time     = t_new;
    last_dt          = dt;
    ++n_steps;
    return report;
  }

  template <int dim>
  void ProjectionScheme<dim>::prescribe(const double dt, Function<dim> &velocity)
  {
    u_older = u_old;
    u_old   = u;
    velocity.set_time(current_time + dt);
    VectorTools::interpolate(space.dof_velocity, velocity, u);
    velocity_ghosted = u;
    current_time += dt;
    last_dt = dt;
    ++n_steps;
  }

  template <int dim>
  std::vector<std::pair<std::string, std::size_t>> ProjectionScheme<dim>::memory_by_part() const
  {
    const std::size_t dofs =
      space.dof_velocity.memory_consumption() + space.dof_pressure.memory_consumption();
    std::size_t constraints = step_constraints.memory_consumption();
    for (const auto *c : {&space.velocity_constraints, &space.pressure_constraints,
                          &space.increment_constraints})
      constraints += c->memory_consumption();
    // PETSc counts its matrices' memory only when asked to trace its
    // allocations: the stored entries and column indices instead
    std::size_t matrices = 0;
    for (const auto *m : {&operators.M, &operators.K, &operators.A, &operators.L,
                          &operators.Mp, &operators.D, &operators.A_step})
      {
        MatInfo info;
        AssertThrow(MatGetInfo(*m, MAT_LOCAL, &info) == 0, ExcMessage("MatGetInfo"));
        matrices += std::size_t(info.nz_allocated) * (sizeof(PetscScalar) + sizeof(PetscInt)) +
                    std::size_t(m->local_size()) * sizeof(PetscInt);
      }
    std::size_t vectors = operators.momentum_operator.vector_memory() +
                          matrix_free_rhs.memory_consumption() +
                          operators.divergence_operator.memory_consumption();
    for (const VectorType *v : std::initializer_list<const VectorType *>{
           &u, &u_old, &u_older, &unit_response, &p, &psi, &psi_old, &div_u,
                          &div_u_load, &rhs_u, &rhs_p, &velocity_ghosted, &pressure_ghosted,
                          &u_star_ghosted, &u_history_ghosted, &p_sharp_ghosted,
                          &operators.flux_weights, &operators.unit_force})
      vectors += v->size() > 0 ? v->memory_consumption() : 0;
    return {{"fluid DoFs", dofs},
            {"fluid constraints", constraints},
            {"fluid MatrixFree", operators.momentum_operator.matrix_free_memory()},
            {"fluid matrices", matrices},
            {"fluid vectors", vectors}};
  }

  template <int dim>
  double ProjectionScheme<dim>::max_difference(const VectorType &a, const VectorType &b) const
  {
    const PetscScalar *x, *y;
    PetscInt           n;
    AssertThrow(VecGetLocalSize(a, &n) == 0, ExcMessage("VecGetLocalSize"));
    AssertThrow(VecGetArrayRead(a, &x) == 0 && VecGetArrayRead(b, &y) == 0,
                ExcMessage("VecGetArrayRead"));
    double difference = 0.;
    for (PetscInt i = 0; i < n; ++i)
      difference = std::max(difference, std::abs(x[i] - y[i]));
    AssertThrow(VecRestoreArrayRead(a, &x) == 0 && VecRestoreArrayRead(b, &y) == 0,
                ExcMessage("VecRestoreArrayRead"));
    return Utilities::MPI::max(difference, space.communicator());
  }

  template <int dim>
  VectorType ProjectionScheme<dim>::extrapolated_velocity(const double dt) const
  {
    VectorType v(u);
    if (n_steps > 0)
      {
        const double w = dt / last_dt;
        v *= 1. + w;
        v.add(-w, u_old);
      }
    return v;
  }

  template <int dim>
  void ProjectionScheme<dim>::assemble_momentum_rhs(
    MomentumLoad<dim> &load, const double dt, const double t_new,
    const std::vector<const MomentumSource<dim> *> &sources)
  {
    // (semi-implicit convection is the momentum operator's)
    const bool convection =
      parameters.fluid_solver.convection == Parameters::ConvectionForm::skew_symmetric;
    bool any_stress = false;
    for (const auto *s : sources)
      any_stress = any_stress || s->has_stress();

    if (operators.matrix_free_momentum && !operators.step_matrix)
      {
        if (!matrix_free_rhs_ready)
          matrix_free_rhs.reinit(operators.momentum_operator);
        matrix_free_rhs_ready = true;
        load.sources         = &sources;
        load.time            = t_new;
        load.alpha_over_dt   = operators.momentum_alpha_over_dt;
        load.viscosity       = nu;
        load.inverse_density = 1. / parameters.material.density;
        load.convection      = convection;
        load.stress          = any_stress;
        matrix_free_rhs.assemble(operators.momentum_operator, space, constraints_of_step(), load,
                                 rhs_u);
        return;
      }

    // ghosted copies of the fields for the cells' FEValues
    for (const auto &[terms, ghosted] :
         {std::pair(&load.u_star, &u_star_ghosted), std::pair(&load.history, &u_history_ghosted),
          std::pair(&load.p_sharp, &p_sharp_ghosted)})
      {
        VectorType owned(ghosted->locally_owned_elements(), space.communicator());
        form_locally_owned(*terms, owned);
        *ghosted = owned;
      }

    rhs_u = 0.;
    // Semi-implicit elastic coupling: the stress increment of the velocity
    // correction du = u^{n+1} - u*, theta dt G phi (grad du B + B grad du^T),
    // joins the predictor; theta = 1/2 (Crank-Nicolson). For the elastic
    // wave rho u_t = div tau, tau_t = G grad u this scheme is stable for
    // any dt once theta >= 1/4 (doc/method.md), where the explicit one
    // needs c dt / h below about 1.
    const bool   semi_implicit = operators.step_matrix;
    const double theta         = 0.5;
    const auto  &step          = constraints_of_step();
    if (semi_implicit)
      operators.A_step = 0.;

    const FEValuesExtractors::Vector velocities(0);
    FEValues<dim> fe_u(space.fe_velocity, space.quadrature,
                       update_values | update_gradients | update_JxW_values |
                         update_quadrature_points);
    FEValues<dim> fe_p(space.fe_pressure, space.quadrature, update_gradients);

    const unsigned int nu_dofs = space.fe_velocity.n_dofs_per_cell();
    const unsigned int n_q     = space.quadrature.size();
    Vector<double>                       cell_rhs(nu_dofs);
    FullMatrix<double>                   cell_matrix(nu_dofs, nu_dofs);
    std::vector<types::global_dof_index> dofs(nu_dofs);
    std::vector<Tensor<1, dim>>          history(n_q), u_star(n_q), grad_p(n_q), force(n_q);
    std::vector<Tensor<2, dim>>          grad_u_star(n_q);
    std::vector<SymmetricTensor<2, dim>> stress(n_q);
    std::vector<unsigned int>            component(nu_dofs);
    std::vector<double>                  modulus(n_q);
    std::vector<SymmetricTensor<2, dim>> B(n_q);
    // the cell's DoF values, read once per vector: the FEValues views
    // would each allocate and read them again
    Vector<double> u_star_local(nu_dofs), u_history_local(nu_dofs), lifted(nu_dofs);
    Vector<double> p_sharp_local(space.fe_pressure.n_dofs_per_cell());
    const FEValuesExtractors::Scalar pressure(0);
    FullMatrix<double>                   cell_E(nu_dofs, nu_dofs);
    // (alpha/dt) M + nu K of the current cell: the lifting of boundary data
    // and the semi-implicit step matrix need it
    const auto assemble_cell_momentum_matrix = [&]() {
      cell_matrix = 0;
      for (unsigned int q = 0; q < n_q; ++q)
        for (unsigned int i = 0; i < nu_dofs; ++i)
          for (unsigned int j = 0; j < nu_dofs; ++j)
            if (component[i] == component[j])
              cell_matrix(i, j) += (operators.momentum_alpha_over_dt * fe_u.shape_value(i, q) *
                                      fe_u.shape_value(j, q) +
                                    nu * fe_u.shape_grad(i, q) * fe_u.shape_grad(j, q)) *
                                   fe_u.JxW(q);
    };
    for (unsigned int i = 0; i < nu_dofs; ++i)
      component[i] = space.fe_velocity.system_to_component_index(i).first;
    const double inv_rho = 1. / parameters.material.density;

    for (const auto &cell : space.dof_velocity.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          const auto pressure_cell = FluidSpace<dim>::cell_of(cell, space.dof_pressure);
          fe_u.reinit(cell);
          fe_p.reinit(pressure_cell);
          cell->get_dof_values(u_history_ghosted, u_history_local);
          fe_u[velocities].get_function_values_from_local_dof_values(make_array_view(u_history_local), history);
          pressure_cell->get_dof_values(p_sharp_ghosted, p_sharp_local);
          fe_p[pressure].get_function_gradients_from_local_dof_values(make_array_view(p_sharp_local), grad_p);
          if (convection || semi_implicit)
            cell->get_dof_values(u_star_ghosted, u_star_local);
          if (convection)
            {
              fe_u[velocities].get_function_values_from_local_dof_values(make_array_view(u_star_local), u_star);
              fe_u[velocities].get_function_gradients_from_local_dof_values(make_array_view(u_star_local),
                                                                           grad_u_star);
            }
          std::fill(force.begin(), force.end(), Tensor<1, dim>());
          std::fill(stress.begin(), stress.end(), SymmetricTensor<2, dim>());
          for (const auto *s : sources)
            s->add(cell, fe_u.get_quadrature_points(),
                   space.quadrature.get_points(), t_new, force, stress);

          // The whole right-hand side as one vector per point:
          // history - convection - grad P# + f / rho.
          for (unsigned int q = 0; q < n_q; ++q)
            {
              force[q] = force[q] * inv_rho + history[q] - grad_p[q];
              if (convection)
                force[q] -= grad_u_star[q] * u_star[q] +
                            0.5 * trace(grad_u_star[q]) * u_star[q];
            }

          cell_rhs = 0;
          for (unsigned int q = 0; q < n_q; ++q)
            {
              const double         JxW = fe_u.JxW(q);
              const Tensor<2, dim> tau = inv_rho * Tensor<2, dim>(stress[q]);
              for (unsigned int i = 0; i < nu_dofs; ++i)
                {
                  const unsigned int c = component[i];
                  double value = force[q][c] * fe_u.shape_value(i, q);
                  if (any_stress)
                    value -= tau[c] * fe_u.shape_grad(i, q);
                  cell_rhs(i) += value * JxW;
                }
            }

          cell->get_dof_indices(dofs);
          if (semi_implicit)
            {
              // the whole step matrix of the cell: (alpha/dt) M + nu K +
              // theta dt / rho E(phi, B); E u* moves to the right-hand side
              bool elastic = false;
              for (const auto *s : sources)
                elastic = s->elastic_stiffness(cell, space.quadrature.get_points(), modulus, B) ||
                          elastic;
              assemble_cell_momentum_matrix();
              if (elastic)
                {
                  // E_ij = int G phi [delta_{ci cj} g_i.B g_j + (B g_j)_{ci} (g_i)_{cj}]
                  cell_E = 0;
                  for (unsigned int q = 0; q < n_q; ++q)
                    {
                      const double w = theta * dt * inv_rho * modulus[q] * fe_u.JxW(q);
                      if (w == 0.)
                        continue;
                      for (unsigned int j = 0; j < nu_dofs; ++j)
                        {
                          const Tensor<1, dim> Bg_j = B[q] * fe_u.shape_grad(j, q);
                          const unsigned int   cj   = component[j];
                          for (unsigned int i = 0; i < nu_dofs; ++i)
                            {
                              const Tensor<1, dim> &g_i = fe_u.shape_grad(i, q);
                              const unsigned int    ci  = component[i];
                              cell_E(i, j) +=
                                w * ((ci == cj ? g_i * Bg_j : 0.) + Bg_j[ci] * g_i[cj]);
                            }
                        }
                    }
                  cell_E.vmult(lifted, u_star_local);
                  cell_rhs += lifted;
                  cell_matrix.add(1., cell_E);
                }
              step.distribute_local_to_global(cell_matrix, cell_rhs, dofs, operators.A_step, rhs_u);
              continue;
            }
          bool inhomogeneous = false;
          for (const auto i : dofs)
            inhomogeneous = inhomogeneous || step.is_inhomogeneously_constrained(i);
          if (inhomogeneous)
            {
              // Lift the boundary data: the cell matrix moves A g to the
              // right-hand side (Dirichlet columns are not in A).
              assemble_cell_momentum_matrix();
              step.distribute_local_to_global(cell_rhs, dofs, rhs_u, cell_matrix);
            }
          else
            step.distribute_local_to_global(cell_rhs, dofs, rhs_u);
        }
    rhs_u.compress(VectorOperation::add);
    if (semi_implicit)
      operators.A_step.compress(VectorOperation::add);
  }

  template <int dim>
  FlowDiagnostics ProjectionScheme<dim>::compute_diagnostics() const
  {
    FlowDiagnostics d;
    // the scalar element's FEValues (see vector_values.h)
    const auto   &fe     = space.fe_velocity;
    FEValues<dim> fe_u(fe.base_element(0), space.quadrature, update_values | update_JxW_values);
    std::vector<Tensor<1, dim>> values(space.quadrature.size());
    Vector<double>              local(fe.n_dofs_per_cell());
    const double degree = fe.degree;
    double energy = 0., speed_over_h = 0., speed = 0.;
    for (const auto &cell : space.dof_velocity.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          fe_u.reinit(typename Triangulation<dim>::cell_iterator(cell));
          cell->get_dof_values(velocity_ghosted, local);
          vector_values_from_scalar_base(
            fe, local, [&](const unsigned int i, const unsigned int q) { return fe_u.shape_value(i, q); },
            values);
          double cell_speed = 0.;
          for (const unsigned int q : fe_u.quadrature_point_indices())
            {
              energy += values[q].norm_square() * fe_u.JxW(q);
              cell_speed = std::max(cell_speed, values[q].norm());
            }
          speed = std::max(speed, cell_speed);
          speed_over_h = std::max(speed_over_h,
                                  cell_speed * degree / cell->minimum_vertex_distance());
        }
    const MPI_Comm comm = space.communicator();
    d.kinetic_energy   = 0.5 * parameters.material.density * Utilities::MPI::sum(energy, comm);
    d.max_speed_over_h = Utilities::MPI::max(speed_over_h, comm);
    d.max_speed        = Utilities::MPI::max(speed, comm);
    d.bulk_velocity    = operators.flux_weights.size() > 0 ? flux(u) / scene.volume() : 0.;
    // (Pi div u, div u) = ||Pi div u||^2, from the condensed load D u
    d.divergence_l2 = std::sqrt(std::max(0., div_u_load * div_u));
    return d;
  }

  template <int dim>
  double ProjectionScheme<dim>::relative_change_rate() const
  {
    return last_change_rate;
  }

  template class ProjectionScheme<2>;
  template class ProjectionScheme<3>;
} // namespace Suspension::Fluid
