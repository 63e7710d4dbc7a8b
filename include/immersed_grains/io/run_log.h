#ifndef immersed_grains_io_run_log_h
#define immersed_grains_io_run_log_h

#include <fstream>
#include <ostream>
#include <streambuf>
#include <string>

namespace ImmersedGrains
{
  /**
   * The run's narrative (what is solved, mesh, DoFs, timings): on rank 0 it
   * goes to log.txt and, unless the terminal is kept for test output, to
   * the screen too. Other ranks write nothing.
   */
  class RunLog
  {
  public:
    RunLog();
    ~RunLog();

    /** Starts writing to @p file_name; @p echo also copies to stdout. */
    void
    open(const std::string &file_name,
         bool               is_root,
         bool               echo,
         bool               append = false);

    std::ostream &
    stream();

  private:
    class TeeBuffer : public std::streambuf
    {
    public:
      std::streambuf *first  = nullptr;
      std::streambuf *second = nullptr;

    protected:
      int
      overflow(int c) override;
      int
      sync() override;
    };

    std::ofstream file;
    TeeBuffer     buffer;
    std::ostream  out;
  };
} // namespace ImmersedGrains

#endif
