#ifndef immersed_grains_scene_regime_h
#define immersed_grains_scene_regime_h

#include <string>
#include <vector>

namespace ImmersedGrains
{
  /**
   * What a scene is, in the numbers that decide which physics it needs and
   * how far the model's validation covers it (Simulation::regime()):
   * `immersed-grains --check` prints it, and a run logs its warnings once.
   */
  struct SceneRegime
  {
    /** "name: value (what it means)", one per line. */
    std::vector<std::string> lines;
    /** What is switched on or off, and why it matters here. */
    std::vector<std::string> switches;
    /** Choices outside the validated range, each with what to use
     *  instead (doc/validation.md). */
    std::vector<std::string> warnings;
  };
} // namespace ImmersedGrains

#endif
