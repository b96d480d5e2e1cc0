#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_dgq.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_q1.h>
#include <deal.II/lac/read_write_vector.h>
#include <deal.II/numerics/vector_tools.h>

#include <suspension/core/scene.h>
#include <suspension/postprocess/point_values.h>
#include <suspension/solid/phi_values.h>
#include <suspension/solid/solid_phase.h>

#include <algorithm>
#include <cstdlib>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace Suspension::Solid
{
  namespace
  {
    /// phi from the particle list (smoothed edges, periodic images) or an
    /// expression; B = I.
    template <int dim>
    class InitialSolid : public Function<dim>
    {
    public:
      InitialSolid(const Parameters::All &p, const unsigned int n_components, const double h)
        : Function<dim>(n_components)
        , solid(p.solid)
        , width(p.solid.interface_width * h)
      {
        for (unsigned int d = 0; d < dim; ++d)
          {
            period[d] = p.boundary_conditions.type[2 * d] == Parameters::BoundaryType::periodic ?
                          p.geometry.box_upper[d] - p.geometry.box_lower[d] :
                          0.;
          }
        if (solid.initial_fraction == Parameters::InitialFraction::function)
          expression = make_function<dim>({solid.fraction_expression, solid.constants}, 1);
      }

      double value(const Point<dim> &x, const unsigned int c) const override
      {
        if (c > 0)
          return c <= dim ? 1. : 0.; // B = I, diagonal first
        if (expression)
          return expression->value(x);
        double phi = 0.;
        for (const auto &particle : solid.particles)
          {
            double r2 = 0.;
            for (unsigned int d = 0; d < dim; ++d)
              {
                double dx = x[d] - particle[d];
                if (period[d] > 0)
                  dx -= period[d] * std::round(dx / period[d]);
                r2 += dx * dx;
              }
            const double distance = std::sqrt(r2) - particle[dim];
            phi = std::max(phi, width > 0 ? 0.5 * (1. - std::tanh(2. * distance / width)) :
                                            (distance <= 0 ? 1. : 0.));
          }
        return phi;
      }

    private:
      const Parameters::Solid       &solid;
      const double                   width;
      std::array<double, dim>        period{};
      std::unique_ptr<Function<dim>> expression;
    };

    /// What VectorTools::interpolate computes for this nodal DG element
    /// (each DoF belongs to one cell: its value is the function's at its
    /// support point), written cell by cell into the solution: deal.II's
    /// interpolate allocates two temporary vectors of the solution's size,
    /// which set the peak memory of a 3D set-up (+470 MB of 4.0 GB on the
    /// level-4 box), and evaluates phi of every particle at every node,
    /// 10 % of that set-up, where the exact cell fractions replace it.
    template <int dim>
    void interpolate_initial_solid(const DoFHandler<dim>    &dof_handler,
                                   const InitialSolid<dim>  &initial,
                                   const bool                phi_needed,
                                   LinearAlgebra::distributed::Vector<double> &solution)
    {
      const FiniteElement<dim>            &fe    = dof_handler.get_fe();
      const std::vector<Point<dim>>       &nodes = fe.base_element(0).get_unit_support_points();
      const Mapping<dim>                  &mapping = StaticMappingQ1<dim>::mapping;
      std::vector<types::global_dof_index> dofs(fe.n_dofs_per_cell());
      for (const auto &cell : dof_handler.active_cell_iterators())
        if (cell->is_locally_owned())
          {
            cell->get_dof_indices(dofs);
            for (unsigned int i = 0; i < dofs.size(); ++i)
              {
                const auto [component, node] = fe.system_to_component_index(i);
                if (component > 0) // B = I: the same at every point
                  solution(dofs[i]) = initial.value(Point<dim>(), component);
                else
                  solution(dofs[i]) =
                    phi_needed ?
                      initial.value(mapping.transform_unit_to_real_cell(cell, nodes[node]), 0) :
                      0.;
              }
          }
    }

    template <int dim>
    FESystem<dim> make_fe(const Parameters::Solid &solid)
    {
      const unsigned int n_B = dim * (dim + 1) / 2;
      return FESystem<dim>(FE_DGQ<dim>(solid.degree), solid.elastic() ? 1 + n_B : 1);
    }
  } // namespace

  template <int dim>
  SolidPhase<dim>::SolidPhase(const Parameters::All                           &parameters,
                              const parallel::distributed::Triangulation<dim> &tria)
    : parameters(parameters)
    , weight(parameters.solid)
    , shape_on_profile(parameters.solid.shape_on_profile && parameters.solid.thinc_reconstruction)
    , fe(make_fe<dim>(parameters.solid))
    , dof_handler(tria)
  {
    if (!parameters.solid.body_force.is_zero())
      body_force = make_function<dim>(parameters.solid.body_force, dim);
  }

  template <int dim>
  std::vector<std::string> SolidPhase<dim>::component_names() const
  {
    std::vector<std::string> names = {"phi"};
    if (fe.n_components() > 1)
      for (unsigned int c = 0; c < n_B; ++c)
        {
          const auto ij = SymmetricTensor<2, dim>::unrolled_to_component_indices(c);
          names.push_back("B_" + std::to_string(ij[0] + 1) + std::to_string(ij[1] + 1));
        }
    return names;
  }

  template <int dim>
  void SolidPhase<dim>::reinit_discretization(const Fluid::FluidSpace<dim> &fluid_space)
  {
    // the old mesh's vectors are released first, so that the new mesh's
    // data reuse their memory instead of adding to the peak (a DG 2 field of
    // the level-4 box is 233 MB; together with its stages and the velocity
    // copies 0.8 GB)
    for (VectorType *v : {&solution, &stage, &stage_rhs, &u0, &u1, &u_stage})
      {
        VectorType released;
        v->swap(released);
      }
    dof_handler.distribute_dofs(fe);
    // hanging nodes of the velocity only (its Dirichlet and periodic
    // values are read as they are)
    AffineConstraints<double> velocity_constraints;
    velocity_constraints.reinit(fluid_space.relevant_velocity);
    DoFTools::make_hanging_node_constraints(fluid_space.dof_velocity, velocity_constraints);
    velocity_constraints.close();
    // before reinit, which prepares the cell geometry the profiles need
    transport.set_reconstruction(parameters.solid.thinc_reconstruction ?
                                   parameters.solid.thinc_sharpness :
                                   0.,
                                 parameters.solid.thinc_curvature,
                                 parameters.solid.thinc_smoothed_normal);
    transport.reinit(dof_handler, fluid_space.dof_velocity, velocity_constraints,
                     parameters.solid.elastic());
    transport.set_compression(parameters.solid.interface_compression,
                              parameters.solid.interface_thickness);
    if (parameters.solid.interface_sharpening > 1.)
      sharpening.reinit(dof_handler);
    transport.initialize_solid_vector(solution);
    transport.initialize_solid_vector(stage);
    transport.initialize_solid_vector(stage_rhs);
    transport.initialize_velocity_vector(u0);
    transport.initialize_velocity_vector(u1);
    transport.initialize_velocity_vector(u_stage);
    stress_values.reset();
  }

  template <int dim>
  std::vector<std::pair<std::string, std::size_t>> SolidPhase<dim>::memory_by_part() const
  {
    const std::size_t matrix_free = transport.matrix_free_memory();
    return {{"solid DoFs", dof_handler.memory_consumption()},
            {"solid MatrixFree", matrix_free},
            {"solid transport data", transport.memory_consumption() - matrix_free},
            {"solid fields", solution.memory_consumption() + stage.memory_consumption() +
                               stage_rhs.memory_consumption() + u0.memory_consumption() +
                               u1.memory_consumption() + u_stage.memory_consumption()}};
  }

  template <int dim>
  void SolidPhase<dim>::setup(const Fluid::FluidSpace<dim> &fluid_space, const double interface_h)
  {
    reinit_discretization(fluid_space);
    // exact cell fractions of the sharp shape (expressions: always)
    const bool exact_fractions =
      parameters.solid.interface_width == 0. ||
      parameters.solid.initial_fraction == Parameters::InitialFraction::function;
    interpolate_initial_solid(dof_handler,
                              InitialSolid<dim>(parameters, fe.n_components(), interface_h),
                              !exact_fractions,
                              solution);
    if (exact_fractions)
      initial_report = project_initial_fraction(parameters, dof_handler, solution);
    if (parameters.solid.limiter)
      transport.limit(solution, true);
    // what particle_shape() reads: the profiles of the current phi, kept so
    // by advance(), finish_mesh_change() and resume_from_checkpoint()
    transport.update_profiles(solution);
    boundary_outflow = 0.;
    updates          = 0;
    initial_volume   = diagnostics().volume;
    time             = 0.;
  }

  template <int dim>
  void SolidPhase<dim>::prepare_for_mesh_change()
  {
    solution.update_ghost_values();
    transfer = std::make_unique<parallel::distributed::SolutionTransfer<dim, VectorType>>(dof_handler);
    transfer->prepare_for_coarsening_and_refinement(solution);
  }

  template <int dim>
  void SolidPhase<dim>::prepare_for_checkpoint()
  {
    solution.update_ghost_values();
    transfer = std::make_unique<parallel::distributed::SolutionTransfer<dim, VectorType>>(dof_handler);
    transfer->prepare_for_serialization(solution);
  }

  template <int dim>
  void SolidPhase<dim>::checkpoint_written()
  {
    transfer.reset();
  }

  template <int dim>
  void SolidPhase<dim>::resume_from_checkpoint(const Fluid::FluidSpace<dim> &fluid_space)
  {
    reinit_discretization(fluid_space);
    parallel::distributed::SolutionTransfer<dim, VectorType>(dof_handler).deserialize(solution);
    // as saved: already limited, so no limiter here (it would not be the
    // uninterrupted run's state)
    solution.zero_out_ghost_values();
    transport.update_profiles(solution);
  }

  template <int dim>
  void SolidPhase<dim>::save(std::ostream &out) const
  {
    out << "SolidPhase " << std::setprecision(17) << initial_volume << " " << time << " "
        << boundary_outflow << " " << updates << "\n";
  }

  template <int dim>
  void SolidPhase<dim>::load(std::istream &in)
  {
    std::string tag;
    in >> tag >> initial_volume >> time >> boundary_outflow >> updates;
    AssertThrow(tag == "SolidPhase" && !in.fail(),
                ExcMessage("checkpoint: cannot read the solid's state"));
  }

  template <int dim>
  void SolidPhase<dim>::finish_mesh_change(const Fluid::FluidSpace<dim> &fluid_space)
  {
    reinit_discretization(fluid_space);
    transfer->interpolate(solution);
    transfer.reset();
    ++updates;
    // The L2 projection onto a coarse cell keeps its mean but may
    // overshoot at nodes: limit as after a transport stage.
    solution.zero_out_ghost_values();
    transport.limit(solution, true);
    if (fe.n_components() > 1)
      transport.limit_B(solution);
    transport.update_profiles(solution);
  }

  template <int dim>
  std::vector<unsigned char> SolidPhase<dim>::classify_cells(const double epsilon) const
  {
    std::vector<unsigned char> phase(dof_handler.get_triangulation().n_active_cells(), fluid_cell);
    PhiValues<dim> phi_values(fe, QGauss<dim>(fe.degree + 1), update_JxW_values);
    const auto    &fe_values = phi_values.fe_values();
    const auto    &phi       = phi_values.values();
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          phi_values.reinit(cell, solution);
          double lo = 1., hi = 0., mean = 0., measure = 0.;
          for (const unsigned int q : fe_values.quadrature_point_indices())
            {
              lo = std::min(lo, phi[q]);
              hi = std::max(hi, phi[q]);
              mean += phi[q] * fe_values.JxW(q);
              measure += fe_values.JxW(q);
            }
          for (const double value : phi_values.dof_values())
            {
              lo = std::min(lo, value);
              hi = std::max(hi, value);
            }
          // a value inside (epsilon, 1 - epsilon), or values on both sides
          const bool inside_range = hi > epsilon && lo < 1. - epsilon;
          auto &p = phase[cell->active_cell_index()];
          if (inside_range)
            p = interface_cell;
          else if (mean > 0.5 * measure)
            p = solid_cell;
        }
    return phase;
  }

  template <int dim>
  double SolidPhase<dim>::max_substep(const double speed_over_h) const
  {
    // speed_over_h = max |u| k_u / h; the DG limit is dt |u| (2k+1) / h <= C
    const double k_u = parameters.fluid_solver.velocity_degree;
    const double k   = parameters.solid.degree;
    if (speed_over_h <= 0.)
      return std::numeric_limits<double>::max();
    // the compression flux moves phi at up to c |u| on top of u; its
    // diffusion eps h c |u| adds the explicit diffusion limit (interior
    // penalty 2 (k+1)^2 / h, in each direction)
    const double c     = parameters.solid.interface_compression;
    const double speed = ((2. * k + 1.) * (1. + c) +
                          2. * dim * 2. * (k + 1.) * (k + 1.) * parameters.solid.interface_thickness * c) *
                         speed_over_h / k_u;
    // each integrator at about 0.8 of its linear limit for DG 1
    using Integrator = Parameters::Solid::TransportIntegrator;
    const double fraction = parameters.solid.integrator == Integrator::ssp_rk2  ? 0.8 :
                            parameters.solid.integrator == Integrator::ssp_rk32 ? 1.41 :
                                                                                  1.;
    return fraction * parameters.solid.transport_cfl / speed;
  }

  template <int dim>
  void SolidPhase<dim>::copy_velocity(const Fluid::VectorType &in, VectorType &out) const
  {
    LinearAlgebra::ReadWriteVector<double> values(out.locally_owned_elements());
    values.import(in, VectorOperation::insert);
    out.zero_out_ghost_values();
    out.import(values, VectorOperation::insert);
  }

  template <int dim>
  SolidDiagnostics SolidPhase<dim>::advance(const double dt, const double speed_over_h,
                                            const Fluid::VectorType &u_begin,
                                            const Fluid::VectorType &u_end)
  {
    copy_velocity(u_begin, u0);
    copy_velocity(u_end, u1);
    // ghosted for interface_speed()
    u0.update_ghost_values();
    u1.update_ghost_values();
    const double sub_steps = std::max(1., std::ceil(dt / max_substep(speed_over_h) - 1e-12));
    // A flow that blew up without (yet) a NaN would make the transport
    // crawl through millions of sub-steps: stop with the reason instead.
    if (!(sub_steps <= 1000.))
      {
        std::ostringstream message;
        message << "the velocity is too large for the transport (" << sub_steps << " sub-steps of the DG transport for one time step, "
                << "max |u| k / h = " << speed_over_h
                << "): the flow is unstable; reduce the time step or the CFL number";
        throw std::runtime_error(message.str());
      }
    const unsigned int n_sub = static_cast<unsigned int>(sub_steps);
    const double       h     = dt / n_sub;
    const bool         scale = parameters.solid.limiter;

    const auto velocity_at = [&](const double fraction) {
      u_stage.zero_out_ghost_values();
      u_stage.equ(1. - fraction, u0);
      u_stage.add(fraction, u1);
      u_stage.update_ghost_values();
    };
    LimiterReport report, r;
    const auto    limit = [&](VectorType &v) {
      v.zero_out_ghost_values();
      r = transport.limit(v, scale);
      if (scale)
        r.limited_cells += transport.limit_B(v);
      report.limited_cells += r.limited_cells;
      report.out_of_bound_means += r.out_of_bound_means;
    };

    // The boundary flux of each stage, with the weight the stage has in
    // the step: SSP-RK3 y1 = y0 + h L0, y2 = (3 y0 + y1 + h L1) / 4,
    // y3 = (y0 + 2 y2 + 2 h L2) / 3 = y0 + h (L0 / 6 + L1 / 6 + 2 L2 / 3);
    // SSP-RK2 y1 = y0 + h L0, y2 = (y0 + y1 + h L1) / 2 = y0 + h (L0 + L1) / 2;
    // SSP-RK(3,2) y1 = y0 + h/2 L0, y2 = y1 + h/2 L1,
    // y3 = (y0 + 2 (y2 + h/2 L2)) / 3 = y0 + h (L0 + L1 + L2) / 3.
    // The limiter keeps cell means, so int phi changes only by these.
    using Integrator       = Parameters::Solid::TransportIntegrator;
    const Integrator integrator = parameters.solid.integrator;
    double     outflow = 0., flux = 0.;
    // one stage: stage += step L(stage) with the velocity at t + fraction h
    const auto euler_stage = [&](VectorType &y, const double f, const double step) {
      velocity_at(f);
      flux = 0.;
      transport.apply(y, stage_rhs, u_stage, &flux);
      y.add(step, stage_rhs);
      return flux;
    };
    for (unsigned int s = 0; s < n_sub; ++s)
      {
        const double f = s * h / dt;
        // B where the sub-step can carry solid (elsewhere it stays I)
        transport.mark_solid_cells(solution);
        solution.zero_out_ghost_values();
        stage.equ(1., solution);
        if (integrator == Integrator::ssp_rk32)
          {
            // stages at t, t + h/2, t + h
            outflow += h / 3. * euler_stage(stage, f, h / 2.);
            limit(stage);
            outflow += h / 3. * euler_stage(stage, f + 0.5 * h / dt, h / 2.);
            limit(stage);
            outflow += h / 3. * euler_stage(stage, f + h / dt, h / 2.);
            // y0 / 3 + 2 z / 3 as z + (y0 - z) / 3 (see SSP-RK3 below)
            solution.add(-1., stage);
            solution.sadd(1. / 3., 1., stage);
            limit(solution);
            continue;
          }
        const bool rk2 = integrator == Integrator::ssp_rk2;
        // SSP-RK3: stages at t, t + h, t + h/2; SSP-RK2: at t, t + h
        outflow += (rk2 ? h / 2. : h / 6.) * euler_stage(stage, f, h);
        limit(stage);
        outflow += (rk2 ? h / 2. : h / 6.) * euler_stage(stage, f + h / dt, h);
        if (rk2)
          {
            // y0 / 2 + z / 2 as z + (y0 - z) / 2 (exact halves): int phi
            // moves by the boundary flux only
            solution.add(-1., stage);
            solution.sadd(0.5, 1., stage);
            limit(solution);
            continue;
          }
        stage.sadd(0.25, 0.75, solution);
        limit(stage);
        outflow += 2. * h / 3. * euler_stage(stage, f + 0.5 * h / dt, h);
        // y0 / 3 + 2 z / 3 as z + (y0 - z) / 3: the doubles nearest to 1/3
        // and 2/3 add up to 1 - 2^-54, which would take 5.6e-17 of int phi
        // in every sub-step (a drift linear in the sub-steps: 7e-11 after
        // 1.3 million); written so, int phi moves by int (y0 - z) / 3 only,
        // which is the boundary flux
        solution.add(-1., stage);
        solution.sadd(1. / 3., 1., stage);
        limit(solution);
      }
    // the transport sees only the cell means of interface cells (their
    // THINC profiles); what is measured and weighted sees the polynomial,
    // so it is made the profile's once per step
    if (transport.project_to_profiles(solution))
      limit(solution);
    boundary_outflow += Utilities::MPI::sum(outflow, dof_handler.get_communicator());
    updates += n_sub;
    time += dt;
    sharpen_interface();
    reset_B_in_fluid(dt);
    // The reset puts I at nodes next to stretched ones. Above degree 1 the
    // Lagrange basis is negative between its nodes, so the mix can leave
    // the SPD cone at a point inside the cell (the 3D box stopped so at
    // phi = 0.98, session 34): limit B once more. The cell means stay
    // SPD, positive combinations of the nodes' values (the basis
    // functions' integrals are positive), so the scaling always exists.
    if (scale && parameters.solid.degree > 1 && fe.n_components() > 1)
      {
        solution.zero_out_ghost_values();
        report.limited_cells += transport.limit_B(solution);
      }

    SolidDiagnostics d     = diagnostics();
    d.limited_cells        = Utilities::MPI::sum(report.limited_cells, dof_handler.get_communicator());
    d.out_of_bound_means   = Utilities::MPI::sum(report.out_of_bound_means, dof_handler.get_communicator());
    d.substeps             = n_sub;
    check_B(d, time);
    return d;
  }

  template <int dim>
  const std::vector<Vector<double>> &
  SolidPhase<dim>::values_at(const typename DoFHandler<dim>::active_cell_iterator &solid_cell,
                             const std::vector<Point<dim>> &unit_points) const
  {
    if (!stress_values || stress_values->n_quadrature_points != unit_points.size())
      stress_values = std::make_unique<FEValues<dim>>(fe, Quadrature<dim>(unit_points), update_values);
    stress_values->reinit(solid_cell);
    point_values.resize(unit_points.size(), Vector<double>(fe.n_components()));
    // summed from cell_values in the order get_function_values uses, without
    // its per-call allocation and vector read
    for (unsigned int q = 0; q < unit_points.size(); ++q)
      {
        point_values[q] = 0.;
        for (unsigned int i = 0; i < fe.n_dofs_per_cell(); ++i)
          point_values[q][fe.system_to_component_index(i).first] +=
            cell_values[i] * stress_values->shape_value(i, q);
      }
    return point_values;
  }

  template <int dim>
  bool SolidPhase<dim>::unstrained(const Vector<double> &values) const
  {
    for (unsigned int i = 0; i < values.size(); ++i)
      {
        const unsigned int c = fe.system_to_component_index(i).first;
        if (c > 0 && values[i] != (c <= dim ? 1. : 0.))
          return false;
      }
    return true;
  }

  template <int dim>
  void SolidPhase<dim>::sharpen_interface()
  {
    if (parameters.solid.interface_sharpening <= 1. ||
        ++steps_since_sharpening < parameters.solid.sharpening_interval)
      return;
    steps_since_sharpening = 0;
    solution.zero_out_ghost_values();
    sharpening.apply(solution, parameters.solid.interface_sharpening);
    ++updates;
    // the nodal map keeps the nodes in [0, 1]; between the nodes of
    // degree > 1 the limiter does (cell means unchanged)
    if (parameters.solid.limiter && parameters.solid.degree > 1)
      transport.limit(solution, true);
    transport.update_profiles(solution);
  }

  template <int dim>
  void SolidPhase<dim>::reset_B_in_fluid(const double dt)
  {
    const double relaxation = parameters.solid.interface_relaxation;
    // Fluid keeps no memory of deformation. Sharp stress weight: B = I at
    // every node where H(phi) = 0, so that no stress can build up in the
    // diffuse tail of phi. Weight phi: in cells without solid (phi below
    // fluid_threshold at every node); B would otherwise grow without bound
    // in sheared fluid (B_11 = 1 + (shear t)^2) and its discretization
    // errors would end the run through the SPD check.
    if (fe.n_components() == 1)
      return;
    const unsigned int n_nodes = fe.base_element(0).n_dofs_per_cell();
    std::vector<types::global_dof_index> dofs(fe.n_dofs_per_cell());
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          cell->get_dof_indices(dofs);
          const auto phi_at = [&](const unsigned int node) {
            return solution(dofs[fe.component_to_system_index(0, node)]);
          };
          bool fluid_cell = true;
          for (unsigned int j = 0; j < n_nodes && fluid_cell; ++j)
            fluid_cell = std::abs(phi_at(j)) < fluid_threshold;
          for (unsigned int j = 0; j < n_nodes; ++j)
            if (weight.sharp ? weight.resets_B(phi_at(j)) : fluid_cell)
              for (unsigned int c = 1; c <= n_B; ++c)
                solution(dofs[fe.component_to_system_index(c, j)]) = (c <= dim ? 1. : 0.);
            else if (relaxation > 0.)
              {
                // B - I relaxed at the rate R (1 - H(phi)): zero in the solid
                const double factor = std::exp(-relaxation * (1. - weight(phi_at(j))) * dt);
                if (factor < 1.)
                  for (unsigned int c = 1; c <= n_B; ++c)
                    {
                      double &b = solution(dofs[fe.component_to_system_index(c, j)]);
                      const double identity = (c <= dim ? 1. : 0.);
                      b = identity + factor * (b - identity);
                    }
              }
        }
  }

  template <int dim>
  void SolidPhase<dim>::check_B(const SolidDiagnostics &d, const double t) const
  {
    // Without the limiter DG overshoots by a few per cent at a sharp edge;
    // half a unit means the transport itself has become unstable.
    if (!(d.min_phi > -0.5 && d.max_phi < 1.5))
      {
        std::ostringstream message;
        message << "the solid fraction phi left [-0.5, 1.5] at t = " << t << " (range ["
                << d.min_phi << ", " << d.max_phi
                << "]): the transport is unstable; switch 'Solid/Limiter' on or reduce "
                   "'Solid/Transport CFL'; the last state was written";
        throw std::runtime_error(message.str());
      }
    if (fe.n_components() == 1)
      return;
    if (!(d.min_eigenvalue_B > 0.) || !std::isfinite(d.volume))
      {
        std::ostringstream message;
        message << "the left Cauchy-Green tensor B is no longer symmetric positive definite at t = "
                << t << " at (" << d.worst_B_location[0];
        for (unsigned int c = 1; c < dim; ++c)
          message << ", " << d.worst_B_location[c];
        message << "), where phi = " << d.worst_B_phi << " (stress weight H = "
                << weight(d.worst_B_phi) << ") (smallest eigenvalue " << d.min_eigenvalue_B
                << "); reduce the time step ('Solid/Elastic number', 'Time stepping/CFL "
                   "number') or refine the mesh; the last state was written";
        throw std::runtime_error(message.str());
      }
  }

  template <int dim>
  void SolidPhase<dim>::add(const typename Triangulation<dim>::active_cell_iterator &cell,
                            const std::vector<Point<dim>> &points,
                            const std::vector<Point<dim>> &unit_points,
                            const double                   time,
                            std::vector<Tensor<1, dim>> &force,
                            std::vector<SymmetricTensor<2, dim>> &stress) const
  {
    if (!pushes_fluid())
      return;
    // Most cells hold fluid only: B = I at every node (reset_B_in_fluid),
    // so G H (B - I) is exactly zero there and the cell is skipped.
    const auto solid_cell = Fluid::FluidSpace<dim>::cell_of(cell, dof_handler);
    cell_values.reinit(fe.n_dofs_per_cell());
    solid_cell->get_dof_values(solution, cell_values);
    if (!body_force && unstrained(cell_values))
      return;
    const auto &values = values_at(solid_cell, unit_points);
    if (body_force)
      {
        body_force->set_time(time);
        for (unsigned int q = 0; q < points.size(); ++q)
          for (unsigned int d = 0; d < dim; ++d)
            force[q][d] += values[q][0] * body_force->value(points[q], d);
      }
    if (fe.n_components() == 1)
      return;
    const double G = parameters.solid.shear_modulus;
    for (unsigned int q = 0; q < unit_points.size(); ++q)
      for (unsigned int c = 0; c < n_B; ++c)
        {
          const auto ij = SymmetricTensor<2, dim>::unrolled_to_component_indices(c);
          stress[q][ij] += G * weight(values[q][0]) * (values[q][1 + c] - (ij[0] == ij[1] ? 1. : 0.));
        }
  }

  template <int dim>
  bool SolidPhase<dim>::elastic_stiffness(
    const typename Triangulation<dim>::active_cell_iterator &cell,
    const std::vector<Point<dim>>                           &unit_points,
    std::vector<double>                                     &modulus,
    std::vector<SymmetricTensor<2, dim>>                    &B) const
  {
    if (!parameters.solid.semi_implicit || fe.n_components() == 1)
      return false;
    const auto solid_cell = Fluid::FluidSpace<dim>::cell_of(cell, dof_handler);
    cell_values.reinit(fe.n_dofs_per_cell());
    solid_cell->get_dof_values(solution, cell_values);
    const auto  &values = values_at(solid_cell, unit_points);
    const double G      = parameters.solid.shear_modulus;
    for (unsigned int q = 0; q < unit_points.size(); ++q)
      {
        modulus[q] = G * weight(values[q][0]);
        for (unsigned int c = 0; c < n_B; ++c)
          B[q][SymmetricTensor<2, dim>::unrolled_to_component_indices(c)] = values[q][1 + c];
      }
    return true;
  }

  template class SolidPhase<2>;
  template class SolidPhase<3>;
} // namespace Suspension::Solid
