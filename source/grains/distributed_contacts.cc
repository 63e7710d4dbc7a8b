#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include <immersed_grains/grains/distributed_contacts.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <vector>

namespace ImmersedGrains
{
  namespace
  {
    constexpr int glue_to_owner_tag   = 7411;
    constexpr int glue_from_owner_tag = 7412;
    constexpr int flags_tag           = 7413;
    constexpr int split_tag           = 7414;

    /**
     * Sends @p outgoing[q] to each rank q and receives from each rank of
     * @p incoming_sizes as many numbers as it names: both sides know whom
     * they hear from and how much (the ghosts' lists, made in
     * exchange_ghosts()). deal.II's some_to_some() first finds the senders
     * with a collective and takes a collective mutex: two collectives per
     * call, and a contact solve made two such calls besides the one whose
     * senders are not known.
     */
    std::map<unsigned int, std::vector<unsigned int>>
    exchange_known(
      const std::map<unsigned int, std::vector<unsigned int>> &outgoing,
      const std::map<unsigned int, std::size_t>               &incoming_sizes,
      const int                                                tag,
      const MPI_Comm                                           comm)
    {
      std::map<unsigned int, std::vector<unsigned int>> incoming;
      std::vector<MPI_Request>                          requests;
      requests.reserve(outgoing.size() + incoming_sizes.size());
      for (const auto &[q, n] : incoming_sizes)
      {
        auto &buffer = incoming[q];
        buffer.resize(n);
        requests.emplace_back();
        const int error = MPI_Irecv(
          buffer.data(), n, MPI_UNSIGNED, q, tag, comm, &requests.back());
        AssertThrowMPI(error);
      }
      for (const auto &[q, values] : outgoing)
      {
        requests.emplace_back();
        const int error = MPI_Isend(values.data(),
                                    values.size(),
                                    MPI_UNSIGNED,
                                    q,
                                    tag,
                                    comm,
                                    &requests.back());
        AssertThrowMPI(error);
      }
      const int error =
        MPI_Waitall(requests.size(), requests.data(), MPI_STATUSES_IGNORE);
      AssertThrowMPI(error);
      return incoming;
    }

    template <int dim>
    std::array<bool, dim>
    periodic_axes(const Geometry<dim> &geometry)
    {
      std::array<bool, dim> p;
      for (unsigned int d = 0; d < dim; ++d)
        p[d] = geometry.is_periodic(d);
      return p;
    }

    /** Distance from @p y to the interval of @p box along axis @p d. */
    template <int dim>
    double
    axis_gap(const dealii::BoundingBox<dim> &box,
             const unsigned int              d,
             const double                    y)
    {
      return std::max({box.get_boundary_points().first[d] - y,
                       y - box.get_boundary_points().second[d],
                       0.});
    }

    template <int dim>
    double
    distance_to_box(const dealii::Point<dim>       &x,
                    const dealii::BoundingBox<dim> &box)
    {
      double d2 = 0;
      for (unsigned int d = 0; d < dim; ++d)
        d2 += dealii::Utilities::fixed_power<2>(axis_gap(box, d, x[d]));
      return std::sqrt(d2);
    }
  } // namespace


  template <int dim>
  DistributedContacts<dim>::DistributedContacts(
    const Geometry<dim>              &geometry,
    const Contact::ContactParameters &parameters,
    MPI_Comm                          comm)
      : comm(comm)
      , my_rank(dealii::Utilities::MPI::this_mpi_process(comm))
      , n_ranks(dealii::Utilities::MPI::n_mpi_processes(comm))
      , friction(parameters.friction > 0)
      , geometry(geometry)
      , neighbours(geometry.lower_corner,
                   geometry.upper_corner,
                   periodic_axes(geometry))
      , solver(parameters)
  {
    wall_boundary_ids = geometry.add_walls(walls);
  }


  template <int dim>
  void
  DistributedContacts<dim>::set_partition(
    const std::vector<std::vector<dealii::BoundingBox<dim>>> &boxes,
    PartitionHalo                                             new_halo)
  {
    rank_boxes = boxes;
    halo       = std::move(new_halo);
  }


  template <int dim>
  void
  DistributedContacts<dim>::set_sweep_direction(
    const dealii::Tensor<1, dim> &direction)
  {
    sweep_direction = direction;
  }


