#ifndef immersed_grains_tests_command_line_in_child_h
#define immersed_grains_tests_command_line_in_child_h

// Runs the executable's command line (ImmersedGrains::run_command_line(),
// all that source/main.cc calls) in a forked child of the test, its standard
// output and error written to files: the process a start of the executable
// would make, without loading deal.II's two hundred libraries again (half a
// second of the dynamic linker's symbol lookups per start). The child
// starts MPI as a singleton, so the test itself must not initialise MPI.

#include <immersed_grains/command_line.h>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

// The exit status of `immersed-grains ARGS > OUT 2> ERR` (ERR the same file
// as OUT for 2>&1), or -1 where the child ended by a signal.
inline int
run_command_line_in_child(const std::vector<std::string> &args,
                          const std::string              &out,
                          const std::string              &err)
{
  // What the test has buffered would otherwise be written twice.
  std::cout.flush();
  std::cerr.flush();
  std::fflush(nullptr);
  const pid_t child = fork();
  if (child == 0)
  {
    const int out_fd = open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err_fd =
      (err == out ? out_fd :
                    open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644));
    if (out_fd < 0 || err_fd < 0)
      _exit(127);
    dup2(out_fd, STDOUT_FILENO);
    dup2(err_fd, STDERR_FILENO);
    std::vector<std::string> words = {"immersed-grains"};
    words.insert(words.end(), args.begin(), args.end());
    std::vector<char *> argv;
    for (std::string &w : words)
      argv.push_back(w.data());
    argv.push_back(nullptr);
    const int status =
      ImmersedGrains::run_command_line(argv.size() - 1, argv.data());
    std::cout.flush();
    std::cerr.flush();
    std::fflush(nullptr);
    _exit(status);
  }
  int status = 0;
  if (child < 0 || waitpid(child, &status, 0) != child)
    return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

#endif
