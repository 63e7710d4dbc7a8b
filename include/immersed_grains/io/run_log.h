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
   * the screen too. Details (a line per step, each mesh change) go to
   * log.txt, and to the screen only when asked for. A progress line is
   * rewritten in place on a terminal; elsewhere (a file, a pipe, CI) each
   * one is a line of its own. Other ranks write nothing.
   */
  class RunLog
  {
  public:
    RunLog();
    ~RunLog();

    /** Starts writing to @p file_name; @p echo also copies to stdout,
     *  @p echo_details the details too. */
    void
    open(const std::string &file_name,
         bool               is_root,
         bool               echo,
         bool               echo_details,
         bool               append = false);

    std::ostream &
    stream();

    /** Details: always in the file, on the screen if asked for. */
    std::ostream &
    details();

    /** Shows @p line as the progress line (screen only). */
    void
    progress(const std::string &line);

    /** Whether the screen is a terminal (and the progress line is
     *  rewritten in place). */
    bool
    on_terminal() const
    {
      return terminal;
    }

  private:
    class TeeBuffer : public std::streambuf
    {
    public:
      std::streambuf *first  = nullptr;
      std::streambuf *second = nullptr;
      /** Set while a progress line stands unfinished on the terminal:
       *  the next character for the screen starts a new line. */
      bool *progress_pending = nullptr;

    protected:
      int
      overflow(int c) override;
      int
      sync() override;
    };

    std::ofstream file;
    TeeBuffer     buffer;
    std::ostream  out;
    TeeBuffer     detail_buffer;
    std::ostream  detail_out;
    bool          terminal         = false;
    bool          progress_pending = false;
  };
} // namespace ImmersedGrains

#endif
