#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include <immersed_grains/coupling/coupled_step.h>
#include <immersed_grains/fluid/fluid_solver.h>
#include <immersed_grains/grains/grains.h>
#include <immersed_grains/io/field_output.h>
#include <immersed_grains/io/particle_output.h>
#include <immersed_grains/io/progress_line.h>
#include <immersed_grains/simulation.h>

#include <filesystem>
#include <fstream>
#include <limits>

namespace ImmersedGrains
{


  template <int dim>
  void
  Simulation<dim>::maybe_write_checkpoint()
  {
    if (checkpoint->due(step, wall_clock()))
      write_checkpoint();
  }


  template <int dim>
  void
  Simulation<dim>::write_checkpoint()
  {
    dealii::TimerOutput::Scope scope(*timer, "output");
    const std::string          directory = checkpoint->begin(step);
    // The fluid's states first, then the grains: loading follows this
    // order.
    if (fluid)
      fluid->prepare_for_serialization();
    if (grains)
      grains->prepare_for_serialization();
    triangulation.save(directory + "/mesh");
    Checkpoint::maybe_die_while_writing(step);
    if (grains)
    {
      std::ofstream out(
        directory + "/contacts_" +
        std::to_string(dealii::Utilities::MPI::this_mpi_process(comm)) +
        ".txt");
      grains->save_contact_memory(out);
      AssertThrow(out, dealii::ExcMessage("Cannot write " + directory));
      // Grains that left in the last step and whose volume the next fluid
      // step takes out of the mixture (Coupling::project_departed()).
      std::ofstream departed(
        directory + "/departed_" +
        std::to_string(dealii::Utilities::MPI::this_mpi_process(comm)) +
        ".txt");
      grains->save_departed(departed);
      AssertThrow(departed, dealii::ExcMessage("Cannot write " + directory));
    }
    field_output->series().save(directory + "/fields_xdmf.txt");
    particle_output->series().save(directory + "/particles_xdmf.txt");
    // Written last: its presence marks the set complete (Checkpoint).
    save_state(directory);
    const std::string saved = checkpoint->commit(step, wall_clock());

    // Go on from what was just written, as a run resumed from it would: a
    // loaded triangulation numbers its cells afresh, and with them the
    // DoFs and the order of the grains, while one that was refined and
    // coarsened keeps the gaps of its history; the two would round
    // differently from here on. (The preconditioner is rebuilt too.)
    const bool echo = pcout.is_active();
    pcout.set_condition(false);
    pdetail.set_condition(false);
    coupling.reset();
    adaptivity.reset();
    load_balance.reset();
    grains.reset();
    fluid.reset();
    triangulation.clear();
    setup(saved);
    pcout.set_condition(echo);
    pdetail.set_condition(echo);
  }


  namespace
  {
    // What decides the layout of the saved fields and grains: a run with
    // other physics would read them as something else (a frictionless
    // pile's 4 numbers per grain read as 7 gave grains at infinite speed).
    template <int dim>
    std::string
    physics_description(const bool                  fluid,
                        const GrainParameters<dim> &grains,
                        const bool                  straight_paths)
    {
      std::string text =
        std::string("fluid ") + (fluid ? "on" : "off") + ", grains ";
      if (!grains.enabled)
        return text + "off";
      const GrainPropertyLayout layout =
        make_grain_property_layout(grains, fluid, straight_paths);
      text += "with " + std::to_string(layout.n_properties) + " properties (";
      for (unsigned int k = 0; k < layout.names.size(); ++k)
        if (k == 0 || layout.names[k] != layout.names[k - 1])
          text += (k == 0 ? "" : ", ") + layout.names[k];
      return text + ")";
    }
  } // namespace


  template <int dim>
  std::string
  Simulation<dim>::saved_physics_description() const
  {
    return physics_description(fluid_parameters.enabled,
                               grain_parameters,
                               follows_straight_paths());
  }


  template <int dim>
  bool
  Simulation<dim>::physics_reachable(const std::string &saved) const
  {
    // Every combination of the settings that decide the layout.
    for (unsigned int k = 0; k < 64; ++k)
    {
      GrainParameters<dim> grains = grain_parameters;
      grains.enabled              = k & 1;
      grains.contacts_enabled     = k & 2;
      grains.contact.friction     = (k & 4) ? 1.0 : 0.0;
      grains.has_fixed_region     = k & 8;
      const bool fluid            = k & 16;
      const bool straight_paths   = k & 32;
      if (physics_description(fluid, grains, straight_paths) == saved)
        return true;
    }
    return false;
  }


