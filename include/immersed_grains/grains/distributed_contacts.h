#ifndef immersed_grains_grains_distributed_contacts_h
#define immersed_grains_grains_distributed_contacts_h

#include <deal.II/base/bounding_box.h>
#include <deal.II/base/mpi.h>

#include <immersed_grains/contact/contact_solver.h>
#include <immersed_grains/contact/neighbour_list.h>
#include <immersed_grains/contact/walls.h>
#include <immersed_grains/mesh/geometry.h>

#include <cstdint>
#include <map>
#include <vector>

namespace ImmersedGrains
{
  /** The normal force of one contact of the last step. */
  struct ContactForce
  {
    std::uint64_t grain;   // id of the first grain
    std::uint64_t partner; // id of the second grain, or the wall number
    bool          wall;    // partner is a wall
    double        force;   // normal impulse / dt [N] (2D: per unit depth)
  };

  /**
   * One contact step (neighbour search, walls, non-smooth contact solver)
   * for the grains a rank owns, with the exchange that makes the converged
   * answer independent of the number of ranks (doc/contacts.md, section
   * "Distributed memory"):
   *
   *  - ghosts: each rank receives copies of the grains owned elsewhere that
   *    lie within reach (largest radius plus alert distance) of its own
   *    cells: of the cells themselves where the reach is shorter than every
   *    cell (PartitionHalo), else of the box around them;
   *  - each contact is solved by exactly one rank, the lowest rank owning
   *    one of its grains;
   *  - a grain whose contacts are solved on k ranks enters each of those
   *    copies' Delassus operators with the mass m/k (mass splitting,
   *    Visseq et al. 2012); after every few Gauss-Seidel sweeps these
   *    copies are glued by averaging their velocities, which gives exactly
   *    v + sum(impulses)/m: at convergence every contact law and the true
   *    equation of motion hold, as in serial. A copy in none of its rank's
   *    contacts takes no share of the mass and no part in the glue (on
   *    two ranks every copy of rank 0's grains on rank 1), so a grain with
   *    all its contacts on one rank is solved there as in serial;
   *  - convergence is decided on the maxima over all ranks, so all ranks
   *    sweep the same number of times; ranks exchange after every few
   *    local sweeps (sweeps_per_exchange), not after each;
   *  - with Contacts/Solver = apgd the copies are glued after every
   *    iteration (its gradient needs the global iterate's velocities) and
   *    the step-size, restart and convergence measures are reduced, so all
   *    ranks iterate as the serial solver does.
   * On one rank this is the serial solver without any copying.
   */
  template <int dim>
  class DistributedContacts
  {
  public:
    /**
     * For each of this rank's cells, the other ranks' cells near it, as
     * compressed rows by active cell index: cell c's are
     * cells[offsets[c]] to cells[offsets[c + 1] - 1], each the owner rank
     * and the cell's bounding box, moved by the period where it lies
     * across a periodic face. They are this rank's ghost cells within
     * reach_limit of the cell: a grain whose radius plus contact reach is
     * below reach_limit (the shortest cell edge) can touch another rank's
     * grain only in one of them, since every cell that close to one of
     * this rank's cells shares a vertex with it, and all such cells are
     * ghosts.
     */
    struct PartitionHalo
    {
      std::vector<unsigned int>                                      offsets;
      std::vector<std::pair<unsigned int, dealii::BoundingBox<dim>>> cells;
      double reach_limit = 0;
    };

    DistributedContacts(const Geometry<dim>              &geometry,
                        const Contact::ContactParameters &parameters,
                        MPI_Comm                          comm);

    /**
     * The bounding boxes of each rank's locally owned cells, and the other
     * ranks' cells near each of this rank's; needed again after the mesh or
     * its partition changes.
     */
    void
    set_partition(
      const std::vector<std::vector<dealii::BoundingBox<dim>>> &boxes,
      PartitionHalo                                             halo);

    /**
     * Gauss-Seidel visits the contacts in increasing x . @p direction on
     * forward sweeps, decreasing on backward ones (with the upward
     * direction: along a pile's load paths); zero: in rounds by grain
     * index (Contact::GrainArrays::sweep_key).
     */
    void
    set_sweep_direction(const dealii::Tensor<1, dim> &direction);

