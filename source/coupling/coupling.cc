#include <deal.II/base/mpi.h>

#include <immersed_grains/coupling/coupling.h>
#include <immersed_grains/fluid/fluid_solver.h>
#include <immersed_grains/grains/grains.h>
#include <immersed_grains/parameters.h>

#include <map>

namespace ImmersedGrains
{
  template <int dim>
  void
  Coupling<dim>::Parameters::declare_parameters(dealii::ParameterHandler &prm)
  {
    using namespace dealii::Patterns;
    prm.enter_subsection("Coupling");
    {
      std::string documentation =
        "Drag closure D = gamma(phi, |w|) w on each grain (w = v - u_f):";
      for (const auto &[name, description] : DragLaw::descriptions())
        documentation += " " + name + " (" + description + ");";
      prm.declare_entry("Drag law",
                        "Dallavalle-Wen-Yu",
                        Selection(DragLaw::names()),
                        documentation);
      prm.declare_entry("Two-way",
                        "true",
                        Bool(),
                        "The fluid feels the grains (solid fraction and drag "
                        "reaction); false: one-way coupling, the grains feel "
                        "the fluid only.");
      prm.declare_entry("Tracers",
                        "false",
                        Bool(),
                        "Grains take the fluid velocity at their centre and "
                        "feel nothing else (implies Two-way = false).");
      prm.declare_entry(
        "Drag distribution",
        "auto",
        Selection("auto|cell|point|filtered"),
        "How a grain's drag enters the fluid: 'point' through the velocity "
        "shape functions at its centre (deal.II step-70), felt against the "
        "fluid velocity there; 'cell' spread evenly over its cell, felt "
        "against the cell-mean velocity; 'filtered' spread with the "
        "Helmholtz filter of length 'Smoothing length' (lumped mass), felt "
        "against the fluid velocity filtered the same way. A grain feels "
        "part of its own disturbance of the fluid; with 'point' and 'cell' "
        "that part grows as cells shrink towards the grain size "
        "(doc/validation.md), with 'filtered' it is set by the length in "
        "metres and does not depend on the mesh. 'auto', two-way coupled: "
        "in 3D 'filtered' for grains placed at random across a box "
        "periodic sideways (Shape = box spanning a periodic axis), with "
        "'Smoothing length' 8 radii of the largest grain unless the length "
        "is set (suspensions within 1 % of the closure, where the corrected "
        "cell spread settles 2-10 % slow) and for packed grains (two or "
        "more neighbours each within 5 % of touching, not a ball or a "
        "lattice: the filter must keep the pore pressure through the "
        "packing), 'cell' for every other placement (lone grains, clouds, "
        "grains given one by one, boxes walled all round); in "
        "2D 'cell' for a cloud (a ball placement) and a "
        "lattice, 'filtered' for other placements: with 'Smoothing length' "
        "three mean diameters where the placed discs are packed (two or "
        "more neighbours each within 5 % of touching: the filter must keep "
        "the pore pressure), half the box's shortest side for lone discs "
        "and suspensions (a disc's own disturbance decays only "
        "logarithmically, doc/theory.md), unless the length is set; the "
        "log says which.");
      prm.declare_entry(
        "Implicit coupling",
        "true",
        Bool(),
        "The grains' new velocities, eliminated into the fluid solve: the "
        "pressure-gradient force on them (-V grad p) and their volume flux "
        "in the mixture continuity at the new time level (doc/theory.md 3). "
        "Keeps dense beds and suspensions stable with time steps far above "
        "their relaxation time. false: both from the previous step (stable "
        "only for dilute suspensions or short steps).");
      prm.declare_entry(
        "Grain sub-steps",
        "true",
        Bool(),
        "Where one fluid step would move a grain more than Grains/Max "
        "displacement fraction of the smallest radius (or half a cell), the "
        "grains take as many equal sub-steps through the fluid of that step "
        "as keep them within it, their interaction force and drag "
        "coefficient re-evaluated where they are at each (contacts solved "
        "at each). false: one grain step per fluid step.");
      prm.declare_entry(
        "Maximum grain sub-steps",
        "1000",
        Integer(1),
        "The most grain sub-steps one fluid step may take. A step that would "
        "need more (its fastest grain would cross more than 125 of the "
        "smallest radii in the fluid of that step) has lost the coupling: "
        "grains far faster than the fluid step can follow, typically a "
        "coupling grown unstable at a step too long. It is taken again with "
        "half its length (Adaptive time step = true, up to Step retries "
        "times), else the run stops with a message, instead of crawling "
        "through thousands of sub-steps per step (doc/stability.md).");
      prm.declare_entry(
        "Resting threshold",
        "0.1",
        Double(0),
        "A grain whose speed is at most this fraction of the velocity its "
        "last contact impulse removed (|v| <= f |P| / (m + dt gamma), with "
        "the drag-augmented mass) is held by its "
        "contacts: the fluid sees it at its velocity with its full drag, as "
        "a fixed grain, instead of eliminating its update (which needs the "
        "new contact impulse). Keeps packed beds at rest with time steps far "
        "above their relaxation time. 0: never.");
      prm.declare_entry(
        "Impulse prediction weight",
        "0.333333",
        Double(0, 1),
        "The fluid step predicts the contact impulse each free grain will "
        "receive (it drives the grain's drag on the fluid) as Q = w P + "
        "(1 - w) Q_last, P the grain's impulse of the last step. 1: the last "
        "impulse alone, which lets grains that collide and part in turn "
        "(dense suspensions) alternate with the fluid from step to step; "
        "the default removes that alternation where the impulses answer "
        "with minus twice the prediction and damps it up to five times "
        "(doc/theory.md, \"Contacts and the drag the fluid receives\"). "
        "Grains held by their contacts do not use it.");
      prm.declare_entry(
        "Repay drag mismatch",
        "true",
        Bool(),
        "The drag impulse a grain received over a fluid step and the fluid "
        "did not (its sub-steps' drags against the one the fluid's step "
        "assumed) is given to the fluid at the grain in the next step, so "
        "that over a run the phases exchange the same momentum, up to the "
        "last step's (statistics momentum_exchange_owed and "
        "momentum_exchange_drift, doc/theory.md). Not for a grain with a "
        "contact impulse in the step, nor the error of a predicted one: "
        "the relaxed prediction (Impulse prediction weight) carries those. "
        "false: the mismatch is reported, not repaid.");
      prm.declare_entry(
        "Self-disturbance correction",
        "auto",
        Selection("auto|true|false|yes|no"),
        "Each grain's drag law reads the fluid as it would be without the "
        "grain, as drag closures assume: its own share of the projected "
        "solid fraction is taken out of the fluid fraction it reads, and "
        "its own disturbance of the velocity it feels (the force it put on "
        "the fluid times the self-mobility of the drag distribution, built "
        "up over the distribution's diffusion time, doc/theory.md) out of "
        "its slip; among other grains only the share that the hole in their "
        "packing leaves, the hard-sphere structure factor S(0) at the local "
        "solid fraction. Validated in 3D for lone grains with the cell and "
        "filtered distributions (the settling velocity no longer depends on "
        "the cell) and for clouds (unchanged within 0.3 %); suspensions "
        "spread over cells of 4-16 radii settle 2-10 % below the closure "
        "with it. auto: on in 3D with the cell spread (given, or chosen by "
        "Drag distribution = auto), whose grains otherwise settle 5-17 % "
        "too fast alone and 2-24 % in suspensions; off with the filtered "
        "distribution, whose length of 8 radii or more already keeps "
        "suspensions within 1 % of the closure (2-5 % below with the "
        "correction), off for the point "
        "distribution, and off in 2D, where the velocity part is not "
        "modelled (a disc's disturbance grows with the box; "
        "doc/validation.md).");
      SolidFraction<dim>::Parameters::declare_parameters(prm);
    }
    prm.leave_subsection();
  }


