#ifndef immersed_grains_io_test_checks_h
#define immersed_grains_io_test_checks_h

#include <immersed_grains/io/statistics.h>
#include <immersed_grains/parameters.h>

#include <ostream>
#include <string>
#include <vector>

namespace ImmersedGrains
{
  /**
   * A condition on a statistics column at the end of a run, for test mode
   * (`subsection Output / set Test checks`): "column < value",
   * "column > value" or "column in [a, b]", where column may also be
   * "max(column)" or "min(column)", its extreme over the rows the run
   * wrote (a pressure's peak during a collapse, say). A test that prints
   * whether its checks hold, rather than the values, stays meaningful for
   * chaotic scenes (a pile, a run on several ranks) whose values differ in the
   * last digits between builds or rank counts.
   */
  struct TestCheck
  {
    std::string column;
    char        relation; // '<', '>' or 'i' (in [lower, upper])
    double      lower;
    double      upper;
    std::string text;
    /** 0 for the last row's value, else '+' (max) or '-' (min) over the
     *  rows recorded. */
    char   extreme = 0;
    double extreme_value;
    bool   recorded = false;

    /** Takes the row just written into the extreme. */
    void
    record(const Statistics &statistics);

    /** The value the condition is on. */
    double
    value(const Statistics &statistics) const;

    bool
    holds(const Statistics &statistics) const;
  };

  /** Parses checks separated by ';'; names the entry in an InputError. */
  std::vector<TestCheck>
  parse_test_checks(const std::string   &text,
                    const Statistics    &statistics,
                    const InputLocation &where,
                    const std::string   &parameter);

  /** One line per check: "check <text>: yes", or "no (value v)". */
  void
  print_test_checks(std::ostream                 &out,
                    const std::vector<TestCheck> &checks,
                    const Statistics             &statistics);
} // namespace ImmersedGrains

#endif
