// The projection's pressure Poisson problem on the main job's kind of mesh,
// solved two ways side by side (issue 14, item 1: "measure both"):
//
//  - amg: the solver's choice today, an assembled PETSc matrix of the Q1
//    Laplacian (hanging-node and periodicity constraints, one DoF pinned),
//    CG preconditioned with BoomerAMG (strong threshold 0.25 in 2D, 0.5 in
//    3D, as source/fluid/fluid_operators.cc);
//  - gmg local: no matrix, MatrixFreeOperators::LaplaceOperator on every
//    level, geometric multigrid with local smoothing (MGTransferMatrixFree;
//    float levels, Chebyshev of degree 4 around a Jacobi diagonal, CG to
//    1e-4 on level 0), the singular Neumann/periodic system solved with a
//    mean-free right-hand side;
//  - gmg global: the same operators and smoothers with global coarsening
//    (MGTransferGlobalCoarsening: each level an active mesh of its own, the
//    fine one coarsened, with its own hanging-node and periodicity
//    constraints).
//
// The mesh is made as the solver's adaptivity makes it at t = 0: a channel
// periodic in the streamwise (and spanwise) directions with walls normal to
// the last axis, refined to `max level` within `buffer` cells of the
// surfaces of randomly placed discs (spheres). The right-hand side is the
// load of a field concentrated at those surfaces, as the divergence of a
// predicted velocity is. Both solve to the same relative residual (1e-8,
// the main job's) from a zero guess; the solutions are compared.
//
// Usage: pressure_poisson DIM MAX_LEVEL [N_SOLVES]
// prints one line per method: set-up s, solve s (mean of N_SOLVES),
// iterations, the heap memory its set-up holds.

#include <deal.II/base/conditional_ostream.h>
#include <deal.II/base/function.h>
#include <deal.II/base/index_set.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/timer.h>
#include <deal.II/base/utilities.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_q1.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/la_parallel_vector.h>
#include <deal.II/lac/petsc_precondition.h>
#include <deal.II/lac/petsc_solver.h>
#include <deal.II/lac/petsc_sparse_matrix.h>
#include <deal.II/lac/petsc_vector.h>
#include <deal.II/lac/precondition.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/sparsity_tools.h>
#include <deal.II/matrix_free/matrix_free.h>
#include <deal.II/matrix_free/operators.h>
#include <deal.II/multigrid/mg_coarse.h>
#include <deal.II/multigrid/mg_constrained_dofs.h>
#include <deal.II/multigrid/mg_matrix.h>
#include <deal.II/multigrid/mg_smoother.h>
#include <deal.II/multigrid/mg_tools.h>
#include <deal.II/multigrid/mg_transfer_global_coarsening.h>
#include <deal.II/multigrid/mg_transfer_matrix_free.h>
#include <deal.II/multigrid/multigrid.h>

#include <malloc.h>

#include <fstream>
#include <iomanip>
#include <iostream>
#include <cstdlib>
#include <random>

using namespace dealii;

namespace
{
  constexpr double tolerance = 1e-8;
  constexpr double radius    = 0.1;

  /// heap memory in use by this process now, MB (glibc's mallinfo2: the
  /// bytes allocated and not freed, PETSc's and hypre's included), so that
  /// what one method frees is not counted again for the next
  double heap_mb()
  {
    const struct mallinfo2 info = mallinfo2();
    return (info.uordblks + info.hblkhd) / 1e6;
  }

  template <int dim>
  struct Box
  {
    Point<dim>                lower, upper;
    std::vector<unsigned int> subdivisions;
    unsigned int              n_particles;
  };

  /// the main job's channel (2D) and the reduced 3D box
  template <int dim>
  Box<dim> make_box()
  {
    if constexpr (dim == 2)
      return {Point<dim>(0, -1), Point<dim>(6, 1), {6, 2}, 38};
    else
      return {Point<dim>(0, 0, -1), Point<dim>(1, 0.5, 1), {4, 2, 8}, 24};
  }