  template <int dim>
  void
  Coupling<dim>::Parameters::parse_parameters(dealii::ParameterHandler &prm,
                                              const std::string        &file)
  {
    prm.enter_subsection("Coupling");
    {
      drag_law                  = prm.get("Drag law");
      tracers                   = prm.get_bool("Tracers");
      two_way                   = prm.get_bool("Two-way") && !tracers;
      drag_distribution         = prm.get("Drag distribution");
      implicit_coupling         = prm.get_bool("Implicit coupling");
      grain_substeps            = prm.get_bool("Grain sub-steps");
      max_grain_substeps        = prm.get_integer("Maximum grain sub-steps");
      resting_threshold         = prm.get_double("Resting threshold");
      impulse_prediction_weight = prm.get_double("Impulse prediction weight");
      repay_drag_mismatch       = prm.get_bool("Repay drag mismatch");
      InputLocation{file, "Coupling"}.require(
        impulse_prediction_weight > 0,
        "Impulse prediction weight",
        prm.get("Impulse prediction weight"),
        "must lie in (0, 1]: 0 would keep the first prediction "
        "for ever");

      const std::string correction = prm.get("Self-disturbance correction");
      // An 'auto' distribution counts as the cell spread until Simulation
      // chooses one (choose_drag_distribution), after which the same rule is
      // applied to the choice.
      self_correction = correction == "auto" ?
                          dim == 3 && (drag_distribution == "cell" ||
                                       drag_distribution == "auto") :
                          (correction == "true" || correction == "yes");
      projection.parse_parameters(prm, file);
      projection.with_mean_diameter =
        DragLaw::create(drag_law)->needs_mean_diameter();
    }
    prm.leave_subsection();
  }


  template <int dim>
  Coupling<dim>::Coupling(
    const Parameters                                        &parameters,
    const GrainParameters<dim>                              &grain_parameters,
    const Geometry<dim>                                     &geometry,
    const dealii::parallel::distributed::Triangulation<dim> &tria,
    const double                                             fluid_density,
    const double                                             fluid_viscosity,
    const bool                                               fluid_transient,
    const bool                                               fluid_advection,
    dealii::TimerOutput                                     &timer)
      : parameters(parameters)
      , grain_parameters(grain_parameters)
      , triangulation(tria)
      , density(fluid_density)
      , viscosity(fluid_viscosity)
      , fluid_transient(fluid_transient)
      , fluid_advection(fluid_advection)
      , timer(timer)
      , projection(std::make_shared<SolidFraction<dim>>(parameters.projection,
                                                        geometry,
                                                        tria))
      , drag_law(DragLaw::create(parameters.drag_law))
      , self_disturbance(parameters.drag_distribution,
                         parameters.projection.smoothing_length,
                         parameters.projection.lumped)
  {
    if (parameters.drag_distribution == "filtered" ||
        (parameters.two_way && parameters.implicit_coupling))
      filtered_drag = std::make_unique<FilteredDrag<dim>>(
        tria,
        geometry,
        parameters.projection.smoothing_length,
        parameters.drag_distribution == "filtered",
        parameters.two_way && parameters.implicit_coupling);
  }