  template <int dim>
  void
  Simulation<dim>::check_saved_physics(const std::string &directory) const
  {
    // Checkpoints written before this file existed are taken as they are,
    // unless the grains now follow straight paths, which no grain of such
    // a set carries (Band lookahead came after the file).
    std::ifstream in(directory + "/physics.txt");
    std::string   saved;
    if (!std::getline(in, saved))
    {
      if (follows_straight_paths())
        InputLocation{parameter_file, "Checkpoint"}.fail(
          "Resume",
          checkpoint_parameters.resume == Checkpoint::Resume::always ? "true" :
                                                                       "auto",
          directory +
            " was written before the grains carried their straight paths "
            "(it has no physics.txt), which Adaptivity/Band lookahead = " +
            std::to_string(adaptivity_parameters.band_lookahead) +
            " needs: resume with Band lookahead = 0, or start afresh with "
            "Resume = false");
      return;
    }
    const std::string wanted = saved_physics_description();
    if (saved != wanted && !physics_reachable(saved))
      InputLocation{parameter_file, "Checkpoint"}.fail(
        "Resume",
        checkpoint_parameters.resume == Checkpoint::Resume::always ? "true" :
                                                                     "auto",
        directory + " was written with " + saved +
          ", a layout no setting of this version gives (this version's, "
          "for this scene: " +
          wanted +
          "): it was written by another version of immersed-grains; resume "
          "it with that version, or start afresh with Resume = false");
    if (saved != wanted)
      InputLocation{parameter_file, "Checkpoint"}.fail(
        "Resume",
        checkpoint_parameters.resume == Checkpoint::Resume::always ? "true" :
                                                                     "auto",
        directory + " was written with " + saved + "; this scene has " +
          wanted +
          ": resume with the settings it was written with (Fluid/Enabled, "
          "Grains/Enabled, Contacts/Enabled, Contacts/Friction, a fixed "
          "region and Adaptivity/Band lookahead decide these), or start "
          "afresh with Resume = false");
  }


  template <int dim>
  void
  Simulation<dim>::save_state(const std::string &directory) const
  {
    MPI_Barrier(comm);
    if (dealii::Utilities::MPI::this_mpi_process(comm) != 0)
      return;
    std::ofstream out(directory + "/state.txt.part");
    out << step << '\n'
        << std::hexfloat << time << '\n'
        << std::dec << dealii::Utilities::MPI::n_mpi_processes(comm) << ' '
        << (coupled_step ? coupled_step->clamped_nodes_before() : 0u) << ' '
        << preconditioner_builds << '\n';
    if (fluid)
      fluid->save_state(out);
    else
      out << "none\n";
    for (const auto *records : {&field_output->series().records(),
                                &particle_output->series().records()})
    {
      out << records->size() << '\n';
      for (const auto &[t, file] : *records)
        out << std::hexfloat << t << ' ' << file << '\n';
    }
    out << "grain_travel " << std::hexfloat << grain_travel << '\n';
    {
      const StraightPathDrift drift =
        grains ? grains->straight_path_drift() : StraightPathDrift();
      out << "band_lookahead " << std::hexfloat
          << (adaptivity ? adaptivity->lookahead_horizon() : 0.0) << ' '
          << band_made_at << ' ' << drift.displacement << ' ' << drift.velocity
          << '\n';
    }
    {
      const typename CoupledStep<dim>::ExchangeBooks books =
        coupled_step ? coupled_step->books() :
                       typename CoupledStep<dim>::ExchangeBooks();
      out << "momentum_exchange " << std::hexfloat << books.impulse;
      for (unsigned int d = 0; d < dim; ++d)
        out << ' ' << books.imbalance[d];
      out << '\n';
    }
    out << "run_figures " << std::hexfloat << previous_step << ' '
        << retries_taken << ' ' << breakup_time << '\n';
    out << "grains_removed " << std::hexfloat
        << static_cast<double>(grains ? grains->n_removed() : 0) << '\n';
    out << "fluid_volume_books " << std::hexfloat << previous_fluid_volume
        << '\n';
    statistics.save_values(out);
    out.close();
    AssertThrow(out, dealii::ExcMessage("Cannot write " + directory));
    std::ofstream physics(directory + "/physics.txt");
    physics << saved_physics_description() << '\n';
    physics.close();
    AssertThrow(physics, dealii::ExcMessage("Cannot write " + directory));
    std::filesystem::rename(directory + "/state.txt.part",
                            directory + "/state.txt");
  }


