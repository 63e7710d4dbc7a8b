#include <immersed_grains/io/progress_line.h>
#include <immersed_grains/io/run_log.h>

#include <chrono>
#include <iomanip>
#include <sstream>

namespace ImmersedGrains
{
  double
  wall_clock()
  {
    return std::chrono::duration<double>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
  }


  ProgressLine::ProgressLine(RunLog      &log,
                             const double interval_seconds,
                             const bool   enabled)
      : log(log)
      , interval_seconds(interval_seconds)
      , enabled(enabled)
  {
  }


  void
  ProgressLine::start(const double wall_start_, const double start_time_)
  {
    wall_start = wall_start_;
    start_time = start_time_;
    last_wall  = wall_clock();
  }


  bool
  ProgressLine::due(const bool last)
  {
    if (!enabled)
      return false;
    const double wall     = wall_clock();
    const double interval = log.on_terminal() ? 0.25 : interval_seconds;
    if (!last && (interval <= 0 || wall - last_wall < interval))
      return false;
    if (last && !log.on_terminal() && wall - last_wall < 1)
      return false; // the last line written is recent enough
    last_wall = wall;
    return true;
  }


  void
  ProgressLine::print(const double       time,
                      const double       end_time,
                      const unsigned int step,
                      const std::string &details,
                      const bool         last)
  {
    const double       done    = time - start_time;
    const double       elapsed = last_wall - wall_start;
    std::ostringstream line;
    line << std::setprecision(3) << "t = " << time << " / " << end_time
         << " s, step " << step << details;
    line << std::fixed << std::setprecision(0) << ", wall " << elapsed << " s";
    if (!last && done > 0 && end_time > time)
      line << ", ETA " << elapsed * (end_time - time) / done << " s";
    log.progress(line.str());
  }
} // namespace ImmersedGrains
