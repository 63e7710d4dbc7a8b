#ifndef immersed_grains_parameters_h
#define immersed_grains_parameters_h

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/point.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace ImmersedGrains
{
  /**
   * A mistake in the user's input. Its message is one line that names the
   * file, the parameter and the offending value; main() prints it and exits
   * with a non-zero status before anything is written.
   */
  class InputError : public std::runtime_error
  {
  public:
    InputError(const std::string &file,
               const std::string &parameter,
               const std::string &value,
               const std::string &problem);
  };

  /**
   * Where in the input a value comes from, so that checks made after
   * parsing can still name the file and the full parameter path.
   */
  struct InputLocation
  {
    std::string file;
    std::string section; // e.g. "Mesh" or "Grains/Placement"

    [[noreturn]] void
    fail(const std::string &parameter,
         const std::string &value,
         const std::string &problem) const;

    void
    require(bool               condition,
            const std::string &parameter,
            const std::string &value,
            const std::string &problem) const;
  };

  /**
   * Reads `set Dimension = ...` from the top level of a parameter file
   * without declaring anything else: the dimension decides which
   * Simulation<dim> declares the rest.
   */
  unsigned int
  read_dimension(const std::string &file);

  /**
   * Parses the whole file into @p prm; any deal.II parse error (unknown
   * entry, malformed value, value out of range) becomes an InputError.
   */
  /** The entries @p file sets, as "Section/Subsection/Name" (the file's
   *  spelling; ParameterHandler checked them). */
  std::vector<std::string>
  entries_set_in(const std::string &file);

  void
  parse_parameter_file(dealii::ParameterHandler &prm, const std::string &file);

  /** Collapse a multi-line message into one line of single spaces. */
  std::string
  one_line(const std::string &text);

  /** Whether @p text is one number and nothing else but spaces; if so,
   *  its value goes to @p value. */
  bool
  parse_number(const std::string &text, double &value);

  /** Parse "a, b, c" into doubles, requiring @p n entries (0: any). */
  std::vector<double>
  parse_double_list(const std::string   &text,
                    const InputLocation &where,
                    const std::string   &parameter,
                    unsigned int         n = 0);

  /** Parse "x,y[,z]" into a point of dimension dim. */
  template <int dim>
  dealii::Point<dim>
  parse_point(const std::string   &text,
              const InputLocation &where,
              const std::string   &parameter);

  /** Parse "x,y; x,y; ..." into points (empty text gives none). */
  template <int dim>
  std::vector<dealii::Point<dim>>
  parse_point_list(const std::string   &text,
                   const InputLocation &where,
                   const std::string   &parameter);
} // namespace ImmersedGrains

#endif
