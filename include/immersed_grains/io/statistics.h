#ifndef immersed_grains_io_statistics_h
#define immersed_grains_io_statistics_h

#include <fstream>
#include <map>
#include <ostream>
#include <string>
#include <vector>

namespace ImmersedGrains
{
  /**
   * The per-step table written to statistics.csv: a column order set once
   * (the core columns, step to wall_time, first, then those each object
   * declares: Simulation::statistics_columns() in
   * source/simulation/statistics.cc), one row per call to
   * write_row(). Only rank 0 writes; the row is flushed at once so that a
   * run that stops early still leaves its history.
   */
  class Statistics
  {
  public:
    explicit Statistics(std::vector<std::string> columns);

    /** Appends a scene's own columns (forces on its boundaries, its
     *  probes) after the declared ones; before open(). */
    void
    add_columns(const std::vector<std::string> &names);

    /** Opens DIR/statistics.csv and writes the header (rank 0 only).
     *  With @p keep_through_step >= 0 (a resumed run) the rows the file
     *  has up to that step are kept and new rows appended; later ones (of
     *  a run that went on past its last checkpoint) are dropped. */
    void
    open(const std::string &file_name,
         bool               is_root,
         int                keep_through_step = -1);

    /** Every column's current value, exactly. */
    void
    save_values(std::ostream &out) const;
    void
    load_values(std::istream &in);

    void
    set(const std::string &column, double value);

    double
    get(const std::string &column) const;

    bool
    has(const std::string &column) const;

    /** Writes the current values as one row and keeps them. */
    void
    write_row();

    /** Prints the chosen columns of the current row (test mode). */
    void
    print(std::ostream &out, const std::vector<std::string> &columns) const;

    const std::vector<std::string> &
    column_names() const;

  private:
    std::vector<std::string>      columns;
    std::map<std::string, double> values;
    std::ofstream                 file;
  };
} // namespace ImmersedGrains

#endif
