#include <deal.II/base/exceptions.h>

#include <immersed_grains/io/run_log.h>

#include <iostream>

namespace ImmersedGrains
{
  RunLog::RunLog()
      : out(&buffer)
  {
  }


  RunLog::~RunLog()
  {
    out.flush();
  }


  void
  RunLog::open(const std::string &file_name,
               const bool         is_root,
               const bool         echo,
               const bool         append)
  {
    if (!is_root)
      return;
    file.open(file_name, append ? std::ios::app : std::ios::out);
    AssertThrow(file, dealii::ExcMessage("Cannot write " + file_name));
    buffer.first  = file.rdbuf();
    buffer.second = echo ? std::cout.rdbuf() : nullptr;
  }


  std::ostream &
  RunLog::stream()
  {
    return out;
  }


  int
  RunLog::TeeBuffer::overflow(const int c)
  {
    if (c == EOF)
      return !EOF;
    if (first)
      first->sputc(static_cast<char>(c));
    if (second)
      second->sputc(static_cast<char>(c));
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
