#pragma once

#include <deal.II/base/point.h>
#include <deal.II/base/tensor.h>
#include <deal.II/distributed/tria.h>

#include <suspension/core/parameters.h>
#include <suspension/fluid/momentum_source.h>
#include <suspension/solid/solid_phase.h>

#include <array>
#include <vector>

namespace Suspension::Solid
{
  /// What the last update() saw; gaps are surface to surface (phi = 1/2).
  struct ContactDiagnostics
  {
    unsigned int n_particles   = 0; // connected solid regions
    unsigned int active_cells  = 0; // fluid cells carrying a force
    double       closest_gap   = 0.; // between two particles (< 0: none seen)
    double       closest_wall  = 0.; // particle to wall (< 0: no wall)
    double       largest_force = 0.; // |f|, force per unit volume
    double       smallest_cell = 0.; // dx of the interface cells
  };

  /**
   * The short-range repulsion that keeps particles from merging (Rosti et
   * al., after Clift et al.): in a fluid cell between two particles, or
   * between a particle and a no-slip wall, whose gap d is within
   * [dx, Range dx], the force per unit volume
   *
   *   f = mu V r (a1 / d + a2 / d^2) n,
   *
   * n the unit vector from the cell centre towards the nearest of the two
   * surfaces, is added to the momentum equation. A gap below dx is taken
   * as dx (the paper switches the force off there; holding it is what
   * keeps two particles apart once they are that close).
   *
   * How particles are told apart (update()):
   *  1. labels: cells with mean phi >= 1/2 are solid cores; cores joined
   *     through faces (periodic and hanging ones too) form one particle.
   *     A parallel union-find: each rank unites its cells with their
   *     neighbours, ghosts carry the smallest label, until no label
   *     changes on any rank (eight bytes per cell).
   *  2. surfaces: the phi = 1/2 crossings on the edges of every cell
   *     (phi at the vertices of the DG field, linear along the edge), each
   *     labelled with its cell's core or the nearest neighbouring core.
   *     This is the zero level set of phi - 1/2, sampled at edge spacing.
   *  3. distances: all ranks gather the surface points into a bucket grid
   *     of Range dx; a fluid cell's nearest point of each label within
   *     Range dx gives distances and normals; periodic directions use the
   *     nearest image. dx is the smallest cell carrying a surface point
   *     (the interface cells, all on the finest level when adaptive).
   * Cost: O(surface points) memory on every rank (a few thousand in 2D,
   * 10^6 and more for the paper's 3D box, where a neighbour-only exchange
   * would be needed), O(fluid cells near interfaces) queries per step.
   */
  template <int dim>
  class ContactForce : public Fluid::MomentumSource<dim>
  {
  public:
    /// walls: (direction, coordinate) of each no-slip plane;
    /// periods: length of each periodic direction, 0 if not periodic;
    /// the corners of the domain (Scene::lower_corner(), upper_corner()).
    ContactForce(const Parameters::All                       &parameters,
                 const std::vector<std::pair<unsigned int, double>> &walls,
                 const std::array<double, dim>                &periods,
                 const Point<dim>                             &lower_corner,
                 const Point<dim>                             &upper_corner);

    /// Labels the particles of the current phi, finds their surfaces and
    /// the force in every locally owned fluid cell. Call after phi moved
    /// and after every mesh change, before the fluid step.
    ContactDiagnostics update(const SolidPhase<dim> &solid);

    void add(const typename Triangulation<dim>::active_cell_iterator &cell,
             const std::vector<Point<dim>> &points,
             const std::vector<Point<dim>> &unit_points,
             double                          time,
             std::vector<Tensor<1, dim>>          &force,
             std::vector<SymmetricTensor<2, dim>> &stress) const override;

    bool has_stress() const override
    {
      return false;
    }

    /// Particle label of each active cell (cores only; others invalid).
    const std::vector<types::global_cell_index> &labels() const
    {
      return cell_label;
    }

  private:
    struct SurfacePoint
    {
      Point<dim>               location;
      types::global_cell_index label;

      template <class Archive>
      void serialize(Archive &archive, const unsigned int)
      {
        archive &location &label;
      }
    };

    void label_particles(const parallel::distributed::Triangulation<dim> &tria,
                         const std::vector<double>                       &cell_mean);
    /// The local crossings; `dx` becomes the smallest cell holding one.
    std::vector<SurfacePoint> find_surface_points(const SolidPhase<dim> &solid,
                                                  double                &dx) const;
    Tensor<1, dim> nearest_image(const Point<dim> &from, const Point<dim> &to) const;
    double         magnitude(double gap, double dx) const;

    const Parameters::Solid::Contact               &settings;
    const double                                    scale; // mu V r
    const std::vector<std::pair<unsigned int, double>> walls;
    const std::array<double, dim>                   periods;
    const Point<dim>                                lower_corner, upper_corner;
    std::vector<types::global_cell_index>           cell_label;
    std::vector<Tensor<1, dim>>                     cell_force;
  };
} // namespace Suspension::Solid
