#include "tests/support/process_runner.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <optional>

namespace cairn::testing {

ProcessResult RunProcess(const std::vector<std::string>& argv, const ProcessOptions& options) {
  ProcessResult result;
  int pipefd[2];
  if (pipe2(pipefd, O_CLOEXEC) != 0) return result;
  // Built before fork: the child of a multithreaded parent may only call async-signal-safe code.
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  std::vector<char*> envp;
  for (char** e = environ; *e != nullptr; ++e) envp.push_back(*e);
  for (const auto& e : options.env) envp.push_back(const_cast<char*>(e.c_str()));
  envp.push_back(nullptr);
  const pid_t pid = fork();
  if (pid == 0) {
    // The child must not inherit blocked signals from a test that blocked them.
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    dup2(pipefd[1], STDOUT_FILENO);
    dup2(pipefd[1], STDERR_FILENO);
    execve(args[0], args.data(), envp.data());
    _exit(127);
  }
  close(pipefd[1]);
  const auto start = std::chrono::steady_clock::now();
  bool signalled = false, signalled_again = false;
  size_t signalled_at_output = 0;
  std::optional<std::chrono::steady_clock::time_point> armed_at;
  char buf[4096];
  while (true) {
    pollfd p{pipefd[0], POLLIN, 0};
    const int r = poll(&p, 1, 20);
    if (r > 0) {
      const ssize_t n = read(pipefd[0], buf, sizeof(buf));
      if (n > 0) {
        result.output.append(buf, static_cast<size_t>(n));
      } else if (n == 0 || errno != EINTR) {
        break;  // the child closed its end: it is exiting
      }
    }
    const auto now = std::chrono::steady_clock::now();
    const auto elapsed = now - start;
    if (!armed_at && (options.signal_when_output_contains.empty() ||
                      result.output.find(options.signal_when_output_contains) != std::string::npos)) {
      armed_at = now;
    }
    if (!signalled && options.signal != 0 && armed_at && now - *armed_at >= options.signal_after) {
      kill(pid, options.signal);
      signalled = true;
      signalled_at_output = result.output.size();
    }
    if (signalled && !signalled_again && !options.signal_again_when_output_contains.empty() &&
        result.output.find(options.signal_again_when_output_contains, signalled_at_output) !=
            std::string::npos) {
      kill(pid, options.signal);
      signalled_again = true;
    }
    if (elapsed > options.timeout) {
      kill(pid, SIGKILL);
      result.timed_out = true;
      break;
    }
  }
  close(pipefd[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  if (WIFEXITED(status)) result.exit_code = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) result.term_signal = WTERMSIG(status);
  return result;
}

}  // namespace cairn::testing
