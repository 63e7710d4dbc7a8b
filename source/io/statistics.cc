#include <deal.II/base/exceptions.h>

#include <immersed_grains/io/statistics.h>

#include <cmath>
#include <iomanip>

namespace ImmersedGrains
{
  Statistics::Statistics(std::vector<std::string> columns)
      : columns(std::move(columns))
  {
    for (const auto &c : this->columns)
      values[c] = 0;
  }


  void
  Statistics::open(const std::string &file_name, const bool is_root)
  {
    if (!is_root)
      return;
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
