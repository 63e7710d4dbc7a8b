#include <deal.II/base/utilities.h>

#include <immersed_grains/io/test_checks.h>

#include <sstream>
#include <utility>

namespace ImmersedGrains
{
  void
  TestCheck::record(const Statistics &statistics)
  {
    if (extreme == 0)
      return;
    const double v = statistics.get(column);
    if (!recorded || (extreme == '+' ? v > extreme_value : v < extreme_value))
      extreme_value = v;
    recorded = true;
  }


  double
  TestCheck::value(const Statistics &statistics) const
  {
    if (extreme == 0 || !recorded)
      return statistics.get(column);
    return extreme_value;
  }


  bool
  TestCheck::holds(const Statistics &statistics) const
  {
    const double v = value(statistics);
    switch (relation)
    {
      case '<':
        return v < upper;
      case '>':
        return v > lower;
      default:
        return v >= lower && v <= upper;
    }
  }


  std::vector<TestCheck>
  parse_test_checks(const std::string   &text,
                    const Statistics    &statistics,
                    const InputLocation &where,
                    const std::string   &parameter)
  {
    std::vector<TestCheck> checks;
    for (const std::string &entry :
         dealii::Utilities::split_string_list(text, ';'))
    {
      if (entry.empty())
        continue;
      std::istringstream in(entry);
      TestCheck          c;
      std::string        relation;
      in >> c.column >> relation;
      c.text = entry;
      for (const auto &[name, sign] :
           {std::pair<std::string, char>{"max(", '+'},
            std::pair<std::string, char>{"min(", '-'}})
        if (c.column.size() > name.size() + 1 &&
            c.column.compare(0, name.size(), name) == 0 &&
            c.column.back() == ')')
        {
          c.column =
            c.column.substr(name.size(), c.column.size() - name.size() - 1);
          c.extreme = sign;
        }
      where.require(statistics.has(c.column),
                    parameter,
                    text,
                    "no statistics column named '" + c.column + "'");
      bool ok = false;
      if (relation == "<" || relation == ">")
      {
        double v;
        ok         = bool(in >> v);
        c.relation = relation[0];
        c.lower = c.upper = v;
      }
      else if (relation == "in")
      {
        // "in [a, b]"
        std::string rest;
        std::getline(in, rest);
        for (char &ch : rest)
          if (ch == '[' || ch == ']' || ch == ',')
            ch = ' ';
        std::istringstream range(rest);
        ok         = bool(range >> c.lower >> c.upper) && c.lower <= c.upper;
        c.relation = 'i';
      }
      where.require(ok,
                    parameter,
                    text,
                    "'" + entry +
                      "' is not 'column < v', 'column > v' or 'column in "
                      "[a, b]', column a name or max(name) or min(name)");
      checks.push_back(c);
    }
    return checks;
  }


  void
  print_test_checks(std::ostream                 &out,
                    const std::vector<TestCheck> &checks,
                    const Statistics             &statistics)
  {
    for (const TestCheck &c : checks)
    {
      out << "check " << c.text << ": ";
      if (c.holds(statistics))
        out << "yes\n";
      else
        out << "no (value " << c.value(statistics) << ")\n";
    }
    out.flush();
  }
} // namespace ImmersedGrains