  template <int dim>
  void
  Coupling<dim>::setup()
  {
    projection->setup();
    if (filtered_drag)
      filtered_drag->setup();
    filtered_velocity_current = false;
    sized_cell                = dealii::numbers::invalid_unsigned_int;
  }


  template <int dim>
  void
  Coupling<dim>::attach(FluidSolver<dim> &fluid) const
  {
    if (!parameters.two_way)
      return;
    // The simulation owns both; the fluid only borrows this object.
    // Grains meet inflow faces as walls, and leave through open ones
    // whole, when their centre crosses (project_departed()): no solid flux
    // passes any boundary.
    fluid.set_mixture_fields(std::shared_ptr<const MixtureFields<dim>>(
                               this, [](const MixtureFields<dim> *) {}),
                             false);
    if (!drag_as_field())
      fluid.set_point_drag_source(std::shared_ptr<const PointDragSource<dim>>(
                                    this, [](const PointDragSource<dim> *) {}),
                                  parameters.drag_distribution == "cell");
  }


  template <int dim>
  typename FilteredDrag<dim>::SolidScale
  Coupling<dim>::solid_scale() const
  {
    if (projection->n_clamped() == 0)
      return {};
    return [this](const auto &cell, const auto &reference_points)
    { return projection->solid_scale(cell, reference_points); };
  }


  template <int dim>
  void
  Coupling<dim>::evaluate(
    const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
    const std::vector<dealii::Point<dim>>                           &points,
    const std::vector<dealii::Point<dim>> &reference_points,
    const double                           time,
    MixtureValues<dim>                    &values) const
  {
    projection->evaluate(cell, points, reference_points, time, values);
    if (!filtered_drag)
      return;
    filtered_drag->evaluate(cell, reference_points, values);
    if (parameters.two_way && parameters.implicit_coupling)
      // Where the fluid fraction is clamped, the grains fill only the rest:
      // their flux s + alpha u - k (s_scale grad p) and their share of the
      // pressure gradient, scaled like the explicit flux.
      for (unsigned int q = 0; q < reference_points.size(); ++q)
      {
        const double scale = values.solid_scale[q];
        values.solid_flux[q] *= scale;
        values.pressure_gradient_weight[q] *= scale;
        values.pressure_mobility[q] *= scale * scale;
      }
  }


  namespace
  {
    template <typename PointValues>
    auto
    velocities_of(const std::vector<PointValues> &values)
    {
      std::vector<decltype(PointValues::velocity)> result;
      for (const auto &v : values)
        result.push_back(v.velocity);
      return result;
    }
  } // namespace


  template <int dim>
  std::vector<dealii::Tensor<1, dim>>
  Coupling<dim>::felt_velocity(
    const FluidSolver<dim>                                          &fluid,
    const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
    const std::vector<dealii::Point<dim>> &references) const
  {
    if (drag_as_field())
      return filtered_drag->filtered_velocity(cell, references);
    return velocities_of(fluid.point_values(cell, references));
  }


  namespace
  {
    // Calls @p f(cell, first, end) for each run of consecutive particles in
    // the same cell; the ParticleHandler iterates cell by cell, in the order
    // in which Grains gathered its arrays.
    template <int dim, typename F>
    void
    for_each_cell_batch(
      const dealii::Particles::ParticleHandler<dim> &particles,
      std::vector<dealii::Point<dim>>               &references,
      F                                            &&f)
    {
      unsigned int index = 0;
      auto         it    = particles.begin();
      while (it != particles.end())
      {
        const auto         cell  = it->get_surrounding_cell();
        const unsigned int first = index;
        references.clear();
        while (it != particles.end() && it->get_surrounding_cell() == cell)
        {
          references.push_back(it->get_reference_location());
          ++it;
          ++index;
        }
        f(cell, first, index);
      }
    }
  } // namespace