  /// random non-overlapping centres, a gap of 0.03 to each other and the walls
  template <int dim>
  std::vector<Point<dim>> seed(const Box<dim> &box)
  {
    std::mt19937                     random(1);
    std::vector<Point<dim>>          centres;
    std::uniform_real_distribution<> unit(0., 1.);
    while (centres.size() < box.n_particles)
      {
        Point<dim> c;
        for (unsigned int d = 0; d < dim; ++d)
          {
            const double margin = d == dim - 1 ? radius + 0.03 : 0.;
            c[d] = box.lower[d] + margin + unit(random) * (box.upper[d] - box.lower[d] - 2 * margin);
          }
        bool fits = true;
        for (const auto &o : centres)
          fits = fits && c.distance(o) > 2 * radius + 0.03;
        if (fits)
          centres.push_back(c);
      }
    return centres;
  }

  /// distance from x to the nearest particle surface (periodic images in
  /// all but the last direction)
  template <int dim>
  double surface_distance(const Point<dim> &x, const std::vector<Point<dim>> &centres,
                          const Box<dim> &box, Tensor<1, dim> *normal = nullptr)
  {
    double best = 1e300;
    for (const auto &c : centres)
      {
        Tensor<1, dim> r = x - c;
        for (unsigned int d = 0; d + 1 < dim; ++d)
          {
            const double L = box.upper[d] - box.lower[d];
            r[d] -= L * std::round(r[d] / L);
          }
        const double distance = std::abs(r.norm() - radius);
        if (distance < best)
          {
            best = distance;
            if (normal)
              *normal = r / std::max(r.norm(), 1e-12);
          }
      }
    return best;
  }

  /// a load concentrated at the surfaces, as div u* of a predicted velocity
  template <int dim>
  class SurfaceLoad : public Function<dim>
  {
  public:
    SurfaceLoad(const std::vector<Point<dim>> &centres, const Box<dim> &box)
      : centres(centres)
      , box(box)
    {}
    double value(const Point<dim> &x, const unsigned int = 0) const override
    {
      Tensor<1, dim> n;
      const double   d = surface_distance(x, centres, box, &n);
      return std::exp(-d * d / (0.02 * 0.02)) * n[0] + 0.1 * std::sin(M_PI * x[dim - 1]);
    }

  private:
    const std::vector<Point<dim>> &centres;
    const Box<dim>                &box;
  };

  /// a ReductionControl that reports its last step as success
  class CoarseControl : public ReductionControl
  {
  public:
    using ReductionControl::ReductionControl;
    State check(const unsigned int step, const double value) override
    {
      const State state = ReductionControl::check(step, value);
      return state == failure ? success : state;
    }
  };

  /// CG on the coarsest level of a singular (Neumann, periodic) problem:
  /// the right-hand side's part along the null vector (1 on the level's
  /// unconstrained DoFs) removed first
  template <typename Operator, typename Vector>
  class MeanFreeCoarseSolver : public MGCoarseGridBase<Vector>
  {
  public:
    MeanFreeCoarseSolver(const Operator &op)
      : op(op)
    {
      op.initialize_dof_vector(null_vector);
      null_vector = 1.;
      for (const auto i : op.get_matrix_free()->get_constrained_dofs())
        null_vector.local_element(i) = 0.;
      null_vector /= null_vector.l2_norm();
    }
    void operator()(const unsigned int, Vector &dst, const Vector &src) const override
    {
      Vector rhs(src);
      rhs.add(-(rhs * null_vector), null_vector);
      CoarseControl     control(200, 1e-30, 1e-4, false, false);
      SolverCG<Vector>  cg(control);
      dst = 0.;
      cg.solve(op, dst, rhs, PreconditionIdentity());
    }

  private:
    const Operator &op;
    Vector          null_vector;
  };

