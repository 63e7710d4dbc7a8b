#include <deal.II/base/exceptions.h>

#include <immersed_grains/io/statistics.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <string>
#include <vector>

namespace ImmersedGrains
{
  namespace
  {
    std::vector<std::string>
    split_row(const std::string &line)
    {
      std::vector<std::string> cells;
      std::string::size_type   start = 0;
      for (;;)
      {
        const auto comma = line.find(',', start);
        cells.push_back(line.substr(start, comma - start));
        if (comma == std::string::npos)
          return cells;
        start = comma + 1;
      }
    }
  } // namespace


  Statistics::Statistics(std::vector<std::string> columns)
      : columns(std::move(columns))
  {
    for (const auto &c : this->columns)
      values[c] = 0;
  }


  void
  Statistics::add_columns(const std::vector<std::string> &names)
  {
    for (const auto &c : names)
      if (values.count(c) == 0)
      {
        columns.push_back(c);
        values[c] = 0;
      }
  }


  void
  Statistics::open(const std::string &file_name,
                   const bool         is_root,
                   const int          keep_through_step)
  {
    if (!is_root)
      return;
    if (keep_through_step >= 0)
    {
      // A resumed run keeps the rows up to its checkpoint's step. They are
      // written to a new file that replaces the old one when complete: a
      // run killed meanwhile leaves the old rows, not a truncated file.
      const std::string part = file_name + ".part";
      {
        std::ifstream old(file_name);
        std::ofstream kept(part);
        std::string   line;
        // The old header: its rows are written in this table's column
        // order, which a file of another version may not share (a column
        // it lacks is left empty).
        std::getline(old, line);
        const std::vector<std::string> old_columns = split_row(line);
        std::vector<int>               source(columns.size(), -1);
        for (unsigned int i = 0; i < columns.size(); ++i)
          for (unsigned int k = 0; k < old_columns.size(); ++k)
            if (old_columns[k] == columns[i])
              source[i] = k;
        for (unsigned int i = 0; i < columns.size(); ++i)
          kept << (i ? "," : "") << columns[i];
        kept << '\n';
        while (std::getline(old, line))
          if (!line.empty() && std::stod(line) <= keep_through_step)
          {
            const std::vector<std::string> cells = split_row(line);
            for (unsigned int i = 0; i < columns.size(); ++i)
              kept << (i ? "," : "")
                   << (source[i] >= 0 && source[i] < int(cells.size()) ?
                         cells[source[i]] :
                         std::string());
            kept << '\n';
          }
        AssertThrow(kept, dealii::ExcMessage("Cannot write " + part));
      }
      std::filesystem::rename(part, file_name);
      file.open(file_name, std::ios::app);
      AssertThrow(file, dealii::ExcMessage("Cannot write " + file_name));
      return;
    }
    file.open(file_name);
    AssertThrow(file, dealii::ExcMessage("Cannot write " + file_name));
    for (unsigned int i = 0; i < columns.size(); ++i)
      file << (i ? "," : "") << columns[i];
    file << '\n';
    file.flush();
  }


  void
  Statistics::set(const std::string &column, const double value)
  {
    auto it = values.find(column);
    Assert(it != values.end(), dealii::ExcMessage("No column " + column));
    it->second = value;
  }


  double
  Statistics::get(const std::string &column) const
  {
    const auto it = values.find(column);
    Assert(it != values.end(), dealii::ExcMessage("No column " + column));
    return it->second;
  }


  bool
  Statistics::has(const std::string &column) const
  {
    return values.count(column) > 0;
  }


  void
  Statistics::save_values(std::ostream &out) const
  {
    out << std::hexfloat;
    for (const auto &[name, value] : values)
      out << name << ' ' << value << '\n';
    out << std::defaultfloat;
  }


  void
  Statistics::load_values(std::istream &in)
  {
    std::string name, value;
    while (in >> name >> value)
    {
      const auto it = values.find(name);
      if (it != values.end())
        it->second = std::strtod(value.c_str(), nullptr);
    }
  }


  void
  Statistics::write_row()
  {
    if (!file.is_open())
      return;
    file << std::setprecision(12);
    for (unsigned int i = 0; i < columns.size(); ++i)
      file << (i ? "," : "") << values[columns[i]];
    file << '\n';
    file.flush();
  }


  void
  Statistics::print(std::ostream                   &out,
                    const std::vector<std::string> &selected) const
  {
    out << std::setprecision(6);
    for (unsigned int i = 0; i < selected.size(); ++i)
    {
      double v = get(selected[i]);
      // Round-off around zero is not a difference between machines.
      if (std::abs(v) < 1e-300)
        v = 0;
      out << (i ? " " : "") << selected[i] << "=" << v;
    }
    out << std::endl;
  }


  const std::vector<std::string> &
  Statistics::column_names() const
  {
    return columns;
  }
} // namespace ImmersedGrains