  template <int dim>
  void
  Coupling<dim>::project(Grains<dim> &grains, const double dt)
  {
    dealii::TimerOutput::Scope scope(timer, "coupling: solid fraction");
    const auto                &particles = grains.particle_handler();
    const auto                &layout    = grains.layout();
    removed_volume_at_projection         = grains.removed_volume();
    // What is left of the departed grains after this step, by cell.
    std::map<std::pair<int, int>, std::vector<GrainSample<dim>>> remnants;
    double                                                       held = 0;
    for (const auto &g : grains.departed())
    {
      GrainSample<dim> s{};
      s.reference_location = g.reference;
      s.volume             = g.volume - g.drained(dt);
      s.diameter           = g.diameter;
      if (s.volume <= 0)
        continue;
      held += s.volume;
      remnants[{g.cell->level(), g.cell->index()}].push_back(s);
    }
    departed_in_projection =
      dealii::Utilities::MPI::sum(held, triangulation.get_communicator());

    projection->project(
      [&](const auto &cell, std::vector<GrainSample<dim>> &samples)
      {
        if (!remnants.empty())
        {
          const auto found = remnants.find({cell->level(), cell->index()});
          if (found != remnants.end())
            samples.insert(samples.end(),
                           found->second.begin(),
                           found->second.end());
        }
        for (const auto &p : particles.particles_in_cell(cell))
        {
          const auto       props = p.get_properties();
          GrainSample<dim> s;
          s.reference_location = p.get_reference_location();
          s.volume             = grain_volume<dim>(props[layout.radius]);
          s.diameter           = 2 * props[layout.radius];
          const bool fixed     = grains.is_fixed(p);
          for (unsigned int d = 0; d < dim; ++d)
            s.velocity[d] = fixed ? 0.0 : props[layout.velocity + d];
          samples.push_back(s);
        }
      },
      // The implicit coupling replaces the projected flux.
      !(parameters.two_way && parameters.implicit_coupling),
      parameters.two_way && fraction_rate);
  }


  template <int dim>
  void
  Coupling<dim>::set_fraction_rate(const bool needed)
  {
    fraction_rate = needed;
  }


  template <int dim>
  void
  Coupling<dim>::project_departed(Grains<dim> &grains, const double dt)
  {
    if (!parameters.two_way)
      return;
    dealii::TimerOutput::Scope scope(timer, "coupling: solid fraction");
    std::vector<
      std::pair<typename dealii::Triangulation<dim>::active_cell_iterator,
                GrainSample<dim>>>
      samples;
    for (const auto &g : grains.departed())
    {
      GrainSample<dim> s{};
      s.reference_location = g.reference;
      s.volume             = g.drained(dt);
      samples.emplace_back(g.cell, s);
    }
    projection->project_sink(samples, dt);
  }


  template <int dim>
  DragInput
  Coupling<dim>::drag_input(const double                  radius,
                            const double                  fluid_fraction,
                            const dealii::Tensor<1, dim> &slip,
                            const double                  mean_diameter) const
  {
    return {radius,
            grain_projected_area<dim>(radius),
            grain_volume<dim>(radius),
            parameters.projection.closure_porosity.of(fluid_fraction),
            slip.norm(),
            density,
            viscosity,
            mean_diameter};
  }


  template <int dim>
  std::pair<double, dealii::Tensor<1, dim>>
  Coupling<dim>::undisturbed(
    const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
    const dealii::Point<dim>                                        &reference,
    const double                                                     radius,
    const double                  felt_fraction,
    const dealii::Tensor<1, dim> &slip,
    const GrainStepArrays<dim>   &arrays,
    const unsigned int            i,
    const double                  dt,
    const bool                    free) const
  {
    if (!parameters.self_correction || !parameters.two_way || !free ||
        arrays.drag_force.empty())
      return {felt_fraction, dealii::Tensor<1, dim>()};
    if (cell->active_cell_index() != sized_cell)
    {
      sized_cell   = cell->active_cell_index();
      sized_cell_h = std::pow(cell->measure(), 1.0 / dim);
    }
    const double h = sized_cell_h;
    // What the grain puts into the fields it reads, less what the hole
    // around it in its neighbours' packing takes out: among neighbours at
    // solid fraction s only S(s) of its own share stays (doc/theory.md).
    // The clamp at the minimum fluid fraction stands: a packed bed's
    // fraction is not the grain's own.
    const double own =
      self_disturbance.own_solid_fraction(reference,
                                          h,
                                          grain_volume<dim>(radius));
    const double structure = SelfDisturbance<dim>::structure_factor(
      1 - std::min(1.0, felt_fraction + own));
    const double phi = std::min(1.0, felt_fraction + structure * own);
    // A later sub-step sees the fluid of its step, frozen, and the
    // grain's disturbance of it with it.
    if (dt == 0)
      return {phi, arrays.self_velocity[i]};
    // The grain pushed the fluid with -drag.
    const dealii::Tensor<1, dim> steady =
      -structure * self_disturbance.mobility(h, phi, viscosity) *
      arrays.drag_force[i];
    const double nu  = viscosity / density;
    const double t_K = self_disturbance.build_up_time(h, nu);
    const double leave_rate =
      fluid_advection && t_K > 0 ?
        (slip - arrays.self_velocity[i]).norm() / std::sqrt(nu * t_K) :
        0.0;
    if (!fluid_transient || t_K == 0)
      return {phi, steady / (1 + t_K * leave_rate)};
    return {phi,
            (arrays.self_velocity[i] + dt / t_K * steady) /
              (1 + dt / t_K + dt * leave_rate)};
  }


