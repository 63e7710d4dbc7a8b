#include <deal.II/base/exceptions.h>

#include <immersed_grains/coupling/drag_law.h>

namespace ImmersedGrains
{
  namespace
  {
    struct Entry
    {
      std::string      description;
      DragLaw::Factory factory;
    };

    // A function-local static: laws register during static initialisation
    // of their own translation units, in no guaranteed order.
    std::map<std::string, Entry> &
    registry()
    {
      static std::map<std::string, Entry> laws;
      return laws;
    }
  } // namespace


  double
  DragLaw::reynolds(const DragInput &in)
  {
    return 2 * in.radius * in.density * in.slip_speed * in.fluid_fraction /
           in.viscosity;
  }


  bool
  DragLaw::register_law(const std::string &name,
                        const std::string &description,
                        Factory            factory)
  {
    registry()[name] = {description, std::move(factory)};
    return true;
  }


  std::string
  DragLaw::names()
  {
    std::string all;
    for (const auto &[name, entry] : registry())
      all += (all.empty() ? "" : "|") + name;
    return all;
  }


  std::map<std::string, std::string>
  DragLaw::descriptions()
  {
    std::map<std::string, std::string> d;
    for (const auto &[name, entry] : registry())
      d[name] = entry.description;
    return d;
  }


  std::unique_ptr<DragLaw>
  DragLaw::create(const std::string &name)
  {
    const auto it = registry().find(name);
    AssertThrow(it != registry().end(),
                dealii::ExcMessage("Unknown drag law '" + name +
                                   "'; known: " + names()));
    return it->second.factory();
  }
} // namespace ImmersedGrains