  template <int dim>
  double
  DistributedContacts<dim>::distance_to_rank(const dealii::Point<dim> &x,
                                             const unsigned int rank) const
  {
    // Per axis the distance to the box's interval, on a periodic axis to
    // the nearest image of it.
    double best = std::numeric_limits<double>::max();
    for (const auto &box : rank_boxes[rank])
    {
      double d2 = 0;
      for (unsigned int d = 0; d < dim; ++d)
      {
        double g = axis_gap(box, d, x[d]);
        if (geometry.is_periodic(d))
        {
          const double L = geometry.upper_corner[d] - geometry.lower_corner[d];
          g              = std::min(
            {g, axis_gap(box, d, x[d] - L), axis_gap(box, d, x[d] + L)});
        }
        d2 += g * g;
      }
      best = std::min(best, std::sqrt(d2));
    }
    return best;
  }


  template <int dim>
  void
  DistributedContacts<dim>::exchange_ghosts(
    Contact::GrainArrays<dim>       &g,
    const double                     reach,
    const std::vector<unsigned int> &cells)
  {
    constexpr unsigned int spin_dim = (dim == 2 ? 1 : 3);
    // Decided together: a rank without grains has empty arrays but must
    // read the same message layout.
    const bool start =
      dealii::Utilities::MPI::max(int(!g.start_velocity.empty()), comm) > 0;
    const unsigned int width =
      1 + 2 * dim + (start ? dim : 0) + 1 + (friction ? 1 + spin_dim : 0) + 1;

    send_lists.clear();
    recv_lists.clear();
    const bool by_cells = cells.size() == n_owned && halo.offsets.size() > 1;
    for (unsigned int i = 0; i < n_owned; ++i)
    {
      const double range = g.radius[i] + reach;
      if (by_cells && range < halo.reach_limit)
      {
        // Only the other ranks' cells near this grain's: most grains have
        // none. (One box per rank around a partition of an adapted mesh
        // covers most of the domain, and with it every grain: each was
        // then shared and mass splitting slowed every contact.)
        const unsigned int c = cells[i];
        Assert(c + 1 < halo.offsets.size(), dealii::ExcInternalError());
        for (unsigned int e = halo.offsets[c]; e < halo.offsets[c + 1]; ++e)
        {
          const auto &[q, box] = halo.cells[e];
          if (distance_to_box(all_positions[i], box) < range)
          {
            auto &list = send_lists[q];
            if (list.empty() || list.back() != i)
              list.push_back(i);
          }
        }
        continue;
      }
      for (unsigned int q = 0; q < n_ranks; ++q)
        if (q != my_rank && distance_to_rank(all_positions[i], q) < range)
          send_lists[q].push_back(i);
    }

    std::map<unsigned int, std::vector<double>> out;
    for (const auto &[q, list] : send_lists)
    {
      auto &buffer = out[q];
      buffer.reserve(list.size() * width);
      for (const unsigned int i : list)
      {
        buffer.push_back(static_cast<double>(ids[i]));
        for (unsigned int d = 0; d < dim; ++d)
          buffer.push_back(all_positions[i][d]);
        for (unsigned int d = 0; d < dim; ++d)
          buffer.push_back(g.velocity[i][d]);
        if (start)
          for (unsigned int d = 0; d < dim; ++d)
            buffer.push_back(g.start_velocity[i][d]);
        buffer.push_back(g.inverse_mass[i]);
        if (friction)
        {
          buffer.push_back(g.inverse_inertia[i]);
          for (unsigned int d = 0; d < spin_dim; ++d)
            buffer.push_back(g.angular_velocity[i][d]);
        }
        buffer.push_back(g.radius[i]);
      }
    }
    const auto in = dealii::Utilities::MPI::some_to_some(comm, out);

    ghost_owner.clear();
    for (const auto &[q, buffer] : in)
    {
      auto &list = recv_lists[q];
      for (std::size_t p = 0; p < buffer.size(); p += width)
      {
        const double *b = buffer.data() + p;
        list.push_back(all_positions.size());
        ghost_owner.push_back(q);
        ids.push_back(static_cast<std::uint64_t>(b[0]));
        dealii::Point<dim>     x;
        dealii::Tensor<1, dim> v, v0;
        unsigned int           c = 1;
        for (unsigned int d = 0; d < dim; ++d)
          x[d] = b[c++];
        for (unsigned int d = 0; d < dim; ++d)
          v[d] = b[c++];
        all_positions.push_back(x);
        g.velocity.push_back(v);
        if (start)
        {
          for (unsigned int d = 0; d < dim; ++d)
            v0[d] = b[c++];
          g.start_velocity.push_back(v0);
        }
        g.inverse_mass.push_back(b[c++]);
        if (friction)
        {
          g.inverse_inertia.push_back(b[c++]);
          Contact::AngularVelocity<dim> w;
          for (unsigned int d = 0; d < spin_dim; ++d)
            w[d] = b[c++];
          g.angular_velocity.push_back(w);
        }
        g.radius.push_back(b[c++]);
      }
    }
  }