  template <int dim>
  typename Coupling<dim>::GrainDrag
  Coupling<dim>::grain_drag(
    const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
    const dealii::Point<dim>                                        &reference,
    const GrainStepArrays<dim>                                      &arrays,
    const unsigned int                                               i,
    const double                  felt_fraction,
    const dealii::Tensor<1, dim> &felt,
    const double                  mean_diameter,
    const double                  dt,
    const bool                    frozen) const
  {
    const auto  &c = arrays.contact;
    const double r = c.radius[i];
    GrainDrag    drag;
    DragInput    in =
      drag_input(r, felt_fraction, c.velocity[i] - felt, mean_diameter);
    drag.gamma             = drag_law->coefficient(in);
    drag.held              = held(arrays, i, arrays.mass[i] + dt * drag.gamma);
    const auto [phi, self] = undisturbed(cell,
                                         reference,
                                         r,
                                         felt_fraction,
                                         c.velocity[i] - felt,
                                         arrays,
                                         i,
                                         frozen ? 0.0 : dt,
                                         !arrays.fixed[i] && !drag.held);
    if (phi != felt_fraction || self.norm() > 0)
    {
      in = drag_input(r, phi, c.velocity[i] - (felt - self), mean_diameter);
      drag.gamma = drag_law->coefficient(in);
    }
    drag.self     = self;
    drag.reynolds = DragLaw::reynolds(in);
    return drag;
  }


  template <int dim>
  bool
  Coupling<dim>::held(const GrainStepArrays<dim> &arrays,
                      const unsigned int          i,
                      const double                drag_mass) const
  {
    return !arrays.contact_impulse.empty() &&
           arrays.contact_impulse[i].norm() > 0 &&
           arrays.contact.velocity[i].norm() * drag_mass <=
             parameters.resting_threshold * arrays.contact_impulse[i].norm();
  }