  template <int dim>
  void
  Simulation<dim>::load_state(const std::string &directory)
  {
    // Every rank reads the same file.
    std::ifstream in(directory + "/state.txt");
    std::string   text;
    unsigned int  saved_ranks          = 0;
    unsigned int  clamped_nodes_before = 0;
    in >> step >> text >> saved_ranks >> clamped_nodes_before >>
      preconditioner_builds;
    if (coupled_step)
      coupled_step->clamped_nodes_before() = clamped_nodes_before;
    time = std::strtod(text.c_str(), nullptr);
    if (fluid)
      fluid->load_state(in);
    else
      in >> text;
    for (auto *records : {&field_output->series().records(),
                          &particle_output->series().records()})
    {
      std::size_t n = 0;
      in >> n;
      records->clear();
      for (std::size_t k = 0; k < n; ++k)
      {
        std::string file;
        in >> text >> file;
        records->emplace_back(std::strtod(text.c_str(), nullptr), file);
      }
    }
    // Lines added to state.txt after its first version: KEYWORD and
    // @p n values (hexfloat), or absent in older checkpoints, which then
    // leaves the stream where it was and returns nothing.
    const auto optional_line =
      [&in, &text](const std::string &keyword, const unsigned int n)
    {
      std::vector<double> values;
      const auto          position = in.tellg();
      if (in >> text && text == keyword)
        for (unsigned int k = 0; k < n && in >> text; ++k)
          values.push_back(std::strtod(text.c_str(), nullptr));
      if (values.size() != n)
      {
        values.clear();
        in.clear();
        in.seekg(position);
      }
      return values;
    };
    // Absent from checkpoints written before Adaptivity/Every steps = auto:
    // the next adaptation then comes a little later than it would have.
    const auto travel = optional_line("grain_travel", 1);
    grain_travel      = travel.empty() ? 0 : travel[0];
    // Absent before Adaptivity/Band lookahead: the band then lasts until
    // the grains have travelled its allowance.
    const auto lookahead = optional_line("band_lookahead", 4);
    if (!lookahead.empty())
    {
      if (adaptivity)
        adaptivity->set_lookahead_horizon(lookahead[0]);
      band_made_at = lookahead[1];
      if (grains)
        grains->straight_path_drift() = {lookahead[2], lookahead[3]};
    }
    // Absent before momentum_exchange_drift: its books start at the resume.
    const auto exchange = optional_line("momentum_exchange", 1 + dim);
    if (coupled_step)
    {
      auto &books   = coupled_step->books();
      books.impulse = exchange.empty() ? 0 : exchange[0];
      for (unsigned int d = 0; d < dim; ++d)
        books.imbalance[d] = exchange.empty() ? 0 : exchange[1 + d];
    }
    const auto figures = optional_line("run_figures", 3);
    // Absent before grains could leave through a mesh's open boundary
    // counted so: the restored row holds the count.
    const auto removed = optional_line("grains_removed", 1);
    // Absent before fluid_volume_balance: its first row after the resume
    // is then 0.
    const auto books = optional_line("fluid_volume_books", 1);
    previous_fluid_volume =
      books.empty() ? std::numeric_limits<double>::quiet_NaN() : books[0];
    statistics.load_values(in);
    if (grains)
      grains->set_removed(static_cast<unsigned long>(
        removed.empty() ? statistics.get("grains_removed") : removed[0]));
    // Absent before run_figures: the restored row holds them.
    previous_step = figures.empty() ? statistics.get("dt") : figures[0];
    retries_taken =
      figures.empty() ? statistics.get("step_retries") : figures[1];
    breakup_time = figures.empty() ? (statistics.has("breakup_time") ?
                                        statistics.get("breakup_time") :
                                        -1.0) :
                                     figures[2];
    AssertThrow(!in.bad(),
                dealii::ExcMessage("Checkpoint: cannot read " + directory));
    field_output->series().load(directory + "/fields_xdmf.txt");
    particle_output->series().load(directory + "/particles_xdmf.txt");

    if (grains)
    {
      // The same ranks: each its own warm-start impulses, exactly as it
      // left them. Others: every rank all of them (it uses those of its
      // contacts).
      const unsigned int n_ranks =
        dealii::Utilities::MPI::n_mpi_processes(comm);
      const unsigned int me = dealii::Utilities::MPI::this_mpi_process(comm);
      for (unsigned int r = 0; r < saved_ranks; ++r)
        if (saved_ranks != n_ranks || r == me)
        {
          std::ifstream contacts(directory + "/contacts_" + std::to_string(r) +
                                 ".txt");
          grains->load_contact_memory(contacts);
        }
      // Rank 0 reads every rank's departed grains; departed() finds their
      // cells on whichever rank owns them now. (Absent from checkpoints
      // written before the sink existed: none then.)
      std::stringstream departed;
      if (me == 0)
        for (unsigned int r = 0; r < saved_ranks; ++r)
        {
          std::ifstream file(directory + "/departed_" + std::to_string(r) +
                             ".txt");
          // (Inserting an empty or missing file would fail the stream.)
          if (file && file.peek() != std::ifstream::traits_type::eof())
            departed << file.rdbuf();
        }
      grains->load_departed(departed);
    }
  }



#define IMMERSED_GRAINS_INSTANTIATE(dim)                                       \
  template void        Simulation<dim>::maybe_write_checkpoint();              \
  template void        Simulation<dim>::write_checkpoint();                    \
  template void        Simulation<dim>::save_state(const std::string &) const; \
  template void        Simulation<dim>::load_state(const std::string &);       \
  template std::string Simulation<dim>::saved_physics_description() const;     \
  template bool Simulation<dim>::physics_reachable(const std::string &) const; \
  template void Simulation<dim>::check_saved_physics(const std::string &) const;

  IMMERSED_GRAINS_INSTANTIATE(2)
  IMMERSED_GRAINS_INSTANTIATE(3)
} // namespace ImmersedGrains