  template <int dim>
  void
  DistributedContacts<dim>::keep_own_contacts()
  {
    // A contact belongs to the lowest rank owning one of its grains; the
    // others see it only through the glued velocities.
    const auto owner = [&](const unsigned int i)
    { return i < n_owned ? my_rank : ghost_owner[i - n_owned]; };
    pairs.erase(std::remove_if(pairs.begin(),
                               pairs.end(),
                               [&](const Contact::GrainPair<dim> &p) {
                                 return std::min(owner(p.first),
                                                 owner(p.second)) != my_rank;
                               }),
                pairs.end());
    wall_contacts.erase(std::remove_if(wall_contacts.begin(),
                                       wall_contacts.end(),
                                       [&](const Contact::WallContact<dim> &c)
                                       { return c.grain >= n_owned; }),
                        wall_contacts.end());
  }


  template <int dim>
  void
  DistributedContacts<dim>::split_masses(Contact::GrainArrays<dim> &g)
  {
    std::vector<bool> in_contact(all_positions.size(), false);
    for (const auto &p : pairs)
    {
      in_contact[p.first]  = true;
      in_contact[p.second] = true;
    }
    for (const auto &c : wall_contacts)
      in_contact[c.grain] = true;

    // Each ghost tells its owner whether it is in one of this rank's
    // contacts: on two ranks no copy of rank 0's grains is, since rank 0
    // solves every contact they share with rank 1's.
    glue_ghosts.clear();
    std::map<unsigned int, std::vector<unsigned int>> flags_out;
    for (const auto &[q, list] : recv_lists)
    {
      auto &flags = flags_out[q];
      for (const unsigned int j : list)
      {
        flags.push_back(in_contact[j]);
        if (in_contact[j])
          glue_ghosts[q].push_back(j);
      }
    }
    // The flags come back from the ranks this one sent grains to, one a
    // grain.
    std::map<unsigned int, std::size_t> flags_sizes;
    for (const auto &[q, list] : send_lists)
      flags_sizes[q] = list.size();
    const auto flags_in =
      exchange_known(flags_out, flags_sizes, flags_tag, comm);

    owner_in_contact.assign(in_contact.begin(), in_contact.begin() + n_owned);
    copies.assign(n_owned, 0);
    for (unsigned int i = 0; i < n_owned; ++i)
      copies[i] = owner_in_contact[i];
    glue_owned.clear();
    for (const auto &[q, flags] : flags_in)
    {
      const auto &list = send_lists.at(q);
      AssertDimension(list.size(), flags.size());
      for (unsigned int m = 0; m < list.size(); ++m)
        if (flags[m])
        {
          glue_owned[q].push_back(list[m]);
          ++copies[list[m]];
        }
    }

    // Mass splitting over the copies in contacts: each carries m/k.
    std::map<unsigned int, std::vector<unsigned int>> split_out;
    for (const auto &[q, list] : glue_owned)
      for (const unsigned int i : list)
        split_out[q].push_back(copies[i]);
    // The owners of this rank's ghosts in contacts answer, one a ghost.
    std::map<unsigned int, std::size_t> split_sizes;
    for (const auto &[q, list] : glue_ghosts)
      split_sizes[q] = list.size();
    const auto split_in =
      exchange_known(split_out, split_sizes, split_tag, comm);
    for (const auto &[q, split] : split_in)
    {
      const auto &list = glue_ghosts.at(q);
      AssertDimension(list.size(), split.size());
      for (unsigned int m = 0; m < list.size(); ++m)
      {
        g.inverse_mass[list[m]] *= split[m];
        if (friction)
          g.inverse_inertia[list[m]] *= split[m];
      }
    }
    mass_split.assign(n_owned, 1);
    shared_owned.clear();
    shared_slot.resize(n_owned);
    for (unsigned int i = 0; i < n_owned; ++i)
    {
      if (owner_in_contact[i] && copies[i] > 1)
      {
        mass_split[i] = copies[i];
        g.inverse_mass[i] *= copies[i];
        if (friction)
          g.inverse_inertia[i] *= copies[i];
      }
      if (copies[i] > (owner_in_contact[i] ? 1u : 0u))
      {
        shared_slot[i] = shared_owned.size();
        shared_owned.push_back(i);
      }
    }
  }