  template <int dim>
  void
  Coupling<dim>::prepare_fluid_drag(const Grains<dim>      &grains,
                                    const FluidSolver<dim> &fluid,
                                    const double            dt,
                                    const double            previous_dt)
  {
    dealii::TimerOutput::Scope scope(timer, "coupling: interaction force");
    auto                      &arrays = grains.step_arrays();
    const auto                &c      = arrays.contact;
    const unsigned int         n      = c.velocity.size();
    // Repaid over a step as short as a run's last sliver, the whole debt
    // of a long step would be a force many times the drag (a Stokes fluid
    // answers it at once): a shorter step repays its share, the rest waits.
    repaid_share = (previous_dt > dt ? dt / previous_dt : 1.0);
    lagged_force.assign(n, dealii::Tensor<1, dim>());
    gamma.assign(n, 0.0);
    self_velocity.assign(n, dealii::Tensor<1, dim>());
    predicted_impulse.assign(arrays.predicted_impulse.size(),
                             dealii::Tensor<1, dim>());
    cell_drags.assign(triangulation.n_active_cells(), {});
    assumed_beta.assign(n, 0.0);
    assumed_pressure_weight.assign(n, 0.0);
    assumed_velocity.assign(n, dealii::Tensor<1, dim>());
    const bool repay = parameters.two_way && parameters.repay_drag_mismatch &&
                       !arrays.exchange_owed.empty();
    reynolds_max  = 0;
    felt_drag_sum = dealii::Tensor<1, dim>();
    // The filtered drag made implicit: the fluid feels beta_h u at each
    // point, the grains the filtered velocity. For free grains it is taken
    // against the last step's velocity, beta_h (u - u^n), with their drags
    // spread less what they felt of u^n: the fluid receives at each point
    // what the grains' drags spread back, up to the step's change. Taken
    // whole, it received about -2 beta_h l^2 lap u more, a viscosity
    // 2 phi_s rho_p l^2 / (dt + tau_p) that slowed a 3D cloud by 18-35 %
    // (doc/theory.md, "Drag distributions"). Not for fixed and held
    // grains: their full gamma would make the explicit rest converge over
    // tens of steps (a packed bed's pressure drop drifted 1 Pa per step).
    const bool against_last =
      drag_as_field() && parameters.two_way && parameters.implicit_coupling;

    // The fluid solution has not changed since set_grain_forces() filtered
    // it, except before the first step or after a mesh change.
    if (drag_as_field() && !filtered_velocity_current)
      filtered_drag->filter_fluid(fluid.get_dof_handler(),
                                  fluid.get_cell_gather(),
                                  fluid.get_solution(),
                                  true,
                                  false);
    filtered_velocity_current = true;
    const bool implicit_velocity =
      parameters.two_way && parameters.implicit_coupling;
    // Values at the grains' centres: the felt velocity unless filtered,
    // the lagged pressure gradient unless implicit.
    const bool at_centres             = !drag_as_field() || !implicit_velocity;
    const dealii::Tensor<1, dim>    g = grain_parameters.gravity;
    std::vector<dealii::Point<dim>> references;
    for_each_cell_batch<dim>(
      grains.particle_handler(),
      references,
      [&](const auto &cell, const unsigned int first, const unsigned int end)
      {
        const auto fluid_values =
          at_centres ? fluid.point_values(cell, references) :
                       decltype(fluid.point_values(cell, references))();
        const auto                felt = drag_as_field() ?
                                           filtered_drag->filtered_velocity(cell, references) :
                                           velocities_of(fluid_values);
        const std::vector<double> felt_fraction =
          projection->felt_fluid_fraction(cell, references);
        const std::vector<double> mean_diameter =
          projection->mean_diameter(cell, references);
        const std::vector<double> scale =
          implicit_velocity ? std::vector<double>() :
                              projection->solid_scale(cell, references);
        for (unsigned int i = first; i < end; ++i)
        {
          const unsigned int k = i - first;
          const double       r = c.radius[i], m = arrays.mass[i];
          const double       V = grain_volume<dim>(r);
          // The seed's interaction force without drag: gravity minus
          // buoyancy (m g comes from Grains) and the dynamic pressure.
          lagged_force[i] = -density * V * g;
          if (!implicit_velocity)
            lagged_force[i] -= (scale.empty() ? 1.0 : scale[k]) * V *
                               fluid_values[k].pressure_gradient;
          const GrainDrag drag_of_grain =
            grain_drag(cell,
                       references[k],
                       arrays,
                       i,
                       felt_fraction[k],
                       felt[k],
                       mean_diameter.empty() ? 0.0 : mean_diameter[k],
                       dt,
                       false);
          gamma[i]        = drag_of_grain.gamma;
          const bool held = drag_of_grain.held;
          if (!predicted_impulse.empty())
          {
            // Grains that collide and part in turn get impulses that flip
            // from step to step; told the last one alone, the fluid pushes
            // them apart when they have parted and not when they collide,
            // and the two alternate (a response of -r times the prediction
            // makes the error's step factor -r). Relaxed with w, the factor
            // is 1 - w (1 + r): stable for r < 2 / w - 1, none left at
            // r = 1 / w - 1 (doc/theory.md).
            const double w       = parameters.impulse_prediction_weight;
            predicted_impulse[i] = w * arrays.contact_impulse[i] +
                                   (1 - w) * arrays.predicted_impulse[i];
          }
          const dealii::Tensor<1, dim> self = drag_of_grain.self;
          self_velocity[i]                  = self;
          reynolds_max = std::max(reynolds_max, drag_of_grain.reynolds);

          // The drag the fluid sees after eliminating the grain's implicit
          // update (a fixed grain is infinitely heavy: full gamma, v = 0).
          PointDrag<dim> drag;
          drag.reference_location = references[k];
          // A grain held by its contacts (it kept almost none of the
          // velocity they removed last step, P / (m + dt gamma) with the
          // drag-augmented mass they acted on) stays where they hold it:
          // the fluid sees it move at its velocity, as a fixed grain,
          // instead of eliminating an update whose contact impulse it
          // could only guess. Predicted with that guess, a packed bed and
          // the fluid pass its weight back and forth and diverge once the
          // step exceeds the bed's relaxation time.
          if (arrays.fixed[i])
          {
            drag.beta     = gamma[i];
            drag.velocity = 0;
          }
          else if (held)
          {
            drag.beta     = gamma[i];
            drag.velocity = c.velocity[i];
          }
          else
          {
            drag.beta     = gamma[i] * m / (m + dt * gamma[i]);
            drag.velocity = c.velocity[i] + dt / m * (m * g + lagged_force[i]);
            // The grain's update will add its contact impulse P / m to
            // this; the last steps' P predict it, so that grains resting
            // on each other (P = -dt m g') leave the fluid undisturbed.
            if (!predicted_impulse.empty())
              drag.velocity += predicted_impulse[i] / m;
            if (implicit_velocity)
            {
              // The grain's new velocity is (m v~ + dt gamma (u - u_self)
              // - dt V grad p) / (m + dt gamma): theta of it follows the
              // fluid.
              const double theta     = dt * gamma[i] / (m + dt * gamma[i]);
              drag.pressure_weight   = V * theta;
              drag.pressure_mobility = dt * V * V / (m + dt * gamma[i]);
              drag.free_flux = V * ((1 - theta) * drag.velocity - theta * self);
            }
            // It pulls towards u - u_self: the fluid sees it at v~ + u_self.
            drag.velocity += self;
          }
          assumed_beta[i]            = drag.beta;
          assumed_pressure_weight[i] = drag.pressure_weight;
          assumed_velocity[i]        = drag.velocity;
          // The predicted contact impulse is the prediction's to repay
          // (settle_exchange_owed()): owed is what the sub-steps leave.
          if (!arrays.fixed[i] && !held && !predicted_impulse.empty())
            assumed_velocity[i] -= predicted_impulse[i] / m;
          // What the fluid owes the grain from the last step, as a force
          // over this one: -beta (u - v) - owed / dt.
          if (repay && drag.beta > 0)
            drag.velocity -=
              repaid_share * arrays.exchange_owed[i] / (drag.beta * dt);
          if (against_last && !arrays.fixed[i] && !held)
          {
            drag.velocity -= felt[k];
            drag.against_last_velocity = true;
            felt_drag_sum += drag.beta * felt[k];
          }
          cell_drags[cell->active_cell_index()].push_back(drag);
        }
      });
    reynolds_max =
      dealii::Utilities::MPI::max(reynolds_max,
                                  triangulation.get_communicator());
    felt_drag_sum =
      dealii::Utilities::MPI::sum(felt_drag_sum,
                                  triangulation.get_communicator());
    if (filtered_drag)
      filtered_drag->spread(
        [&](const auto &cell, std::vector<PointDrag<dim>> &drags)
        { drags = cell_drags[cell->active_cell_index()]; });
  }


  template <int dim>
  void
  Coupling<dim>::set_grain_forces(Grains<dim>            &grains,
                                  const FluidSolver<dim> &fluid,
                                  const double            dt)
  {
    set_hooks(grains, fluid, dt, true);
  }