  template <int dim>
  class Benchmark
  {
  public:
    Benchmark(const unsigned int max_level, const unsigned int n_solves);
    void run();

  private:
    using LevelVector   = LinearAlgebra::distributed::Vector<float>;
    using VectorType    = LinearAlgebra::distributed::Vector<double>;
    using LevelOperator = MatrixFreeOperators::LaplaceOperator<dim, 1, 2, 1, LevelVector>;
    using ActiveOperator = MatrixFreeOperators::LaplaceOperator<dim, 1, 2, 1, VectorType>;

    void make_mesh();
    void run_amg();
    void run_gmg();
    void run_gmg_global();

    using Smoother = PreconditionChebyshev<LevelOperator, LevelVector>;
    /// the matrix-free Laplacian of the active mesh (both multigrid paths)
    std::shared_ptr<MatrixFree<dim, double>> make_active_operator(ActiveOperator &A) const;
    /// Chebyshev of degree smoothing_degree around each level's Jacobi
    MGLevelObject<typename Smoother::AdditionalData>
    chebyshev_data(const MGLevelObject<LevelOperator> &level_operators) const;
    /// n_solves CG solves of A x = b from zero, at most 300 iterations each
    /// (with periodic faces the local-smoothing multigrid is not a
    /// converging preconditioner, doc/method.md: reported, not aborted);
    /// returns the last solve's iterations and whether all converged
    template <typename Preconditioner>
    std::pair<unsigned int, bool> solve_repeatedly(const ActiveOperator &A, VectorType &x,
                                                   const VectorType     &b,
                                                   const Preconditioner &preconditioner) const;

    MPI_Comm                                  communicator;
    ConditionalOStream                        pcout;
    Box<dim>                                  box;
    std::vector<Point<dim>>                   centres;
    parallel::distributed::Triangulation<dim> tria;
    FE_Q<dim>                                 fe;
    DoFHandler<dim>                           dof;
    MappingQ1<dim>                            mapping;
    IndexSet                                  owned, relevant;
    AffineConstraints<double>                 constraints; // hanging nodes, periodicity
    const unsigned int                        max_level, n_solves;
    /// PRESSURE_POISSON_WALLS=1: walls all round instead of periodic faces
    const bool periodic = std::getenv("PRESSURE_POISSON_WALLS") == nullptr;
    /// PRESSURE_POISSON_CHEBYSHEV=k: the smoother's degree (4)
    const unsigned int smoothing_degree =
      std::getenv("PRESSURE_POISSON_CHEBYSHEV") ? std::atoi(std::getenv("PRESSURE_POISSON_CHEBYSHEV")) : 4;
    VectorType                                gmg_solution, gmg_rhs;
  };

  template <int dim>
  Benchmark<dim>::Benchmark(const unsigned int max_level, const unsigned int n_solves)
    : communicator(MPI_COMM_WORLD)
    , pcout(std::cout, Utilities::MPI::this_mpi_process(communicator) == 0)
    , box(make_box<dim>())
    , centres(seed(box))
    , tria(communicator, Triangulation<dim>::limit_level_difference_at_vertices,
           parallel::distributed::Triangulation<dim>::construct_multigrid_hierarchy)
    , fe(1)
    , dof(tria)
    , max_level(max_level)
    , n_solves(n_solves)
  {}

  template <int dim>
  std::shared_ptr<MatrixFree<dim, double>>
  Benchmark<dim>::make_active_operator(ActiveOperator &A) const
  {
    auto data = std::make_shared<MatrixFree<dim, double>>();
    typename MatrixFree<dim, double>::AdditionalData additional;
    additional.tasks_parallel_scheme = MatrixFree<dim, double>::AdditionalData::none;
    additional.mapping_update_flags  = update_gradients | update_JxW_values;
    data->reinit(mapping, dof, constraints, QGauss<1>(2), additional);
    A.initialize(data);
    return data;
  }

