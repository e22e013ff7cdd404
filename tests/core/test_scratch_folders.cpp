// The tests' scratch folders (tests/test_paths.hpp) are removed when the test process ends,
// so that the suite leaves no simulated sequences behind on a shared disk (CI once failed on
// a full one), and kept when SCFLOAM_KEEP_TEST_SCRATCH=1 asks for them.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include "test_paths.hpp"

namespace {

// Runs a child process that makes a scratch folder with a file in it and ends normally
// (std::exit: static destructors run, as after a test's main). Returns the folder's path as
// the child reported it, or "" if the child failed.
std::string scratch_of_a_child_process(bool keep) {
  int fds[2];
  if (::pipe(fds) != 0) return "";
  std::fflush(stdout);  // the child's exit flushes copies of these buffers too
  std::fflush(stderr);
  const pid_t pid = ::fork();
  if (pid < 0) return "";
  if (pid == 0) {
    ::close(fds[0]);
    if (keep) ::setenv("SCFLOAM_KEEP_TEST_SCRATCH", "1", 1);
    else ::unsetenv("SCFLOAM_KEEP_TEST_SCRATCH");
    const auto dir = scfloam::test::scratch_dir("scratch_probe");
    std::ofstream(dir / "scan.bin") << "points";
    const std::string line = std::filesystem::exists(dir / "scan.bin") ? dir.string() : "";
    if (::write(fds[1], line.data(), line.size()) != static_cast<ssize_t>(line.size())) std::_Exit(3);
    ::close(fds[1]);
    std::exit(0);
  }
  ::close(fds[1]);
  std::string path;
  char buf[512];
  for (ssize_t n; (n = ::read(fds[0], buf, sizeof buf)) > 0;) path.append(buf, static_cast<std::size_t>(n));
  ::close(fds[0]);
  int status = 0;
  if (::waitpid(pid, &status, 0) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0) return "";
  return path;
}

}  // namespace

TEST(ScratchFolders, AreRemovedWhenTheTestProcessEnds) {
  const std::string dir = scratch_of_a_child_process(false);
  ASSERT_FALSE(dir.empty()) << "the child could not make its scratch folder";
  EXPECT_FALSE(std::filesystem::exists(dir)) << dir;
}

TEST(ScratchFolders, AreKeptWhenAskedFor) {
  const std::string dir = scratch_of_a_child_process(true);
  ASSERT_FALSE(dir.empty()) << "the child could not make its scratch folder";
  EXPECT_TRUE(std::filesystem::exists(std::filesystem::path(dir) / "scan.bin")) << dir;
  std::filesystem::remove_all(dir);
}