  template <int dim>
  void
  Coupling<dim>::set_substep_grain_forces(Grains<dim>            &grains,
                                          const FluidSolver<dim> &fluid,
                                          const double            dt)
  {
    set_hooks(grains, fluid, dt, false);
  }


  template <int dim>
  void
  Coupling<dim>::set_hooks(Grains<dim>            &grains,
                           const FluidSolver<dim> &fluid,
                           const double            dt,
                           const bool              as_predicted)
  {
    dealii::TimerOutput::Scope scope(timer, "coupling: interaction force");
    auto                      &arrays = grains.step_arrays();
    const auto                &c      = arrays.contact;
    const unsigned int         n      = c.velocity.size();
    arrays.external_force.resize(n);
    arrays.drag_coefficient.resize(n);
    arrays.drag_velocity.resize(n);

    const bool implicit_velocity =
      parameters.two_way && parameters.implicit_coupling;
    // The grains feel the pressure gradient the fluid solve eliminated
    // into alpha_h grad p and k_h grad p: spread by the filter, so the
    // gradient they take is its adjoint, filtered with every distribution
    // (sum_i V_i theta_i grad p_i = (alpha_h, grad p)). Taken at their
    // centres, the books of a 2D cloud with the cell spread drifted by 2 %.
    // A later sub-step sees the same fluid: its filtered fields stand.
    if (as_predicted && (drag_as_field() || implicit_velocity))
      filtered_drag->filter_fluid(fluid.get_dof_handler(),
                                  fluid.get_cell_gather(),
                                  fluid.get_solution(),
                                  drag_as_field(),
                                  implicit_velocity,
                                  solid_scale());
    filtered_velocity_current = true;
    if (as_predicted)
      for (unsigned int i = 0; i < predicted_impulse.size(); ++i)
        arrays.predicted_impulse[i] = predicted_impulse[i];
    if (!as_predicted)
    {
      // The grains moved and were re-sorted since prepare_fluid_drag():
      // gamma and the force without drag, again, grain by grain.
      gamma.assign(n, 0.0);
      lagged_force.assign(n, dealii::Tensor<1, dim>());
    }
    const dealii::Tensor<1, dim>    g = grain_parameters.gravity;
    std::vector<dealii::Point<dim>> references;
    for_each_cell_batch<dim>(
      grains.particle_handler(),
      references,
      [&](const auto &cell, const unsigned int first, const unsigned int end)
      {
        // The felt velocity and the new pressure gradient, as the fluid
        // solve assumed: the adjoint of how it was spread, filtered with
        // the drag as a field and the pressure gradient with the implicit
        // coupling; else at the centre (the lagged gradient of explicit
        // sub-steps).
        std::vector<dealii::Tensor<1, dim>> felt, pressure_gradient;
        if (drag_as_field())
          felt = filtered_drag->filtered_velocity(cell, references);
        if (implicit_velocity)
          pressure_gradient =
            filtered_drag->filtered_pressure_gradient(cell, references);
        if (!drag_as_field() || (!implicit_velocity && !as_predicted))
        {
          for (const auto &v : fluid.point_values(cell, references))
          {
            if (!drag_as_field())
              felt.push_back(v.velocity);
            if (!implicit_velocity)
              pressure_gradient.push_back(v.pressure_gradient);
          }
          const auto scale = implicit_velocity ?
                               std::vector<double>() :
                               projection->solid_scale(cell, references);
          for (unsigned int k = 0; k < scale.size(); ++k)
            pressure_gradient[k] *= scale[k];
        }
        const std::vector<double> felt_fraction =
          as_predicted ? std::vector<double>() :
                         projection->felt_fluid_fraction(cell, references);
        const std::vector<double> mean_diameter =
          as_predicted ? std::vector<double>() :
                         projection->mean_diameter(cell, references);
        for (unsigned int i = first; i < end; ++i)
        {
          const unsigned int k    = i - first;
          const auto        &u    = felt[k];
          arrays.drag_velocity[i] = u;
          // The fluid's step assumed this drag impulse; the grain's own
          // (sub-)steps add theirs (account_drag_on_grains()).
          if (as_predicted && parameters.two_way &&
              !arrays.exchange_owed.empty())
          {
            // With the grains' new velocities eliminated into the fluid
            // solve, the fluid received alpha grad p as well (alpha = V
            // theta, the share of the pressure force the drag takes back).
            dealii::Tensor<1, dim> assumed =
              assumed_beta[i] * (u - assumed_velocity[i]);
            if (assumed_pressure_weight[i] > 0)
              assumed += assumed_pressure_weight[i] * pressure_gradient[k];
            // What this step did not repay stays owed.
            const double kept = !parameters.repay_drag_mismatch ? 0.0 :
                                assumed_beta[i] > 0 ? 1 - repaid_share :
                                                      1.0;
            arrays.exchange_owed[i] =
              kept * arrays.exchange_owed[i] - dt * assumed;
          }
          if (as_predicted && !arrays.self_velocity.empty())
          {
            arrays.drag_velocity[i] -= self_velocity[i];
            arrays.self_velocity[i] = self_velocity[i];
          }
          if (parameters.tracers)
          {
            // The limit gamma -> infinity of the implicit update: v' = u to
            // twelve digits, gravity cancelled.
            arrays.external_force[i]   = -arrays.mass[i] * g;
            arrays.drag_coefficient[i] = 1e12 * arrays.mass[i] / dt;
            continue;
          }
          const double V = grain_volume<dim>(c.radius[i]);
          if (!as_predicted)
          {
            const GrainDrag drag_of_grain =
              grain_drag(cell,
                         references[k],
                         arrays,
                         i,
                         felt_fraction[k],
                         u,
                         mean_diameter.empty() ? 0.0 : mean_diameter[k],
                         dt,
                         true);
            gamma[i]                          = drag_of_grain.gamma;
            const dealii::Tensor<1, dim> self = drag_of_grain.self;
            arrays.drag_velocity[i] -= self;
            if (!arrays.self_velocity.empty())
              arrays.self_velocity[i] = self;
            lagged_force[i] = -density * V * g;
          }
          arrays.external_force[i] = lagged_force[i];
          // The pressure gradient of this step: in the lagged force of the
          // predicted step unless implicit; in every later sub-step.
          if (implicit_velocity || !as_predicted)
            arrays.external_force[i] -= V * pressure_gradient[k];
          arrays.drag_coefficient[i] = gamma[i];
        }
      });
  }