  template <int dim>
  auto Benchmark<dim>::chebyshev_data(const MGLevelObject<LevelOperator> &level_operators) const
    -> MGLevelObject<typename Smoother::AdditionalData>
  {
    MGLevelObject<typename Smoother::AdditionalData> data(level_operators.min_level(),
                                                          level_operators.max_level());
    for (unsigned int level = data.min_level(); level <= data.max_level(); ++level)
      {
        data[level].smoothing_range     = 15.;
        data[level].degree              = smoothing_degree;
        data[level].eig_cg_n_iterations = 10;
        data[level].preconditioner      = level_operators[level].get_matrix_diagonal_inverse();
      }
    return data;
  }

  template <int dim>
  template <typename Preconditioner>
  std::pair<unsigned int, bool>
  Benchmark<dim>::solve_repeatedly(const ActiveOperator &A, VectorType &x, const VectorType &b,
                                   const Preconditioner &preconditioner) const
  {
    unsigned int iterations = 0;
    bool         converged  = true;
    for (unsigned int s = 0; s < n_solves; ++s)
      {
        x = 0.;
        SolverControl        control(300, tolerance * b.l2_norm());
        SolverCG<VectorType> cg(control);
        try
          {
            cg.solve(A, x, b, preconditioner);
          }
        catch (const SolverControl::NoConvergence &)
          {
            converged = false;
          }
        iterations = control.last_step();
      }
    return {iterations, converged};
  }

  template <int dim>
  void Benchmark<dim>::make_mesh()
  {
    GridGenerator::subdivided_hyper_rectangle(tria, box.subdivisions, box.lower, box.upper, true);
    std::vector<GridTools::PeriodicFacePair<typename Triangulation<dim>::cell_iterator>> pairs;
    if (periodic)
      {
        for (unsigned int d = 0; d + 1 < dim; ++d)
          GridTools::collect_periodic_faces(tria, 2 * d, 2 * d + 1, d, pairs);
        tria.add_periodicity(pairs);
      }
    // refine to max_level within 3 cells (of the finest level) of a surface,
    // coarser levels in a band as wide in their own cells
    for (unsigned int level = 0; level < max_level; ++level)
      {
        for (const auto &cell : tria.active_cell_iterators())
          if (cell->is_locally_owned() && static_cast<unsigned int>(cell->level()) < max_level)
            {
              const double h = cell->extent_in_direction(0);
              if (surface_distance(cell->center(), centres, box) < 0.5 * std::sqrt(dim) * h + 3 * h)
                cell->set_refine_flag();
            }
        tria.execute_coarsening_and_refinement();
      }
    dof.distribute_dofs(fe);
    dof.distribute_mg_dofs();
    owned    = dof.locally_owned_dofs();
    relevant = DoFTools::extract_locally_relevant_dofs(dof);
    constraints.reinit(relevant);
    DoFTools::make_hanging_node_constraints(dof, constraints);
    if (periodic)
      for (unsigned int d = 0; d + 1 < dim; ++d)
        DoFTools::make_periodicity_constraints(dof, 2 * d, 2 * d + 1, d, constraints);
    constraints.close();
    pcout << "mesh: " << tria.n_global_active_cells() << " cells, " << tria.n_global_levels()
          << " levels, " << dof.n_dofs() << " pressure DoFs (Q1), " << centres.size()
          << " particles, " << Utilities::MPI::n_mpi_processes(communicator) << " ranks"
          << std::endl;
  }

