#pragma once

#include <deal.II/base/geometry_info.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/tensor.h>
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/la_parallel_vector.h>
#include <deal.II/matrix_free/matrix_free.h>

#include <array>
#include <vector>

namespace Suspension::Solid
{
  using namespace dealii;
  using VectorType = LinearAlgebra::distributed::Vector<double>;

  /**
   * Smallest eigenvalue of a symmetric tensor, robust for nearly isotropic
   * ones (B close to I). deal.II's eigenvalues() of a 2x2 tensor takes the
   * square root of tr^2 - 4 det, which round-off makes negative (NaN) when
   * the eigenvalues nearly coincide and the off-diagonal entry is tiny but
   * not zero; the half-difference form below has no such cancellation. In
   * 3D the Jacobi eigensolver is used.
   */
  template <int dim>
  double smallest_eigenvalue(const SymmetricTensor<2, dim> &t)
  {
    if constexpr (dim == 2)
      {
        const double mean = 0.5 * (t[0][0] + t[1][1]);
        const double half = 0.5 * (t[0][0] - t[1][1]);
        return mean - std::sqrt(half * half + t[0][1] * t[0][1]);
      }
    else
      return eigenvectors(t, SymmetricTensorEigenvectorMethod::jacobi)[dim - 1].first;
  }

  /**
   * Whether every eigenvalue of t certainly exceeds `floor`: Sylvester's
   * criterion (all leading principal minors positive) for t - f I, with f
   * raised by a round-off margin, so that a true answer agrees with
   * smallest_eigenvalue(t) > floor. A few products instead of an
   * eigensolver: the B limiter asks this at every node and quadrature point
   * of every solid cell and stage, where nearly all answers are true (in 3D
   * the Jacobi eigensolver took a third of a step's time).
   */
  template <int dim>
  bool eigenvalues_exceed(const SymmetricTensor<2, dim> &t, const double floor)
  {
    const SymmetricTensor<2, dim> a =
      t - (floor + 1e-12 * std::abs(trace(t))) * unit_symmetric_tensor<dim>();
    if (!(a[0][0] > 0.) || !(a[0][0] * a[1][1] - a[0][1] * a[0][1] > 0.))
      return false;
    return dim == 2 || determinant(a) > 0.;
  }

  /// Smallest and largest values seen by the limiter, and its work.
  struct LimiterReport
  {
    unsigned int limited_cells      = 0; // cells scaled towards their mean
    unsigned int out_of_bound_means = 0; // cell means outside [0, 1]
    double       min_phi = 1., max_phi = 0.;
  };

  /**
   * The discontinuous Galerkin operator of the solid fields, matrix-free
   * (MatrixFree handles interior, periodic and hanging-node faces alike):
   *
   *   d phi / dt = - div(u phi),
   *   d B / dt   = - div(u B) + (div u) B + (grad u) B + B (grad u)^T,
   *
   * i.e. the conservative form of the transport of phi and the
   * upper-convected derivative of B written so that, for the continuous
   * (not pointwise divergence-free) velocity, it still equals
   * dB/dt + u.grad B - (grad u) B - B (grad u)^T = 0. Upwind fluxes; on
   * inflow boundaries fluid enters (phi = 0, B = I). apply() returns
   * M^{-1} R(y): the right-hand side of the semi-discrete system, with the
   * exact cell-wise inverse mass matrix of FE_DGQ.
   *
   * Component 0 of the solid DoFHandler is phi, components 1..n_B the
   * independent entries of B in SymmetricTensor's unrolled order.
   */
  template <int dim>
  class TransportOperator
  {
  public:
    static constexpr unsigned int n_B = dim * (dim + 1) / 2;

    void reinit(const DoFHandler<dim>           &dof_solid,
                const DoFHandler<dim>           &dof_velocity,
                const AffineConstraints<double> &velocity_constraints,
                bool                             with_B);

    void initialize_solid_vector(VectorType &v) const;
    void initialize_velocity_vector(VectorType &v) const;

    /// dst = M^{-1} R(src; u), u a ghosted velocity vector. With
    /// boundary_flux, adds this rank's share of the flux of phi out of the
    /// domain, int_{boundary} (u.n) phi^ ds (upwind phi^: the inside value
    /// where u.n > 0, the inflow's phi = 0 where u.n < 0), computed with the
    /// face quadrature of R itself: d/dt int phi = -(that flux) holds for
    /// the discrete operator to round-off, since the test functions of a
    /// cell sum to one.
    void apply(const VectorType &src,
               VectorType       &dst,
               const VectorType &velocity,
               double           *boundary_flux = nullptr) const;

    /// Zhang-Shu scaling of phi towards each cell mean so that 0 <= phi <= 1
    /// at the nodes and quadrature points; means are left unchanged.
    LimiterReport limit(VectorType &solution, bool scale) const;

    /// Scaling of B towards its cell mean so that its smallest eigenvalue
    /// stays positive at the nodes and quadrature points (the smallest
    /// eigenvalue of an affine matrix function is concave, so one scaling
    /// factor per cell suffices); cell means are unchanged. Returns the
    /// number of cells scaled.
    unsigned int limit_B(VectorType &solution) const;

