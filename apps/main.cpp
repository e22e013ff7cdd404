// `scfloam <command>`: the single entry point. Bad input gives "error: <file>: <problem>" on
// stderr and exit code 1; a malformed command line exits 2.
#include <algorithm>
#include <cstdio>
#include <exception>

#include "command_registry.hpp"
#include "scfloam/error.hpp"

namespace scfloam::cli {
std::vector<CommandEntry>& command_registry() {
  static std::vector<CommandEntry> registry;
  return registry;
}
}  // namespace scfloam::cli

int main(int argc, char** argv) {
  using namespace scfloam::cli;
  CLI::App app{"scfloam: LiDAR SLAM (Optimized-SC-F-LOAM): odometry, Scan Context loops, pose graph"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "scfloam 0.1.0");
  auto& registry = command_registry();
  std::sort(registry.begin(), registry.end(),
            [](const CommandEntry& a, const CommandEntry& b) { return a.name < b.name; });
  for (const auto& entry : registry) entry.add(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  } catch (const scfloam::Error& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}