    /**
     * Resolves the contacts of the owned grains at @p positions: grains go
     * in with free velocities and come out with end-of-step velocities.
     * The result holds global numbers (sums or maxima over ranks).
     * @p cells holds each grain's active cell index, for the halo; empty:
     * ghosts are found from the ranks' boxes alone.
     */
    Contact::SolverResult
    solve(const std::vector<dealii::Point<dim>> &positions,
          Contact::GrainArrays<dim>             &grains,
          double                                 time_step,
          double                                 alert_distance,
          const std::vector<unsigned int>       &cells = {});

    /** Largest normal contact force of the last step, over all ranks. */
    double
    max_contact_force() const;

    /** The contact solver's warm-start memory (ContactSolver). */
    Contact::ContactSolver<dim> &
    contact_solver()
    {
      return solver;
    }

    /** The grain-grain neighbour search of this rank. */
    const Contact::NeighbourList<dim> &
    neighbour_list() const
    {
      return neighbours;
    }

    /** The contacts this rank solved in the last step, with their forces. */
    std::vector<ContactForce>
    contact_forces() const;

    /**
     * Adds the impulse that the last step's contacts solved on this rank
     * gave each boundary (the walls of Geometry::add_walls()) to
     * @p impulses, by boundary id: what the grains pushed that boundary
     * with, normal and tangential parts.
     */
    void
    add_boundary_impulses(std::map<dealii::types::boundary_id,
                                   dealii::Tensor<1, dim>> &impulses) const;

  private:
    MPI_Comm             comm;
    const unsigned int   my_rank;
    const unsigned int   n_ranks;
    const bool           friction;
    const Geometry<dim> &geometry;

    // The grain-grain search, kept over sub-steps while the grains stay
    // within its skin.
    Contact::NeighbourList<dim> neighbours;
    Contact::Walls<dim>         walls;
    // The boundary id of each wall, by wall number.
    std::vector<dealii::types::boundary_id> wall_boundary_ids;
    Contact::ContactSolver<dim>             solver;

    std::vector<std::vector<dealii::BoundingBox<dim>>> rank_boxes;
    PartitionHalo                                      halo;
    dealii::Tensor<1, dim>                             sweep_direction;

    /// Local Gauss-Seidel sweeps between two glue exchanges (MPI only).
    static constexpr unsigned int sweeps_per_exchange = 4;

    // This step's work: owned grains then ghosts.
    unsigned int                                      n_owned   = 0;
    double                                            time_step = 0;
    std::vector<dealii::Point<dim>>                   all_positions;
    std::vector<unsigned int>                         ghost_owner;
    std::map<unsigned int, std::vector<unsigned int>> send_lists; // owned
    std::map<unsigned int, std::vector<unsigned int>> recv_lists; // ghosts
    // Owned grains: the factor on the inverse mass of this rank's copy
    // (the number of copies in contacts where this copy is in one, else 1),
    // and the number of copies the glue averages.
    std::vector<unsigned int> mass_split, copies;
    // Per owned grain, whether this rank's copy is in one of its contacts.
    std::vector<bool> owner_in_contact;
    // The copies that a glue exchanges: per owner rank, the ghosts here in
    // one of this rank's contacts (ghost side); per rank, the owned grains
    // whose copy there is in one of its contacts (owner side), in the same
    // order.
    std::map<unsigned int, std::vector<unsigned int>> glue_ghosts, glue_owned;
    // The owned grains with copies in contacts elsewhere, ascending, and
    // each one's place among them (valid for those only): a glue touches
    // these alone.
    std::vector<unsigned int>              shared_owned, shared_slot;
    std::vector<double>                    glue_sum;
    std::vector<Contact::GrainPair<dim>>   pairs;
    std::vector<Contact::WallContact<dim>> wall_contacts;
    std::vector<std::uint64_t>             ids;
    std::vector<double>                    send_buffer, recv_buffer;

    double
    distance_to_rank(const dealii::Point<dim> &x, unsigned int rank) const;

    void
    exchange_ghosts(Contact::GrainArrays<dim>       &grains,
                    double                           reach,
                    const std::vector<unsigned int> &cells);

    void
    drop_ghosts(Contact::GrainArrays<dim> &grains) const;

    void
    keep_own_contacts();

    /**
     * Splits the mass of each grain over its copies that are in contacts
     * (after keep_own_contacts()) and makes the glue's lists.
     */
    void
    split_masses(Contact::GrainArrays<dim> &grains);

    /** Averages the velocities of every grain's copies (mass splitting). */
    void
    glue_copies();
  };
} // namespace ImmersedGrains

#endif