    const MatrixFree<dim, double> &get_matrix_free() const { return matrix_free; }

    /// This rank's share of the jumps of phi across the faces between cells
    /// (hanging faces included, periodic ones not): the sum of
    /// int_face |phi^+ - phi^-| ds over the faces that have a cell on
    /// either side with phi > `touches` at a node of the DG polynomial,
    /// with k + 1 Gauss points per direction. MatrixFree gives each face to
    /// one rank, so the sum over the ranks counts every face once. The
    /// face part of the total variation of phi, for the interface width.
    double face_jumps(const VectorType &solution, double touches) const;

    /// Bytes held on this rank: the MatrixFree data (mapping, DoF
    /// indices), the per-cell geometry and profiles, the scratch vectors.
    std::size_t memory_consumption() const;
    /// Of these, the MatrixFree data alone.
    std::size_t matrix_free_memory() const { return matrix_free.memory_consumption(); }

    /// Where B is transported: B = I wherever a cell and its face
    /// neighbours hold no solid (every node of phi at most 1e-8), since
    /// reset_B_in_fluid() would put it back to I there anyway. Marks the
    /// cells that hold solid (phi > 1e-8 at a node) and their face
    /// neighbours, the same on every rank (ghost cells take their owner's
    /// mark); apply() and limit_B() then skip B elsewhere, and a face to an
    /// unmarked cell sees B = I outside, as an inflow boundary does. Until
    /// it is called, every cell is marked.
    void mark_solid_cells(const VectorType &solution);

    /// The largest |u| (u0 and u1: ghosted velocity vectors, at the
    /// quadrature points) over the cells the interface crosses (nodal
    /// values of phi above `epsilon` and below 1 - `epsilon`) and their
    /// face neighbours: how fast the interface moves, which sets how often
    /// the mesh that follows it must adapt.
    double interface_speed(const VectorType &solution, const VectorType &u0,
                           const VectorType &u1, double epsilon) const;

    /// Interface compression: phi also moves with the flux
    /// c |u| phi (1 - phi) grad phi / |grad phi| (towards the solid, only
    /// where 0 < phi < 1), with a Lax-Friedrichs face flux; 0: off.
    /// With it a diffusion eps c |u| grad phi, eps = thickness times the
    /// cell size, so that the profile settles at phi = 1/(1 + exp(-d/eps))
    /// (d the distance from the phi = 1/2 surface; Olsson & Kreiss 2005)
    /// instead of steepening into a step that snaps to the cells.
    void set_compression(const double c, const double thickness_)
    {
      compression = c;
      thickness   = thickness_;
    }

    /// THINC reconstruction of phi in the cells the interface cuts
    /// (doc/method.md, "A sharp interface inside the cell"): sharpness beta
    /// of the profile 1/2 (1 + tanh(beta (n.xi + d))) in the unit cell; 0:
    /// off (phi is the DG polynomial everywhere). curved: the profile
    /// follows the curvature of the normals; smoothed_normal (with curved):
    /// n is the mean of the cell's vertex normals where they agree.
    void set_reconstruction(const double beta, const bool curved = false,
                            const bool smoothed_normal = false)
    {
      thinc_beta     = beta;
      thinc_curved   = curved;
      thinc_smoothed = curved && smoothed_normal;
    }

    /// With the THINC reconstruction: phi in each interface cell replaced
    /// by the projection of its profile onto the cell's polynomials, cell
    /// means unchanged, so that what is measured and weighted (the stress
    /// weight, D, the area) is the sharp profile the transport carries.
    /// Returns whether it did (only with the reconstruction on).
    bool project_to_profiles(VectorType &solution) const;

    /// The THINC profiles of the current solution, for profile():
    /// what project_to_profiles() computes, without changing the solution.
    /// Nothing without the reconstruction.
    void update_profiles(const VectorType &solution) const;

    /// The profile of one cell as a function of x: 1/2 (1 + tanh(slope.x +
    /// offset)), or none (the DG polynomial is used).
    struct Reconstruction
    {
      Tensor<1, dim> slope;
      double         offset = 0.;
      /// how much of the profile the transport sees, 1 - weight of the DG
      /// polynomial: 0 where the cell mean is within 1e-6 of 0 or 1, 1
      /// beyond 2e-6, a smooth step between (a switch would turn round-off
      /// into differences of 1e-7 between partitions)
      double         weight = 0.;
      /// beta c of the curved profile (0: a plane): the argument gains
      /// beta c |s_t|^2, s_t the part of s = (x - centre)/h normal to the
      /// profile's normal (slope / |slope| in unit-cell coordinates)
      double         curvature = 0.;
      /// the cell's box: a point of a periodic face, given in the
      /// coordinates of the other side, is moved onto this cell's face
      Point<dim> lower, upper;

      /// phi of this profile at x: p + w (H - p), p = `dg_value`
      double value(const Point<dim> &x, double dg_value) const;
      /// the argument a of H = 1/2 (1 + tanh a) at x
      double argument(const Point<dim> &x) const;
    };

