#include <deal.II/base/exceptions.h>
#include <deal.II/base/utilities.h>

#include <immersed_grains/parameters.h>

#include <cctype>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace ImmersedGrains
{
  std::string
  one_line(const std::string &text)
  {
    std::string result;
    bool        in_space = true;
    for (const char c : text)
    {
      if (std::isspace(static_cast<unsigned char>(c)))
      {
        if (!in_space)
          result += ' ';
        in_space = true;
      }
      else if (std::iscntrl(static_cast<unsigned char>(c)))
      {
        // A control character quoted from a damaged file would act on the
        // terminal: shown as its code instead.
        char code[8];
        std::snprintf(code,
                      sizeof(code),
                      "\\x%02x",
                      static_cast<unsigned int>(static_cast<unsigned char>(c)));
        result += code;
        in_space = false;
      }
      else
      {
        result += c;
        in_space = false;
      }
    }
    while (!result.empty() && result.back() == ' ')
      result.pop_back();
    return result;
  }


  InputError::InputError(const std::string &file,
                         const std::string &parameter,
                         const std::string &value,
                         const std::string &problem)
      : std::runtime_error(one_line(file + ": parameter '" + parameter +
                                    "' = '" + value + "': " + problem))
  {
  }


  void
  InputLocation::fail(const std::string &parameter,
                      const std::string &value,
                      const std::string &problem) const
  {
    throw InputError(file,
                     section.empty() ? parameter : section + "/" + parameter,
                     value,
                     problem);
  }


  void
  InputLocation::require(const bool         condition,
                         const std::string &parameter,
                         const std::string &value,
                         const std::string &problem) const
  {
    if (!condition)
      fail(parameter, value, problem);
  }


  namespace
  {
    // A "set" statement of a parameter file, found by a plain text scan
    // before (or beside) ParameterHandler: its subsections joined by '/',
    // its name and value as written.
    struct SetStatement
    {
      std::string path;
      std::string name;
      std::string value;
      bool        has_value;
    };

    std::vector<SetStatement>
    set_statements(const std::string &file)
    {
      std::ifstream in(file);
      if (!in)
        throw InputError(file,
                         "(file)",
                         file,
                         "cannot open the parameter file");
      std::vector<std::string>  path;
      std::vector<SetStatement> statements;
      std::string               line;
      while (std::getline(in, line))
      {
        const auto hash = line.find('#');
        if (hash != std::string::npos)
          line.erase(hash);
        std::istringstream words(line);
        std::string        first, rest;
        words >> first;
        std::getline(words, rest);
        if (first == "subsection")
          path.push_back(dealii::Utilities::trim(rest));
        else if (first == "end" && !path.empty())
          path.pop_back();
        else if (first == "set")
        {
          const auto   eq = rest.find('=');
          SetStatement statement;
          for (const auto &section : path)
            statement.path += (statement.path.empty() ? "" : "/") + section;
          statement.name      = dealii::Utilities::trim(rest.substr(0, eq));
          statement.has_value = eq != std::string::npos;
          if (statement.has_value)
            statement.value = dealii::Utilities::trim(rest.substr(eq + 1));
          statements.push_back(statement);
        }
      }
      return statements;
    }
  } // namespace


  unsigned int
  read_dimension(const std::string &file)
  {
    // Only the top level counts: a "set Dimension" inside a subsection
    // would be an error that ParameterHandler reports later.
    for (const auto &statement : set_statements(file))
      if (statement.path.empty() && statement.has_value &&
          statement.name == "Dimension")
      {
        if (statement.value == "2")
          return 2;
        if (statement.value == "3")
          return 3;
        throw InputError(file, "Dimension", statement.value, "must be 2 or 3");
      }
    return 2;
  }


  std::vector<std::string>
  entries_set_in(const std::string &file)
  {
    std::vector<std::string> entries;
    for (const auto &statement : set_statements(file))
      entries.push_back((statement.path.empty() ? "" : statement.path + "/") +
                        statement.name);
    return entries;
  }


  void
  parse_parameter_file(dealii::ParameterHandler &prm, const std::string &file)
  {
    std::ifstream in(file);
    if (!in)
      throw InputError(file, "(file)", file, "cannot open the parameter file");
    try
    {
      prm.parse_input(in, file);
    }
    catch (const dealii::ExceptionBase &e)
    {
      std::ostringstream info;
      e.print_info(info);
      throw std::runtime_error(one_line(file + ": " + info.str()));
    }
  }


  bool
  parse_number(const std::string &text, double &value)
  {
    std::istringstream in(text);
    std::string        trailing;
    return (in >> value) && !(in >> trailing);
  }


  std::vector<double>
  parse_double_list(const std::string   &text,
                    const InputLocation &where,
                    const std::string   &parameter,
                    const unsigned int   n)
  {
    std::vector<double> values;
    for (const std::string &entry : dealii::Utilities::split_string_list(text))
    {
      double v;
      if (!parse_number(entry, v))
        where.fail(parameter, text, "'" + entry + "' is not a number");
      values.push_back(v);
    }
    if (n != 0 && values.size() != n)
      where.fail(parameter,
                 text,
                 "expected " + std::to_string(n) + " comma-separated values");
    return values;
  }


  template <int dim>
  dealii::Point<dim>
  parse_point(const std::string   &text,
              const InputLocation &where,
              const std::string   &parameter)
  {
    const auto         values = parse_double_list(text, where, parameter, dim);
    dealii::Point<dim> p;
    for (unsigned int d = 0; d < dim; ++d)
      p[d] = values[d];
    return p;
  }


  template <int dim>
  std::vector<dealii::Point<dim>>
  parse_point_list(const std::string   &text,
                   const InputLocation &where,
                   const std::string   &parameter)
  {
    std::vector<dealii::Point<dim>> points;
    for (const std::string &entry :
         dealii::Utilities::split_string_list(text, ';'))
      if (!entry.empty())
        points.push_back(parse_point<dim>(entry, where, parameter));
    return points;
  }


  template dealii::Point<2>
  parse_point<2>(const std::string &,
                 const InputLocation &,
                 const std::string &);
  template dealii::Point<3>
  parse_point<3>(const std::string &,
                 const InputLocation &,
                 const std::string &);
  template std::vector<dealii::Point<2>>
  parse_point_list<2>(const std::string &,
                      const InputLocation &,
                      const std::string &);
  template std::vector<dealii::Point<3>>
  parse_point_list<3>(const std::string &,
                      const InputLocation &,
                      const std::string &);
} // namespace ImmersedGrains