  template <int dim>
  void Benchmark<dim>::run_amg()
  {
    const double memory_before = heap_mb();
    Timer        timer(communicator, true);

    // the solver's pinned DoF: the first owned one of rank 0
    AffineConstraints<double> pinned(relevant);
    pinned.merge(constraints);
    const types::global_dof_index first = Utilities::MPI::min(
      owned.n_elements() > 0 ? *owned.begin() : dof.n_dofs(), communicator);
    if (relevant.is_element(first) && !pinned.is_constrained(first))
      pinned.add_line(first);
    pinned.close();

    DynamicSparsityPattern dsp(relevant);
    DoFTools::make_sparsity_pattern(dof, dsp, pinned, false);
    SparsityTools::distribute_sparsity_pattern(dsp, owned, communicator, relevant);
    PETScWrappers::MPI::SparseMatrix L;
    L.reinit(owned, owned, dsp, communicator);
    PETScWrappers::MPI::Vector b(owned, communicator), x(owned, communicator);

    SurfaceLoad<dim>   load(centres, box);
    const QGauss<dim>  quadrature(2);
    FEValues<dim>      fe_values(fe, quadrature,
                                 update_values | update_gradients | update_JxW_values |
                                   update_quadrature_points);
    const unsigned int n = fe.n_dofs_per_cell();
    FullMatrix<double> cell_L(n, n);
    Vector<double>     cell_b(n);
    std::vector<types::global_dof_index> dofs(n);
    for (const auto &cell : dof.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          fe_values.reinit(cell);
          cell_L = 0;
          cell_b = 0;
          for (const unsigned int q : fe_values.quadrature_point_indices())
            {
              const double f = load.value(fe_values.quadrature_point(q));
              for (unsigned int i = 0; i < n; ++i)
                {
                  for (unsigned int j = 0; j < n; ++j)
                    cell_L(i, j) +=
                      fe_values.shape_grad(i, q) * fe_values.shape_grad(j, q) * fe_values.JxW(q);
                  cell_b(i) += f * fe_values.shape_value(i, q) * fe_values.JxW(q);
                }
            }
          cell->get_dof_indices(dofs);
          pinned.distribute_local_to_global(cell_L, cell_b, dofs, L, b);
        }
    L.compress(VectorOperation::add);
    b.compress(VectorOperation::add);
    // solve for the matrix-free path's mean-free load (the pinned row zero),
    // so that the two solutions differ by a constant only
    for (const auto i : owned)
      b(i) = pinned.is_constrained(i) ? 0. : gmg_rhs(i);
    b.compress(VectorOperation::insert);
    const double assembly = timer.wall_time();

    PETScWrappers::PreconditionBoomerAMG                 amg;
    PETScWrappers::PreconditionBoomerAMG::AdditionalData data;
    data.symmetric_operator = true;
    data.strong_threshold   = dim == 2 ? 0.25 : 0.5;
    amg.initialize(L, data);
    const double setup = timer.wall_time();

    unsigned int iterations = 0;
    for (unsigned int s = 0; s < n_solves; ++s)
      {
        x = 0.;
        SolverControl             control(5000, tolerance * b.l2_norm());
        PETScWrappers::SolverCG   cg(control, communicator);
        cg.solve(L, x, b, amg);
        iterations = control.last_step();
      }
    const double solve = (timer.wall_time() - setup) / n_solves;
    const double memory_after = heap_mb();

    // the difference from the matrix-free solution, both mean-free
    VectorType amg_solution(owned, relevant, communicator);
    for (const auto i : owned)
      amg_solution(i) = x(i);
    amg_solution.update_ghost_values();
    constraints.distribute(amg_solution);
    VectorType ones(gmg_solution);
    ones = 1.;
    const double n_dofs = dof.n_dofs();
    amg_solution.add(-(amg_solution * ones) / n_dofs, ones);
    amg_solution -= gmg_solution;

    pcout << std::fixed << std::setprecision(3) << "amg: assembly " << assembly
          << " s, AMG set-up " << setup - assembly << " s, solve " << solve << " s, "
          << iterations << " iterations, heap growth "
          << Utilities::MPI::sum(memory_after - memory_before, communicator) << " MB" << std::endl;
    pcout << std::scientific << std::setprecision(2)
          << "max |p_amg - p_gmg| (both mean-free): " << amg_solution.linfty_norm()
          << " of max |p| " << gmg_solution.linfty_norm() << std::endl;
  }

