#include <deal.II/base/exceptions.h>

#include <immersed_grains/io/run_log.h>

#include <unistd.h>

#include <cstdlib>
#include <iostream>

namespace ImmersedGrains
{
  RunLog::RunLog()
      : out(&buffer)
      , detail_out(&detail_buffer)
  {
  }


  RunLog::~RunLog()
  {
    out.flush();
    detail_out.flush();
    if (progress_pending)
      std::cout << std::endl;
  }


  void
  RunLog::open(const std::string &file_name,
               const bool         is_root,
               const bool         echo,
               const bool         echo_details,
               const bool         append)
  {
    if (!is_root)
      return;
    file.open(file_name, append ? std::ios::app : std::ios::out);
    AssertThrow(file, dealii::ExcMessage("Cannot write " + file_name));
    // mpirun hands its ranks a pseudo-terminal whatever its own output
    // is (often a file): under an MPI launcher, a line at a time.
    const bool launched_by_mpi = std::getenv("OMPI_COMM_WORLD_SIZE") ||
                                 std::getenv("PMI_SIZE") ||
                                 std::getenv("PMIX_RANK");
    terminal             = echo && isatty(STDOUT_FILENO) && !launched_by_mpi;
    buffer.first         = file.rdbuf();
    buffer.second        = echo ? std::cout.rdbuf() : nullptr;
    detail_buffer.first  = file.rdbuf();
    detail_buffer.second = echo && echo_details ? std::cout.rdbuf() : nullptr;
    buffer.progress_pending        = &progress_pending;
    detail_buffer.progress_pending = &progress_pending;
  }


  std::ostream &
  RunLog::stream()
  {
    return out;
  }


  std::ostream &
  RunLog::details()
  {
    return detail_out;
  }


  void
  RunLog::progress(const std::string &line)
  {
    if (!buffer.second)
      return;
    out.flush();
    detail_out.flush();
    if (terminal)
    {
      // Back to the start of the line, the new text, the rest cleared.
      std::cout << '\r' << line << "\033[K" << std::flush;
      progress_pending = true;
    }
    else
      std::cout << line << std::endl;
  }


  int
  RunLog::TeeBuffer::overflow(const int c)
  {
    if (c == EOF)
      return !EOF;
    if (first)
      first->sputc(static_cast<char>(c));
    if (second)
    {
      if (progress_pending && *progress_pending)
      {
        second->sputc('\n');
        *progress_pending = false;
      }
      second->sputc(static_cast<char>(c));
    }
    return c;
  }


  int
  RunLog::TeeBuffer::sync()
  {
    if (first)
      first->pubsync();
    if (second)
      second->pubsync();
    return 0;
  }
} // namespace ImmersedGrains