    /// The profile of the locally owned cell with this active_cell_index(),
    /// or nullptr where it has none (the cell is not cut, or THINC is off):
    /// Reconstruction::value() is phi as the transport carries it there.
    const Reconstruction *profile(unsigned int active_cell_index) const;

    /// The THINC profile of a cell of phi mean `mean` and reference-cell
    /// gradient integral `gradient` (the cell [x0, x0 + h], axis-parallel),
    /// with its mean equal to `mean` by the reference quadrature.
    /// `divergence`: div n of the unit normal field (physical units), whose
    /// level sets the curved profile follows (0: a plane).
    Reconstruction reconstruct(double mean, const Tensor<1, dim> &gradient,
                               const Point<dim> &x0, const Tensor<1, dim> &h,
                               double divergence = 0.) const;

  private:
    using Lanes = std::array<Reconstruction, VectorizedArray<double>::size()>;

    /// 1 for the cells (owned and ghost, by active_cell_index()) whose
    /// lowest and highest nodal values of phi satisfy holds_at(lowest,
    /// highest), and for their face neighbours; the same on every rank
    template <typename Holds>
    std::vector<unsigned char> cells_near(const VectorType &solution, const Holds &holds_at) const;

    /// fills `reconstruction` for the cells (and ghost cells) from src
    void compute_reconstruction(const VectorType &src) const;

    MatrixFree<dim, double> matrix_free;
    bool                    with_B = false;
    double                  compression = 0., thickness = 0.;
    std::vector<VectorizedArray<double>> cell_size, face_size;

    double thinc_beta   = 0.;
    bool   thinc_curved = false;
    bool   thinc_smoothed = false;
    /// the cell mean as a linear functional of the (lexicographic) phi
    /// DoFs of a cell
    std::vector<double> mean_weights;
    /// lower corner, extents, volume and vertices of the cells and ghost
    /// cells, by lane
    std::vector<Point<dim>>     cell_corner;
    std::vector<Tensor<1, dim>> cell_extent;
    std::vector<double>         cell_volume;
    /// quadrature of the unit cell that sets the profile's offset
    std::vector<Point<dim>> profile_points;
    std::vector<double>     profile_weights;
    std::vector<unsigned int>           cell_vertices;
    /// The quadrature points of a cell batch (quadrature 0 or 1) and of
    /// the interior side of a face batch (quadrature 0), where the THINC
    /// profile is evaluated: the box of the cell maps the unit cell's
    /// points, so that MatrixFree need not store them (in 3D with DG 2,
    /// 91 points per cell and 25 per face, about 0.4 of its memory).
    Point<dim, VectorizedArray<double>> cell_point(unsigned int cell, unsigned int quadrature,
                                                   unsigned int q) const;
    Point<dim, VectorizedArray<double>> face_point(unsigned int face, unsigned int q) const;
    /// the unit cell's points of quadratures 0 and 1, and of quadrature 0
    /// on each face
    std::array<std::vector<Point<dim>>, 2>                          unit_cell_points;
    std::array<std::vector<Point<dim>>, GeometryInfo<dim>::faces_per_cell> unit_face_points;
    /// global_active_cell_index() of the cells and ghost cells by lane
    std::vector<types::global_cell_index> lane_global_cell;
    /// What a cell's neighbours on other ranks need of it: its mean, its
    /// unit normal, its profile (weight, offset, slope, curvature), one
    /// value per active cell and vector, with the ghost cells of the
    /// triangulation (a few doubles per cell, where solid vectors with
    /// all the DoFs of phi and B took 1.5 kB per cell in 3D)
    static constexpr unsigned int             n_cell_values = 3 + dim;
    mutable std::array<VectorType, n_cell_values> cell_exchange;
    mutable std::vector<double>         vertex_mean, vertex_weight;
    mutable std::vector<double>         cell_mean;
    mutable AlignedVector<Lanes>        reconstruction;
    /// 1 in the lanes of cells where B is transported, 0 elsewhere; owned
    /// and ghost cell batches (mark_solid_cells)
    AlignedVector<VectorizedArray<double>> b_active;
    /// active_cell_index() of each lane of the owned and ghost cell batches
    std::vector<unsigned int> lane_cell_index;
    /// batch * lanes + lane of each locally owned active cell (by
    /// active_cell_index(); invalid for the others)
    std::vector<unsigned int> owned_cell_lane;
    /// 1 in the lanes of inner face batches that are periodic faces
    std::vector<unsigned char> periodic_face_lane;
    /// volume-weighted sums of the cells' unit normals at the vertices,
    /// for div n
    mutable std::vector<Tensor<1, dim>> vertex_normal;
    /// the ghost layer of the mesh (all cells that share a vertex with an
    /// owned one): vertices, volumes, global active cell indices
    std::vector<unsigned int>             ghost_layer_vertices;
    std::vector<double>                   ghost_layer_volume;
    std::vector<types::global_cell_index> ghost_layer_cells;
  };
} // namespace Suspension::Solid