  template <int dim>
  void
  Coupling<dim>::point_drags(
    const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
    std::vector<PointDrag<dim>> &drags) const
  {
    if (cell->active_cell_index() < cell_drags.size())
      drags = cell_drags[cell->active_cell_index()];
  }


  template <int dim>
  dealii::Tensor<1, dim>
  Coupling<dim>::drag_on_fluid(const Grains<dim>      &grains,
                               const FluidSolver<dim> &fluid) const
  {
    const MPI_Comm         comm = triangulation.get_communicator();
    dealii::Tensor<1, dim> on_fluid;
    if (!parameters.two_way)
      return on_fluid;
    if (filtered_drag)
      on_fluid = filtered_drag->force_on_fluid(fluid.get_dof_handler(),
                                               fluid.get_cell_gather(),
                                               fluid.get_solution(),
                                               solid_scale()) +
                 felt_drag_sum;
    if (!drag_as_field())
    {
      // The point drags through the fluid velocity the grains felt.
      dealii::Tensor<1, dim>          point_force;
      std::vector<dealii::Point<dim>> references;
      for_each_cell_batch<dim>(
        grains.particle_handler(),
        references,
        [&](const auto &cell, const unsigned int, const unsigned int)
        {
          const auto  felt  = felt_velocity(fluid, cell, references);
          const auto &drags = cell_drags[cell->active_cell_index()];
          for (unsigned int k = 0; k < drags.size(); ++k)
            point_force -= drags[k].beta * (felt[k] - drags[k].velocity);
        });
      on_fluid += dealii::Utilities::MPI::sum(point_force, comm);
    }
    return on_fluid;
  }


  template <int dim>
  dealii::Tensor<1, dim>
  Coupling<dim>::account_drag_on_grains(Grains<dim> &grains,
                                        const double substep) const
  {
    dealii::Tensor<1, dim> on_grains;
    if (!parameters.two_way)
      return on_grains;
    // The drag in the grains' implicit update, with their final velocity.
    auto      &arrays = grains.step_arrays();
    const bool owed   = !arrays.exchange_owed.empty();
    for (unsigned int i = 0; i < arrays.drag_coefficient.size(); ++i)
    {
      const dealii::Tensor<1, dim> drag =
        arrays.drag_coefficient[i] *
        (arrays.drag_velocity[i] - arrays.contact.velocity[i]);
      on_grains += drag;
      if (owed)
        arrays.exchange_owed[i] += substep * drag;
    }
    return dealii::Utilities::MPI::sum(on_grains,
                                       triangulation.get_communicator());
  }


  template <int dim>
  dealii::Tensor<1, dim>
  Coupling<dim>::settle_exchange_owed(Grains<dim> &grains) const
  {
    auto                  &arrays = grains.step_arrays();
    dealii::Tensor<1, dim> owed;
    for (unsigned int i = 0; i < arrays.exchange_owed.size(); ++i)
    {
      if (!arrays.contact_impulse.empty() &&
          arrays.contact_impulse[i].norm() > 0)
        arrays.exchange_owed[i] = dealii::Tensor<1, dim>();
      owed += arrays.exchange_owed[i];
    }
    return dealii::Utilities::MPI::sum(owed, triangulation.get_communicator());
  }


  template <int dim>
  double
  Coupling<dim>::solid_volume() const
  {
    return projection->integral();
  }


  template <int dim>
  double
  Coupling<dim>::removed_since_projection(const Grains<dim> &grains) const
  {
    return grains.removed_volume() - removed_volume_at_projection +
           departed_in_projection;
  }


  template <int dim>
  double
  Coupling<dim>::fluid_volume() const
  {
    return projection->fluid_volume();
  }


  template <int dim>
  double
  Coupling<dim>::max_reynolds() const
  {
    return reynolds_max;
  }


  template <int dim>
  const SolidFraction<dim> &
  Coupling<dim>::solid_fraction() const
  {
    return *projection;
  }


  template class Coupling<2>;
  template class Coupling<3>;
} // namespace ImmersedGrains