  template <int dim>
  void
  DistributedContacts<dim>::glue_copies()
  {
    if (n_ranks == 1)
      return;
    constexpr unsigned int spin_dim = (dim == 2 ? 1 : 3);
    const unsigned int     width    = dim + (friction ? spin_dim : 0);
    const auto             pack     = [&](const unsigned int i, double *b)
    {
      const auto v = solver.get_velocity(i);
      for (unsigned int d = 0; d < dim; ++d)
        b[d] = v[d];
      if (friction)
      {
        const auto w = solver.get_angular_velocity(i);
        for (unsigned int d = 0; d < spin_dim; ++d)
          b[dim + d] = w[d];
      }
    };
    const auto unpack = [&](const unsigned int i, const double *b)
    {
      dealii::Tensor<1, dim> v;
      for (unsigned int d = 0; d < dim; ++d)
        v[d] = b[d];
      solver.set_velocity(i, v);
      if (friction)
      {
        Contact::AngularVelocity<dim> w;
        for (unsigned int d = 0; d < spin_dim; ++d)
          w[d] = b[dim + d];
        solver.set_angular_velocity(i, w);
      }
    };
    const auto exchange = [&](const auto &outgoing,
                              const auto &incoming,
                              const int   tag,
                              const auto &fill)
    {
      std::size_t n_out = 0, n_in = 0;
      for (const auto &[q, list] : outgoing)
        n_out += list.size() * width;
      for (const auto &[q, list] : incoming)
        n_in += list.size() * width;
      send_buffer.resize(n_out);
      recv_buffer.resize(n_in);
      std::vector<MPI_Request> requests;
      std::size_t              offset = 0;
      for (const auto &[q, list] : incoming)
      {
        requests.emplace_back();
        MPI_Irecv(recv_buffer.data() + offset,
                  list.size() * width,
                  MPI_DOUBLE,
                  q,
                  tag,
                  comm,
                  &requests.back());
        offset += list.size() * width;
      }
      offset = 0;
      for (const auto &[q, list] : outgoing)
      {
        for (std::size_t m = 0; m < list.size(); ++m)
          fill(list[m], send_buffer.data() + offset + m * width);
        requests.emplace_back();
        MPI_Isend(send_buffer.data() + offset,
                  list.size() * width,
                  MPI_DOUBLE,
                  q,
                  tag,
                  comm,
                  &requests.back());
        offset += list.size() * width;
      }
      MPI_Waitall(requests.size(), requests.data(), MPI_STATUSES_IGNORE);
    };

    // 1. The ghost copies in contacts go to their owners, which average
    // the copies in contacts. Over the shared grains only: a buffer over
    // all owned grains, zeroed at every glue, made the glue cost as much as
    // the sweeps between.
    exchange(glue_ghosts, glue_owned, glue_to_owner_tag, pack);
    glue_sum.assign(shared_owned.size() * width, 0.);
    for (unsigned int s = 0; s < shared_owned.size(); ++s)
      if (owner_in_contact[shared_owned[s]])
        pack(shared_owned[s], glue_sum.data() + s * width);
    std::size_t offset = 0;
    for (const auto &[q, list] : glue_owned)
      for (const unsigned int i : list)
      {
        for (unsigned int c = 0; c < width; ++c)
          glue_sum[shared_slot[i] * width + c] += recv_buffer[offset + c];
        offset += width;
      }
    for (unsigned int s = 0; s < shared_owned.size(); ++s)
    {
      const unsigned int i = shared_owned[s];
      for (unsigned int c = 0; c < width; ++c)
        glue_sum[s * width + c] /= copies[i];
      unpack(i, glue_sum.data() + s * width);
    }

    // 2. The glued velocities go back to the copies in contacts.
    exchange(glue_owned,
             glue_ghosts,
             glue_from_owner_tag,
             [&](const unsigned int i, double *b) { pack(i, b); });
    offset = 0;
    for (const auto &[q, list] : glue_ghosts)
      for (const unsigned int i : list)
      {
        unpack(i, recv_buffer.data() + offset);
        offset += width;
      }
  }