  template <int dim>
  void Benchmark<dim>::run_gmg()
  {
    const double memory_before = heap_mb();
    Timer        timer(communicator, true);

    // the active level: no matrix, the load assembled matrix-free-style
    // with FEValues (the solver's projection gets it from D u)
    ActiveOperator A;
    const auto     active_data = make_active_operator(A);

    MGConstrainedDoFs mg_constrained_dofs;
    mg_constrained_dofs.initialize(dof);
    const unsigned int              n_levels = tria.n_global_levels();
    MGLevelObject<LevelOperator>    level_operators(0, n_levels - 1);
    for (unsigned int level = 0; level < n_levels; ++level)
      {
        typename MatrixFree<dim, float>::AdditionalData additional;
        additional.tasks_parallel_scheme = MatrixFree<dim, float>::AdditionalData::none;
        additional.mapping_update_flags  = update_gradients | update_JxW_values;
        additional.mg_level              = level;
        AffineConstraints<double> level_constraints;
        level_constraints.copy_from(mg_constrained_dofs.get_level_constraints(level));
        level_constraints.close();
        auto level_data = std::make_shared<MatrixFree<dim, float>>();
        level_data->reinit(mapping, dof, level_constraints, QGauss<1>(2), additional);
        level_operators[level].initialize(level_data, mg_constrained_dofs, level);
        level_operators[level].compute_diagonal();
      }
    MGTransferMatrixFree<dim, float> transfer(mg_constrained_dofs);
    transfer.build(dof);

    mg::SmootherRelaxation<Smoother, LevelVector> smoother;
    smoother.initialize(level_operators, chebyshev_data(level_operators));
    // level 0 (the coarse mesh) solved by CG to 1e-4 after the restricted
    // residual is made orthogonal to the level's constants (with walls it
    // is already; with periodic faces it is not, see doc/method.md)
    MeanFreeCoarseSolver<LevelOperator, LevelVector> coarse(level_operators[0]);

    mg::Matrix<LevelVector> level_matrix(level_operators);
    MGLevelObject<MatrixFreeOperators::MGInterfaceOperator<LevelOperator>> interface_operators(
      0, n_levels - 1);
    for (unsigned int level = 0; level < n_levels; ++level)
      interface_operators[level].initialize(level_operators[level]);
    mg::Matrix<LevelVector> interface_matrix(interface_operators);

    Multigrid<LevelVector> mg(level_matrix, coarse, transfer, smoother, smoother);
    mg.set_edge_matrices(interface_matrix, interface_matrix);
    PreconditionMG<dim, LevelVector, MGTransferMatrixFree<dim, float>> preconditioner(dof, mg,
                                                                                      transfer);
    const double setup = timer.wall_time();

    // the same load as the assembled path, made mean-free (the Neumann and
    // periodic problem is singular: its right-hand side must be orthogonal
    // to the constants)
    VectorType b, x;
    active_data->initialize_dof_vector(b);
    active_data->initialize_dof_vector(x);
    {
      SurfaceLoad<dim>   load(centres, box);
      const QGauss<dim>  quadrature(2);
      FEValues<dim>      fe_values(fe, quadrature,
                                   update_values | update_JxW_values | update_quadrature_points);
      const unsigned int n = fe.n_dofs_per_cell();
      Vector<double>     cell_b(n);
      std::vector<types::global_dof_index> dofs(n);
      for (const auto &cell : dof.active_cell_iterators())
        if (cell->is_locally_owned())
          {
            fe_values.reinit(cell);
            cell_b = 0;
            for (const unsigned int q : fe_values.quadrature_point_indices())
              {
                const double f = load.value(fe_values.quadrature_point(q));
                for (unsigned int i = 0; i < n; ++i)
                  cell_b(i) += f * fe_values.shape_value(i, q) * fe_values.JxW(q);
              }
            cell->get_dof_indices(dofs);
            constraints.distribute_local_to_global(cell_b, dofs, b);
          }
      b.compress(VectorOperation::add);
      VectorType ones(b);
      ones = 0.;
      unsigned int free_dofs = 0;
      for (const auto i : owned)
        if (!constraints.is_constrained(i))
          {
            ones(i) = 1.;
            ++free_dofs;
          }
      b.add(-(b * ones) / Utilities::MPI::sum(free_dofs, communicator), ones);
    }
    const double load_time = timer.wall_time() - setup;

    const auto [iterations, converged] = solve_repeatedly(A, x, b, preconditioner);
    const double solve = (timer.wall_time() - setup - load_time) / n_solves;
    const double memory_after = heap_mb();

    constraints.distribute(x);
    VectorType ones(x);
    ones = 1.;
    x.add(-(x * ones) / static_cast<double>(dof.n_dofs()), ones);
    gmg_solution.reinit(owned, relevant, communicator);
    gmg_solution = x;
    gmg_rhs = b;

    std::size_t operator_memory = active_data->memory_consumption() + transfer.memory_consumption();
    for (unsigned int level = 0; level < n_levels; ++level)
      operator_memory += level_operators[level].memory_consumption();
    pcout << std::fixed << std::setprecision(3) << "gmg local (Chebyshev " << smoothing_degree << "): set-up " << setup << " s, solve " << solve
          << " s, " << iterations << (converged ? "" : " (not converged)")
          << " iterations, operators and transfer "
          << Utilities::MPI::sum(operator_memory, communicator) / 1e6 << " MB, heap growth "
          << Utilities::MPI::sum(memory_after - memory_before, communicator) << " MB" << std::endl;
  }

  /// geometric multigrid with global coarsening: every level is an active
  /// mesh of its own (the fine mesh coarsened 1, 2, ... times), with its own
  /// hanging-node and periodicity constraints, which MGTwoLevelTransfer
  /// applies on both sides of each transfer
  template <int dim>
  void Benchmark<dim>::run_gmg_global()
  {
    const double memory_before = heap_mb();
    Timer        timer(communicator, true);

    ActiveOperator A;
    const auto     active_data = make_active_operator(A);

    const auto triangulations =
      MGTransferGlobalCoarseningTools::create_geometric_coarsening_sequence(tria);
    const unsigned int n_levels = triangulations.size();
    std::vector<std::unique_ptr<DoFHandler<dim>>> level_dofs(n_levels);
    std::vector<AffineConstraints<double>>        level_constraints(n_levels);
    MGLevelObject<LevelOperator>                  level_operators(0, n_levels - 1);
    MGLevelObject<MGTwoLevelTransfer<dim, LevelVector>> transfers(0, n_levels - 1);
    unsigned int coarse_periodic_faces = 0;
    for (unsigned int level = 0; level < n_levels; ++level)
      {
        const DoFHandler<dim> *level_dof = &dof;
        if (level + 1 < n_levels)
          {
            level_dofs[level] = std::make_unique<DoFHandler<dim>>(*triangulations[level]);
            level_dofs[level]->distribute_dofs(fe);
            level_dof = level_dofs[level].get();
          }
        AffineConstraints<double> &c = level_constraints[level];
        c.reinit(DoFTools::extract_locally_relevant_dofs(*level_dof));
        DoFTools::make_hanging_node_constraints(*level_dof, c);
        if (periodic)
          for (unsigned int d = 0; d + 1 < dim; ++d)
            DoFTools::make_periodicity_constraints(*level_dof, 2 * d, 2 * d + 1, d, c);
        c.close();
        if (level == 0)
          for (const auto &cell : triangulations[0]->active_cell_iterators())
            if (cell->is_locally_owned())
              for (const unsigned int f : cell->face_indices())
                coarse_periodic_faces += cell->has_periodic_neighbor(f);

        typename MatrixFree<dim, float>::AdditionalData additional;
        additional.tasks_parallel_scheme = MatrixFree<dim, float>::AdditionalData::none;
        additional.mapping_update_flags  = update_gradients | update_JxW_values;
        auto level_data = std::make_shared<MatrixFree<dim, float>>();
        level_data->reinit(mapping, *level_dof, c, QGauss<1>(2), additional);
        level_operators[level].initialize(level_data);
        level_operators[level].compute_diagonal();
      }
    std::vector<AffineConstraints<float>> transfer_constraints(n_levels);
    for (unsigned int level = 0; level < n_levels; ++level)
      transfer_constraints[level].copy_from(level_constraints[level]);
    for (unsigned int level = 1; level < n_levels; ++level)
      transfers[level].reinit_geometric_transfer(
        level + 1 < n_levels ? *level_dofs[level] : dof, *level_dofs[level - 1],
        transfer_constraints[level], transfer_constraints[level - 1]);
    MGTransferGlobalCoarsening<dim, LevelVector> transfer(
      transfers, [&](const unsigned int level, LevelVector &v) {
        level_operators[level].initialize_dof_vector(v);
      });

    mg::SmootherRelaxation<Smoother, LevelVector> smoother;
    smoother.initialize(level_operators, chebyshev_data(level_operators));
    MeanFreeCoarseSolver<LevelOperator, LevelVector> coarse(level_operators[0]);
    mg::Matrix<LevelVector> level_matrix(level_operators);
    Multigrid<LevelVector>  mg(level_matrix, coarse, transfer, smoother, smoother);
    PreconditionMG<dim, LevelVector, MGTransferGlobalCoarsening<dim, LevelVector>>
      preconditioner(dof, mg, transfer);
    const double setup = timer.wall_time();

    VectorType x;
    active_data->initialize_dof_vector(x);
    const auto [iterations, converged] = solve_repeatedly(A, x, gmg_rhs, preconditioner);
    const double solve        = (timer.wall_time() - setup) / n_solves;
    const double memory_after = heap_mb();

    constraints.distribute(x);
    VectorType ones(x);
    ones = 1.;
    x.add(-(x * ones) / static_cast<double>(dof.n_dofs()), ones);
    x -= gmg_solution;

    std::size_t operator_memory = active_data->memory_consumption();
    for (unsigned int level = 0; level < n_levels; ++level)
      operator_memory += level_operators[level].memory_consumption();
    pcout << std::fixed << std::setprecision(3) << "gmg global (Chebyshev " << smoothing_degree
          << "): set-up " << setup << " s, solve " << solve << " s, " << iterations
          << (converged ? "" : " (not converged)") << " iterations, operators "
          << Utilities::MPI::sum(operator_memory, communicator) / 1e6 << " MB, heap growth "
          << Utilities::MPI::sum(memory_after - memory_before, communicator) << " MB, "
          << n_levels << " levels, "
          << Utilities::MPI::sum(coarse_periodic_faces, communicator)
          << " periodic faces on the coarsest" << std::endl;
    pcout << std::scientific << std::setprecision(2)
          << "max |p_global - p_local| (both mean-free): " << x.linfty_norm() << std::endl;
  }

  template <int dim>
  void Benchmark<dim>::run()
  {
    make_mesh();
    run_gmg();
    run_gmg_global();
    run_amg();
  }
} // namespace

int main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  if (argc < 3)
    {
      std::cerr << "usage: pressure_poisson DIM MAX_LEVEL [N_SOLVES]" << std::endl;
      return 1;
    }
  const unsigned int dim       = std::stoi(argv[1]);
  const unsigned int max_level = std::stoi(argv[2]);
  const unsigned int n_solves  = argc > 3 ? std::stoi(argv[3]) : 3;
  if (dim == 2)
    Benchmark<2>(max_level, n_solves).run();
  else
    Benchmark<3>(max_level, n_solves).run();
  return 0;
}