  template <int dim>
  void
  DistributedContacts<dim>::drop_ghosts(Contact::GrainArrays<dim> &g) const
  {
    const auto cut = [&](auto &v)
    {
      if (v.size() > n_owned)
        v.resize(n_owned);
    };
    cut(g.velocity);
    cut(g.angular_velocity);
    cut(g.start_velocity);
    cut(g.inverse_mass);
    cut(g.inverse_inertia);
    cut(g.radius);
    cut(g.id);
    cut(g.sweep_key);
    cut(g.position_correction);
    for (unsigned int i = 0; i < n_owned; ++i)
      if (mass_split.size() == n_owned && mass_split[i] > 1)
      {
        g.inverse_mass[i] /= mass_split[i];
        if (friction)
          g.inverse_inertia[i] /= mass_split[i];
      }
  }


  template <int dim>
  Contact::SolverResult
  DistributedContacts<dim>::solve(const std::vector<dealii::Point<dim>> &x,
                                  Contact::GrainArrays<dim>             &g,
                                  const double                           dt,
                                  const double                           alert,
                                  const std::vector<unsigned int>       &cells)
  {
    n_owned   = x.size();
    time_step = dt;
    all_positions.assign(x.begin(), x.end());
    ids = g.id;
    if (ids.empty())
      for (unsigned int i = 0; i < n_owned; ++i)
        ids.push_back(i);
    mass_split.assign(n_owned, 1);
    ghost_owner.clear();
    send_lists.clear();
    recv_lists.clear();

    double r_max = 0;
    for (const double r : g.radius)
      r_max = std::max(r_max, r);
    r_max = dealii::Utilities::MPI::max(r_max, comm);
    if (n_ranks > 1)
    {
      exchange_ghosts(g, r_max + alert, cells);
      g.id = ids;
    }

    g.sweep_key.clear();
    if (sweep_direction.norm() > 0)
      for (const auto &x : all_positions)
        g.sweep_key.push_back(x * sweep_direction);
    neighbours.find_pairs(all_positions, g.radius, ids, alert, pairs);
    walls.find_contacts(all_positions, g.radius, alert, wall_contacts);
    if (n_ranks > 1)
    {
      keep_own_contacts();
      split_masses(g);
    }

    const auto &prm = solver.get_parameters();
    solver.setup(pairs, wall_contacts, walls.velocities(), g, dt);
    glue_copies();

    // One phase, the velocities or the position correction: the same
    // iterations on every rank, which stop together.
    const auto iterate = [&]()
    {
      Contact::SolverResult result;
      if (prm.method == Contact::ContactMethod::apgd)
      {
        // One glue and two reductions per iteration: APGD's gradient needs
        // the velocities of the global iterate.
        const auto reduce = [&](Contact::AcceleratedMeasures &m)
        {
          if (n_ranks == 1)
            return;
          const double sums[3]   = {m.curvature, m.metric, m.restart};
          const double maxima[4] = {m.max_change,
                                    m.max_impulse,
                                    m.max_overlap,
                                    m.overlap_excess};
          double       s[3], x[4];
          dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(sums, 3),
                                      comm,
                                      dealii::ArrayView<double>(s, 3));
          dealii::Utilities::MPI::max(dealii::ArrayView<const double>(maxima,
                                                                      4),
                                      comm,
                                      dealii::ArrayView<double>(x, 4));
          m.curvature      = s[0];
          m.metric         = s[1];
          m.restart        = s[2];
          m.max_change     = x[0];
          m.max_impulse    = x[1];
          m.max_overlap    = x[2];
          m.overlap_excess = x[3];
        };
        return solver.iterate_accelerated([&]() { glue_copies(); }, reduce);
      }
      const auto sum = [&](double *values, const unsigned int n)
      {
        if (n_ranks == 1)
          return;
        std::vector<double> local(values, values + n);
        dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(local),
                                    comm,
                                    dealii::ArrayView<double>(values, n));
      };
      // Subspace corrections as in ContactSolver::solve(); the copies are
      // glued where they run, as they need.
      Contact::SubspaceSchedule schedule(prm.subspace_interval, n_ranks > 1);
      const auto                correct = [&]()
      {
        schedule.record(result.iterations,
                        solver.settled_by(solver.subspace_correction(
                          [&]() { glue_copies(); }, sum)));
      };
      while (!result.converged && result.iterations < prm.max_iterations)
      {
        if (schedule.due(result.iterations))
          correct();
        // Several local sweeps per exchange: on a rank boundary information
        // then crosses once per batch, but the messages and the reduction,
        // whose latency dominates on loaded machines, are paid once.
        // The largest change over the batch: its first sweep is the one
        // that sees what the last glue did to the copies, so a batch
        // converges only once gluing no longer disturbs the contacts.
        Contact::SweepResult s;
        for (unsigned int q = 0; q < (n_ranks > 1 ? sweeps_per_exchange : 1) &&
                                 result.iterations < prm.max_iterations;
             ++q)
        {
          const Contact::SweepResult t = solver.sweep();
          s.max_change                 = std::max(s.max_change, t.max_change);
          s.max_impulse                = std::max(s.max_impulse, t.max_impulse);
          ++result.iterations;
        }
        glue_copies();
        if (n_ranks > 1)
        {
          double local[2] = {s.max_change, s.max_impulse}, global[2];
          dealii::Utilities::MPI::max(dealii::ArrayView<const double>(local, 2),
                                      comm,
                                      dealii::ArrayView<double>(global, 2));
          s.max_change  = global[0];
          s.max_impulse = global[1];
        }
        result.residual = s.max_impulse > 0 ? s.max_change / s.max_impulse : 0;
        if (s.max_change <= prm.tolerance * s.max_impulse)
        {
          // s is the same on every rank, so all correct together.
          if (schedule.confirm(result.iterations))
          {
            schedule.record_confirmation();
            correct();
            if (!schedule.settled)
              continue;
          }
          if (schedule.settled)
            result.converged = dealii::Utilities::MPI::min(
              int(solver.converged(s, solver.predicted_max_overlap())), comm);
        }
      }
      result.max_overlap = solver.predicted_max_overlap();
      return result;
    };

    // Overlaps beyond the limit are removed by moving grains, not by
    // pushing them apart (ContactSolver::iterate_phases()).
    Contact::SolverResult result =
      solver.iterate_phases(iterate,
                            [&](const bool needed) {
                              return dealii::Utilities::MPI::max(int(needed),
                                                                 comm) == 1;
                            });
    solver.finish(g);
    drop_ghosts(g);

    unsigned int active = 0;
    for (const double p : solver.pair_impulses().normal)
      active += (p > 0);
    for (const double p : solver.wall_impulses().normal)
      active += (p > 0);
    result.max_overlap = dealii::Utilities::MPI::max(result.max_overlap, comm);
    result.n_contacts  = dealii::Utilities::MPI::sum(
      static_cast<unsigned int>(pairs.size() + wall_contacts.size()), comm);
    result.n_active = dealii::Utilities::MPI::sum(active, comm);
    return result;
  }


  template <int dim>
  double
  DistributedContacts<dim>::max_contact_force() const
  {
    double p = 0;
    for (const double q : solver.pair_impulses().normal)
      p = std::max(p, q);
    for (const double q : solver.wall_impulses().normal)
      p = std::max(p, q);
    return dealii::Utilities::MPI::max(time_step > 0 ? p / time_step : 0.,
                                       comm);
  }


  template <int dim>
  void
  DistributedContacts<dim>::add_boundary_impulses(
    std::map<dealii::types::boundary_id, dealii::Tensor<1, dim>> &impulses)
    const
  {
    // The wall is the contact's partner: the normal impulse pushes it
    // along the normal, from the grain towards the wall.
    const auto &on_walls = solver.wall_impulses();
    for (unsigned int m = 0;
         m < wall_contacts.size() && m < on_walls.normal.size();
         ++m)
    {
      auto &sum = impulses[wall_boundary_ids[wall_contacts[m].wall]];
      sum +=
        on_walls.normal[m] * wall_contacts[m].normal + on_walls.tangential[m];
    }
  }


  template <int dim>
  std::vector<ContactForce>
  DistributedContacts<dim>::contact_forces() const
  {
    std::vector<ContactForce> forces;
    const auto               &pn = solver.pair_impulses().normal;
    for (unsigned int m = 0; m < pairs.size() && m < pn.size(); ++m)
      forces.push_back(
        {ids[pairs[m].first], ids[pairs[m].second], false, pn[m] / time_step});
    const auto &wn = solver.wall_impulses().normal;
    for (unsigned int m = 0; m < wall_contacts.size() && m < wn.size(); ++m)
      forces.push_back({ids[wall_contacts[m].grain],
                        wall_contacts[m].wall,
                        true,
                        wn[m] / time_step});
    return forces;
  }


  template class DistributedContacts<2>;
  template class DistributedContacts<3>;
} // namespace ImmersedGrains
